"""Shadow maps' cost per scene, printed (issue 15's benchmark): frames with shadows against
the same scene without, and against a bare moderngl program doing the same two passes.

    .venv/bin/python benchmarks/bench_shadows.py [--size 640x480] [--rounds 15] [--quick]
        [--scenes shadow_plane,shadow_room,shadow_curved,classic] [--context egl]

For each scene, on one GL context, three frames are timed in turn, round after round (so all
three see the same machine load), each with the same read-back as GpuRenderer.render(): the
RGBA8 colour and the float depth (glReadPixels into arrays made once):
- without: GpuRenderer.render(out=frame) of the scene with every light's shadows off
  (Shadow(enabled=False)): no maps, no lookup code;
- with: GpuRenderer.render(out=frame) of the scene as it is (every light's map on);
- bare: a moderngl program with nothing of the project in the loop (BareShadows): the same
  passes with the matrices renderer/core/shadows.plan_shadows gives (planned once, before the
  timed frames), drawn into the same storage (the layers of a DEPTH_COMPONENT32F array
  texture, a framebuffer per layer, each map cleared and drawn R x R from texel (0, 0)), then
  the camera pass with minimal GLSL (benchmarks/glsl/bare_*.vert/.frag): Phong with one
  LINEAR depth-compare lookup per light (pcf2x2's one bilinear comparison), a fixed normal
  offset in place of the bias rule, the facet rule (a facet turned from the light is
  shadowed) with the facet's normal from screen derivatives. It is the lower bound for the
  same GL work.
with/bare is the issue's figure (target <= 1.2). update() (uniforms and the frame's shadow
plan: run when the camera, lights or objects move, not per frame) is timed the same way,
with and without. The renderer also turns GL's bottom-up rows into row-0-on-top arrays and
window depth into camera distance, which the bare program does not (about 0.2 ms at 640x480:
benchmarks/bench_pipeline.py). Not a test: this machine is shared and noisy.

Run on the default scenes (no --scenes), it writes benchmarks/results/shadows.json (the
figures, with machine, date, load and commit) and shadows.md (the table made from it:
`markdown`), which docs/benchmarks.md includes; a run on other scenes only prints.
"""

from __future__ import annotations

import dataclasses
import time
from pathlib import Path

import moderngl
import numpy as np

from renderer.core.gl_rules import STANDARD_DEPTH
from renderer.core.scene import Scene
from renderer.core.scene_file import load_scene
from renderer.core.shadow_settings import Shadow
from renderer.core.shadows import plan_shadows, shadow_layout
from renderer.core.transforms import to_glsl
from renderer.core.visibility import visible_objects
from renderer.gpu import GpuRenderer
from renderer.gpu.context import activate, make_context
from renderer.gpu.pipeline import CULL_FLAGS, make_float_depth
from renderer.gpu.shaders import shader_source
from renderer.gpu.shadow_maps import ShadowMaps
from renderer.gpu.uniforms import frame_uniform_values, object_uniform_values, set_shadow_sampler_units
from renderer.methods import open_renderer

from common import alternating_ms, machine, measured_line, parser, write_results   # benchmarks/common.py

# sphere, the default scene: one convex ball, which nothing can shadow, so it has no maps at
# all and its frame with shadows on must cost what it costs with them off (issue 28: within
# 1.1x), with the same image.
SCENES = ("sphere", "shadow_plane", "shadow_room", "shadow_curved", "classic")
DEFAULT_TARGET = 1.1               # issue 28: the default scene's with/without
GLSL = Path(__file__).resolve().parent / "glsl"
TARGET = 1.2                       # issue 15: with shadows within 1.2x the bare program
QUICK_ROUNDS = 3


def without_shadows(scene: Scene) -> Scene:
    """`scene` with every light's shadow map off (the objects are shared)."""
    off = Shadow(enabled=False)
    return dataclasses.replace(
        scene, directional_lights=[dataclasses.replace(l, shadow=off) for l in scene.directional_lights],
        point_lights=[dataclasses.replace(l, shadow=off) for l in scene.point_lights])


class BareShadows:
    """The two passes of a shadowed frame with nothing else: everything is resolved in
    __init__ (plan, matrices, uniforms as bytes, vertex arrays), and frame() only draws the
    maps, draws the camera pass and reads the colour and depth back."""

    def __init__(self, ctx: moderngl.Context, scene: Scene, width: int, height: int):
        self.ctx = ctx
        matrices = scene.matrices(width, height)
        visible = visible_objects(scene, matrices)
        layout = shadow_layout(scene, width, height)
        plan = plan_shadows(scene, matrices, layout, visible)
        self.storage = ShadowMaps(ctx, layout)          # its texture and framebuffers only
        self.depth_program = ctx.program(vertex_shader=self._source("bare_depth.vert"),
                                         fragment_shader=self._source("bare_depth.frag"))
        self.clip_from_model = self.depth_program["u_clip_from_model"]
        self.buffers = []
        for obj in scene.objects:
            vertices = np.hstack([obj.mesh.positions, obj.mesh.normals]).astype(np.float32)
            self.buffers.append((ctx.buffer(vertices.tobytes()),
                                 ctx.buffer(obj.mesh.faces.astype(np.uint32).tobytes())))
        self.passes = []                                  # (framebuffer, R, [(vao, bytes)])
        for shadow_pass in plan.passes:
            draws = [(self._vao(self.depth_program, i, "3f 3x4", "in_position"),
                      to_glsl(shadow_pass.clip_from_world @ matrices.objects[i].model))
                     for i in shadow_pass.casters]
            self.passes.append((self.storage.framebuffers(shadow_pass.kind)[shadow_pass.tile.layer],
                                shadow_pass.tile.size, draws))
        frame_values = frame_uniform_values(scene, matrices, shadows=plan.uniforms)
        programs, self.draws = {}, []                     # (vao, enable, cull, [(uniform, bytes)])
        for i, obj in enumerate(scene.objects):
            if not visible[i] or not obj.mesh.triangle_count:
                continue
            key = (obj.material.two_sided, obj.material.has_specular)
            program = programs.get(key)
            if program is None:
                program = programs[key] = self._camera_program(scene, *key)
                for name, data in frame_values.items():
                    if name in program:
                        program[name].write(data)
            uploads = [(program[name], data) for name, data in
                       object_uniform_values(obj, matrices.objects[i]).items() if name in program]
            cull = CULL_FLAGS[obj.cull]
            enable = moderngl.DEPTH_TEST | (moderngl.CULL_FACE if cull else 0)
            self.draws.append((self._vao(program, i, "3f 3f", "in_position", "in_normal"),
                               enable, cull, uploads))
        self.background = scene.background
        self.colour = ctx.renderbuffer((width, height), 4)
        self.depth = ctx.depth_renderbuffer((width, height))
        make_float_depth(ctx, self.depth, width, height)          # the renderer's depth format
        self.fbo = ctx.framebuffer([self.colour], self.depth)
        self.colour_out = np.empty((height, width, 4), np.uint8)
        self.depth_out = np.empty((height, width), np.float32)

    @staticmethod
    def _source(name: str, defines: dict | None = None) -> str:
        return shader_source(name, defines, directory=GLSL).text

    def _camera_program(self, scene: Scene, two_sided: bool, specular: bool) -> moderngl.Program:
        defines = {"NUM_DIRECTIONAL_LIGHTS": len(scene.directional_lights),
                   "NUM_POINT_LIGHTS": len(scene.point_lights),
                   "TWO_SIDED": two_sided, "SPECULAR": specular}
        program = self.ctx.program(vertex_shader=self._source("bare_phong.vert"),
                                   fragment_shader=self._source("bare_phong.frag", defines))
        set_shadow_sampler_units(self.ctx, program)
        return program

    def _vao(self, program, index: int, layout: str, *attributes: str) -> moderngl.VertexArray:
        vbo, ibo = self.buffers[index]
        return self.ctx.vertex_array(program, [(vbo, layout, *attributes)], index_buffer=ibo,
                                     index_element_size=4)

    def frame(self) -> tuple[np.ndarray, np.ndarray]:
        ctx, clear_depth = self.ctx, STANDARD_DEPTH.clear_depth
        activate(ctx)                                     # as GpuRenderer.draw does
        ctx.enable_only(moderngl.DEPTH_TEST)
        ctx.depth_func = STANDARD_DEPTH.depth_func
        for framebuffer, size, draws in self.passes:
            framebuffer.use()
            ctx.viewport = (0, 0, size, size)
            framebuffer.clear(depth=clear_depth, viewport=(0, 0, size, size))
            for vao, clip_from_model in draws:
                self.clip_from_model.write(clip_from_model)
                vao.render(moderngl.TRIANGLES)
        self.fbo.use()
        self.storage.bind()
        self.fbo.clear(*self.background, 0.0, depth=clear_depth)
        for vao, enable, cull, uploads in self.draws:
            ctx.enable_only(enable)
            if cull:
                ctx.cull_face = cull
            for uniform, data in uploads:
                uniform.write(data)
            vao.render(moderngl.TRIANGLES)
        self.fbo.read_into(self.colour_out, components=4, alignment=1)
        self.fbo.read_into(self.depth_out, components=1, attachment=-1, alignment=1, dtype="f4")
        return self.colour_out, self.depth_out

    def release(self) -> None:
        for vao, *_ in self.draws:
            vao.release()
        for _framebuffer, _size, draws in self.passes:
            for vao, _ in draws:
                vao.release()
        for buffer in (b for pair in self.buffers for b in pair):
            buffer.release()
        for gl_object in (self.fbo, self.colour, self.depth, self.depth_program):
            gl_object.release()
        self.storage.release()


def maps_label(renderer: GpuRenderer) -> str:
    """The scene's maps: each light's resolution (x6 for a point light's cube), the layers'
    side and count, and the passes (maps drawn) and caster draws of the current plan."""
    if renderer.shadow_maps is None:
        return "none (nothing can shadow)"
    layout, plan = renderer.shadow_maps.layout, renderer.shadow_maps.plan
    sizes = " + ".join(f"{m.resolution}" + ("x6" if m.kind == "point" else "") for m in layout.maps)
    draws = sum(len(p.casters) for p in plan.passes)
    stacks = " + ".join(f"{s.layers}x{s.side}²" for s in layout.stacks if s.layers)
    return f"{sizes} ({stacks}), {len(plan.passes)} passes, {draws} draws"


def maps_figures(renderer: GpuRenderer) -> dict | None:
    """maps_label's figures, for a results file: each map's kind and resolution, the layer
    stacks (layers, side) and the current plan's passes and caster draws; None: no maps."""
    if renderer.shadow_maps is None:
        return None
    layout, plan = renderer.shadow_maps.layout, renderer.shadow_maps.plan
    return {"maps": [[m.kind, m.resolution] for m in layout.maps],
            "stacks": [[s.layers, s.side] for s in layout.stacks if s.layers],
            "passes": len(plan.passes), "draws": sum(len(p.casters) for p in plan.passes)}


def measure(ctx, scene: Scene, size, rounds: int) -> dict:
    plain_scene = without_shadows(scene)
    # A scene without maps has no shadow passes for a bare program to draw: with = without.
    bare = BareShadows(ctx, scene, *size) if shadow_layout(scene, *size).any else None
    with open_renderer(scene, size, context=ctx) as shadowed, \
            open_renderer(plain_scene, size, context=ctx) as plain:
        frames = shadowed.render(), plain.render()      # compiles; not timed
        same = bool((frames[0].rgba8 == frames[1].rgba8).all())
        calls = [lambda: plain.render(out=frames[1]), lambda: shadowed.render(out=frames[0])]
        differ = bare_ms = None
        if bare is not None:
            bare_colour, _ = bare.frame()
            differ = float(np.mean(np.abs(bare_colour[::-1].astype(int) - frames[0].rgba8).max(axis=2) > 8))
            calls.append(bare.frame)
        plain_ms, shadowed_ms, *bare_ms = alternating_ms(calls, rounds)
        update_plain, update_shadowed = alternating_ms((plain.update, shadowed.update), rounds)
        label, maps = maps_label(shadowed), maps_figures(shadowed)
    if bare is not None:
        bare.release()
    return {"scene": scene.name, "maps": label, "map figures": maps, "without": plain_ms, "with": shadowed_ms,
            "bare": bare_ms[0] if bare_ms else None, "update without": update_plain,
            "update with": update_shadowed, "bare differs": differ, "same image": same}


def main() -> None:
    options = parser(__doc__, "rounds", 15)
    options.add_argument("--quick", action="store_true", help=f"{QUICK_ROUNDS} rounds")
    options.add_argument("--scenes", type=lambda text: text.split(","), default=list(SCENES),
                         help=f"comma-separated scene names (default: {','.join(SCENES)})")
    args = options.parse_args()
    rounds = QUICK_ROUNDS if args.quick else args.rounds
    ctx = make_context(args.context)
    width, height = args.size
    print(f"{machine()}; {ctx.info['GL_RENDERER']}; {time.strftime('%Y-%m-%d %H:%M')}")
    print(f"{width}x{height}, {args.context}; medians of {rounds} rounds, the three frames of a "
          f"round in turn; colour and depth read back")
    header = (f"{'scene':<14} {'maps (sizes, passes)':<44} {'without':>8} {'with':>8} {'bare':>8} "
              f"{'with/without':>12} {'with/bare':>9}  {'<= ' + str(TARGET):>6}  "
              f"{'update ms without/with':>22}  {'same image':>10}")
    print(header)
    print("-" * len(header))
    rows = []
    for name in args.scenes:
        row = measure(ctx, load_scene(name), args.size, rounds)
        rows.append(row)
        if row["bare"] is None:           # no maps: held to with/without instead
            bare, ratio, meets = "-", "-", row["with"] / row["without"] <= DEFAULT_TARGET
        else:
            bare, ratio = f"{row['bare']:.2f}", f"{row['with'] / row['bare']:.2f}x"
            meets = row["with"] / row["bare"] <= TARGET
        print(f"{row['scene']:<14} {row['maps']:<44} {row['without']:8.2f} {row['with']:8.2f} "
              f"{bare:>8} {row['with'] / row['without']:11.2f}x {ratio:>9}  "
              f"{'yes' if meets else 'NO':>6}  "
              f"{row['update without']:10.2f} / {row['update with']:<9.2f}  "
              f"{'yes' if row['same image'] else 'no':>10}", flush=True)
    print("ms: medians per frame (update: per update() call). A scene without maps is held to "
          f"with/without <= {DEFAULT_TARGET} (no bare program: it would draw no light view). "
          "The bare program's image differs from the renderer's (more than 8/255 in a channel) in "
          + ", ".join(f"{r['scene']} {100 * r['bare differs']:.2f}%" for r in rows
                      if r["bare differs"] is not None)
          + " of the pixels (its fixed bias). Same image: with shadows on and off, every pixel.")
    print(f"{machine()}")
    if args.scenes == list(SCENES):                   # docs/benchmarks.md's table: every scene
        figures = {"gl_renderer": ctx.info["GL_RENDERER"], "context": args.context,
                   "size": [width, height], "rounds": rounds, "scenes": [results_row(r) for r in rows]}
        print(f"wrote {write_results('shadows', figures, markdown)}")
    scenes = "" if args.scenes == list(SCENES) else f" --scenes {','.join(args.scenes)}"
    quick = " --quick" if args.quick else f" --rounds {args.rounds}"
    print(f"Reproduce: .venv/bin/python benchmarks/bench_shadows.py --size {width}x{height}"
          f"{quick}{scenes} --context {args.context}")
    ctx.release()


def results_row(row: dict) -> dict:
    """A measure() row for the results file: ms rounded, the maps as figures."""
    def rounded(value):
        return None if value is None else round(value, 3)
    return {"scene": row["scene"], "maps": row["map figures"], "without_ms": rounded(row["without"]),
            "with_ms": rounded(row["with"]), "bare_ms": rounded(row["bare"]),
            "update_without_ms": rounded(row["update without"]), "update_with_ms": rounded(row["update with"]),
            "bare_differs": None if row["bare differs"] is None else round(row["bare differs"], 5),
            "same_image": row["same image"]}


def markdown(document: dict) -> str:
    """docs/benchmarks.md's table of shadow maps' cost, made from a results document
    (write_results). A ratio that misses its target is in bold."""
    f = document["figures"]
    width, height = f["size"]
    lines = [f"{width}×{height}, medians of {f['rounds']} rounds, the three frames of a round in turn, "
             f"colour and depth read back; GL: {f['gl_renderer']}, context {f['context']}.", "",
             "| scene | maps (texels on a side; layers) | passes, caster draws | without ms | with ms "
             f"| bare ms | with / without | with / bare (target ≤ {TARGET}) | update ms, without / with "
             "| same image as without |",
             "| --- | --- | --- | ---: | ---: | ---: | ---: | ---: | ---: | --- |"]

    def ratio(value: float, target: float) -> str:
        return f"**{value:.2f}×**" if value > target else f"{value:.2f}×"

    for r in f["scenes"]:
        maps = r["maps"]
        name = r["scene"] + (" (the default)" if r["scene"] == SCENES[0] else "")
        if maps is None:
            drawn, work = "none: nothing in it can shadow", "0, 0"
        else:
            sizes = " + ".join(str(size) if kind != "point" else f"point 6 × {size}" for kind, size in maps["maps"])
            stacks = " + ".join(f"{layers} layer{'s' if layers > 1 else ''} of {side}²"
                                for layers, side in maps["stacks"])
            drawn, work = f"{sizes} ({stacks})", f"{maps['passes']}, {maps['draws']}"
        with_without = r["with_ms"] / r["without_ms"]
        if r["bare_ms"] is None:
            first, bare, second = f"{ratio(with_without, DEFAULT_TARGET)} (target ≤ {DEFAULT_TARGET})", "", ""
        else:
            first, bare, second = f"{with_without:.2f}×", f"{r['bare_ms']:.2f}", ratio(r["with_ms"] / r["bare_ms"], TARGET)
        lines.append(f"| {name} | {drawn} | {work} | {r['without_ms']:.2f} | {r['with_ms']:.2f} | {bare} "
                     f"| {first} | {second} | {r['update_without_ms']:.2f} / {r['update_with_ms']:.2f} "
                     f"| {'yes' if r['same_image'] else 'no'} |")
    differs = [f"{r['scene']} {100 * r['bare_differs']:.2f} %" for r in f["scenes"] if r["bare_differs"] is not None]
    if differs:
        lines += ["", "The bare program's image differs from the renderer's (by more than 8/255 in a "
                  "channel, its fixed bias) in " + ", ".join(differs) + " of the pixels."]
    return "\n".join(lines + ["", measured_line(document), ""])


if __name__ == "__main__":
    main()
