"""Frame times, printed: every built-in scene on the GPU path and the reference, and the
renderer against a bare moderngl program doing the same GL work.

    .venv/bin/python benchmarks/bench_pipeline.py [--size 640x480] [--frames 30] [--context egl]

Not a test: this machine is shared and noisy, so figures are medians measured side by side
in one run (the renderer and the bare program alternate frame by frame).

It writes benchmarks/results/pipeline.json (the figures, with machine, date, load and commit)
and pipeline.md (the tables made from it: `markdown`), which docs/benchmarks.md includes.
"""

from __future__ import annotations

import statistics
import time

import numpy as np

from renderer.core.builtin import builtin_scenes
from renderer.core.drawn import triangle_bound
from renderer.gpu.context import activate, make_context
from renderer.gpu.pipeline import make_float_depth
from renderer.gpu.uniforms import uniform_values
from renderer.core.primitives import icosphere
from renderer.core.scene import Camera, DirectionalLight, Material, PointLight, Scene, SceneObject
from renderer.core.scene_file import load_scene
from renderer.gpu.shaders import program_source
from renderer.methods import open_renderer

from common import arguments, measured_line, write_results          # benchmarks/common.py


def sphere_scene() -> Scene:
    """The 20,480-triangle sphere (an icosphere of 5 subdivisions), Phong-shaded."""
    mesh = icosphere(radius=1.0, subdivisions=5)
    assert mesh.triangle_count == 20480
    return Scene(
        camera=Camera(eye=(0.0, 0.0, 3.5), look=(0.0, 0.0, 0.0)),
        objects=[SceneObject("sphere", mesh, Material(ks=(0.5, 0.5, 0.5), n=40.0, shading="phong"))],
        directional_lights=[DirectionalLight(direction=(-1.0, -1.0, -1.0))],
        point_lights=[PointLight(position=(2.0, 2.0, 3.0), intensity=(0.6, 0.6, 0.6))],
        name="sphere20480",
    )


class BareProgram:
    """The same GL work as GpuRenderer.render for a one-object Phong scene, with nothing
    else: the uniforms are set once, and a frame is clear, draw, read colour, read depth."""

    def __init__(self, ctx, scene: Scene, width: int, height: int):
        self.ctx = ctx
        obj = scene.objects[0]
        vertex, geometry, fragment = program_source(scene, obj.material)
        self.program = ctx.program(vertex_shader=vertex, geometry_shader=geometry, fragment_shader=fragment)
        m = scene.matrices(width, height)
        mesh = obj.mesh
        data = np.hstack([mesh.positions, mesh.normals]).astype("f4")
        self.vbo = ctx.buffer(data.tobytes())
        self.ibo = ctx.buffer(mesh.faces.astype("i4").tobytes())
        self.vao = ctx.vertex_array(self.program, [(self.vbo, "3f 3f", "in_position", "in_normal")], self.ibo)
        self.colour = ctx.renderbuffer((width, height), 4)
        self.depth = ctx.depth_renderbuffer((width, height))
        make_float_depth(ctx, self.depth, width, height)      # the renderer's depth format
        self.fbo = ctx.framebuffer([self.colour], self.depth)
        self.colour_out = np.empty((height, width, 4), np.uint8)   # read into, no allocation
        self.depth_out = np.empty((height, width), np.float32)
        self.set_uniforms(scene, m)

    def set_uniforms(self, scene, m):
        for name, value in uniform_values(scene, scene.objects[0], m, 0).items():
            if name in self.program:
                self.program[name].write(value)

    def frame(self):
        activate(self.ctx)                              # as GpuRenderer.render does
        self.fbo.use()
        self.ctx.enable(self.ctx.DEPTH_TEST)
        self.fbo.clear(0.0, 0.0, 0.0, 0.0, depth=1.0)
        self.vao.render()
        self.fbo.read_into(self.colour_out, components=4, alignment=1)
        self.fbo.read_into(self.depth_out, components=1, attachment=-1, alignment=1, dtype="f4")
        return self.colour_out, self.depth_out


def timed(fn) -> float:
    start = time.perf_counter()
    fn()
    return (time.perf_counter() - start) * 1000.0


def bench_scenes(ctx, size, frames) -> list[dict]:
    rows = []
    print(f"\nBuilt-in scenes at {size[0]}x{size[1]} (median ms per frame; GPU path = llvmpipe here)")
    print(f"{'scene':<20} {'triangles':>9} {'gpu_ms':>8} {'reference_ms':>13} {'ratio':>7}")
    for name, path in builtin_scenes().items():
        scene = load_scene(path)
        triangles = sum(triangle_bound(obj) for obj in scene.objects)   # a plane's polygon: at most 4
        with open_renderer(scene, size, context=ctx) as gpu:
            gpu.render()
            gpu_ms = statistics.median(timed(gpu.render) for _ in range(frames))
        twin = open_renderer(scene, size, backend="reference")
        ref_ms = statistics.median(timed(twin.render) for _ in range(3))
        print(f"{name:<20} {triangles:>9} {gpu_ms:>8.2f} {ref_ms:>13.1f} {ref_ms / gpu_ms:>6.1f}x")
        rows.append({"scene": name, "triangles": triangles, "gpu_ms": round(gpu_ms, 3),
                     "reference_ms": round(ref_ms, 2)})
    return rows


def bench_overhead(ctx, size, frames) -> dict:
    scene = sphere_scene()
    bare = BareProgram(ctx, scene, *size)
    with open_renderer(scene, size, context=ctx) as gpu:
        previous = gpu.render()
        bare.frame()                                    # warm up both
        fresh, reused, theirs = [], [], []
        for _ in range(frames):                         # interleave, so all see the same noise
            fresh.append(timed(gpu.render))
            reused.append(timed(lambda: gpu.render(out=previous)))
            theirs.append(timed(bare.frame))
    fresh_ms, ours_ms, bare_ms = (statistics.median(t) for t in (fresh, reused, theirs))
    twin = open_renderer(scene, size, backend="reference")
    ref_ms = statistics.median(timed(twin.render) for _ in range(3))
    print(f"\n20,480-triangle sphere at {size[0]}x{size[1]}, colour + depth read back")
    print(f"  renderer, reusing the frame's arrays  {ours_ms:8.2f} ms/frame (median of {frames})")
    print(f"  renderer, new arrays every frame      {fresh_ms:8.2f} ms/frame")
    print(f"  bare moderngl program                 {bare_ms:8.2f} ms/frame")
    print(f"  ratio renderer (reusing) / bare       {ours_ms / bare_ms:8.3f}  (target <= 1.2)")
    print(f"  ratio renderer (new arrays) / bare    {fresh_ms / bare_ms:8.3f}")
    print(f"  reference (float64)                   {ref_ms:8.1f} ms/frame, "
          f"{ref_ms / fresh_ms:.1f}x the GPU path (target <= 100)")
    return {"reused_ms": round(ours_ms, 3), "fresh_ms": round(fresh_ms, 3), "bare_ms": round(bare_ms, 3),
            "reference_ms": round(ref_ms, 2)}


def main():
    args = arguments(__doc__, "frames", 30)
    ctx = make_context(args.context)
    print(f"GL: {ctx.info['GL_RENDERER']} | {ctx.info['GL_VERSION']} | context {args.context}")
    scene_frames = max(5, args.frames // 3)
    overhead = bench_overhead(ctx, args.size, args.frames)
    scenes = bench_scenes(ctx, args.size, scene_frames)
    figures = {"gl_renderer": ctx.info["GL_RENDERER"], "context": args.context, "size": list(args.size),
               "frames": args.frames, "scene_frames": scene_frames, "reference_frames": 3,
               "overhead": overhead, "scenes": scenes}
    print(f"wrote {write_results('pipeline', figures, markdown)}")


def markdown(document: dict) -> str:
    """docs/benchmarks.md's tables of frame times, made from a results document (write_results)."""
    f = document["figures"]
    o = f["overhead"]
    width, height = f["size"]
    lines = [f"| 20,480-triangle sphere at {width}×{height}, colour + depth read back "
             f"| ms/frame (median of {f['frames']}) |", "| --- | --- |",
             f"| `GpuRenderer.render(out=frame)` (arrays reused) | {o['reused_ms']:.2f} "
             f"({o['reused_ms'] / o['bare_ms']:.2f}× the bare program) |",
             f"| `GpuRenderer.render()` (new arrays each frame) | {o['fresh_ms']:.2f} "
             f"({o['fresh_ms'] / o['bare_ms']:.2f}×) |",
             f"| a bare moderngl program doing the same GL work | {o['bare_ms']:.2f} |",
             f"| NumPy reference, float64 (median of {f['reference_frames']}) | {o['reference_ms']:.1f} "
             f"({o['reference_ms'] / o['fresh_ms']:.1f}× the GPU path) |",
             "", f"Each built-in scene at {width}×{height} (medians: the GPU path of {f['scene_frames']} "
             f"frames, the reference of {f['reference_frames']}):", "",
             "| scene | triangles | GPU ms | reference ms | reference / GPU |",
             "| --- | ---: | ---: | ---: | ---: |"]
    for r in f["scenes"]:
        lines.append(f"| {r['scene']} | {r['triangles']} | {r['gpu_ms']:.2f} | {r['reference_ms']:.1f} "
                     f"| {r['reference_ms'] / r['gpu_ms']:.1f}× |")
    return "\n".join(lines + ["", f"GL: {f['gl_renderer']}, context {f['context']}.", measured_line(document), ""])


if __name__ == "__main__":
    main()
