"""The ray tracer's speed per scene, GPU and reference, printed (issue 14's benchmark).

    .venv/bin/python benchmarks/bench_raytrace.py [--size 640x480] [--frames 5] [--quick]
        [--spp 1,16] [--scenes classic,cornell_box,...] [--context egl]

Scenes: the built-in scenes made for the ray tracer (classic: a floor plane, a diffuse, a
mirror and a glass sphere, two lights; cornell_box: five planes, a mirror and a glass sphere,
a point light; mesh_shadow: the 5,040-triangle torus knot over a plane; tir_bubble: a glass
sphere and an air bubble before a 256-triangle checkerboard), the built-in `sphere` (3,968
triangles), a 20,480-triangle icosphere (subdivisions 5) lit as `sphere`, built here, and
issue 32's knot: mesh_shadow with a 131,072-triangle knot (benchmarks/knot_scene.py).
For each at 1 and 16 samples per pixel (--spp; regular pattern, max depth 4):
- GPU (renderer/gpu/raytracer.py): the median of --frames frames after a warm-up frame,
  RayTracer.render() (the draw and the read-back);
- reference (reference/raytrace/pipeline.py): one frame (the ray scene and BVH made before,
  not timed); --quick leaves out the reference frames of more than 1 sample;
- rays per frame, counted in the reference (every ray it intersects with the scene: camera
  rays, reflected and refracted rays, shadow rays), the same for the GPU (same algorithm);
  where --quick skips a reference frame, estimated as spp times the 1-spp count (marked ~);
- rays per second = rays per frame / time per frame; ref/GPU = the ratio of the times.
Then, at 1 spp, the GPU specialised (the default: only what the scene uses compiled in) against
all features compiled in (RayTracer(..., specialise=False)), frames alternating; the images
must be identical; and the rasteriser (renderer.gpu.GpuRenderer) against the ray tracer at
1 spp, frames alternating. The BVH's speed-up over brute force: benchmarks/bench_bvh.py.
Not a test: this machine is shared and noisy; the load average is printed. The figures go to
benchmarks/results/raytrace.json and .md (benchmarks/common.py write_results; `markdown`
makes the .md), which docs/ray-tracing.md includes.
"""

from __future__ import annotations

import argparse
import statistics
import tempfile
import time

import numpy as np

import reference.raytrace.trace as trace_module
from renderer.cli.options import parse_size
from renderer.core.ray_options import RayOptions
from renderer.core.raytrace_scene import ray_scene
from renderer.core.scene_file import load_scene, scene_from_dict
from renderer.gpu.context import make_context
from renderer.methods import open_renderer

from common import alternating_ms, machine, measured_line, write_results       # benchmarks/common.py
from knot_scene import knot_toml                                                 # benchmarks/knot_scene.py

RAYTRACE_SCENES = ("classic", "cornell_box", "mesh_shadow", "tir_bubble")
ICOSPHERE = "icosphere (20,480 tri)"
KNOT = "knot (131,072 tri)"
TARGET_MS = 100          # issue 14: `classic` at 640x480, 1 spp, within 100 ms a frame on the GPU path
REFERENCE_LIMIT = 50     # issue 14: the reference within 50 times the GPU path's time


def icosphere_scene():
    """The built-in `sphere` scene's camera, lights and material on icosphere(5): 20,480 triangles."""
    return scene_from_dict({
        "background": [0.04, 0.05, 0.08], "ambient": [0.12, 0.12, 0.14],
        "camera": {"eye": [0.0, 0.4, 4.2], "look": [0.0, 0.0, 0.0], "fov_y": 40.0},
        "materials": {"red": {"ka": [0.8, 0.15, 0.1], "kd": [0.75, 0.12, 0.08],
                              "ks": [0.7, 0.7, 0.7], "n": 40.0}},
        "lights": [{"type": "directional", "direction": [1.0, -1.0, -1.2], "intensity": [0.85, 0.85, 0.8]},
                   {"type": "point", "position": [3.0, 0.5, 2.5], "intensity": [0.45, 0.5, 0.65],
                    "attenuation": [1.0, 0.0, 0.02]}],
        "objects": [{"name": "ball", "mesh": {"primitive": "icosphere", "radius": 1.0, "subdivisions": 5},
                     "material": "red"}]})


class RayCount:
    """Counts the rays the reference intersects with the scene (trace.py's scene_hit: camera
    and secondary rays; occluded: shadow rays) while in a `with` block."""

    def __enter__(self):
        self.total = 0
        self._scene_hit, self._occluded = trace_module.scene_hit, trace_module.occluded

        def counted(function):
            def count(rs, O, *args, **kwargs):
                self.total += len(O)
                return function(rs, O, *args, **kwargs)
            return count
        trace_module.scene_hit, trace_module.occluded = counted(self._scene_hit), counted(self._occluded)
        return self

    def __exit__(self, *exc):
        trace_module.scene_hit, trace_module.occluded = self._scene_hit, self._occluded


def gpu_ms(tracer, frames: int):
    tracer.render()                                            # warm-up
    times = []
    for _ in range(frames):
        start = time.perf_counter()
        tracer.render()
        times.append((time.perf_counter() - start) * 1000.0)
    return statistics.median(times)


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--size", type=parse_size, default=(640, 480))
    parser.add_argument("--frames", type=int, default=5)
    parser.add_argument("--quick", action="store_true", help="no reference frames of more than 1 sample")
    parser.add_argument("--spp", type=lambda text: [int(n) for n in text.split(",")], default=[1, 16],
                        help="sample counts, comma-separated (each a perfect square)")
    parser.add_argument("--scenes", type=lambda text: text.split(","), default=None,
                        help=f"comma-separated names among {', '.join(RAYTRACE_SCENES)}, sphere, icosphere, knot")
    parser.add_argument("--context", choices=("egl", "osmesa"), default="egl")
    args = parser.parse_args()
    W, H = args.size
    ctx = make_context(args.context)
    print(f"{machine()}; {ctx.info['GL_RENDERER']}; {time.strftime('%Y-%m-%d %H:%M')}")
    scenes = {name: load_scene(name) for name in RAYTRACE_SCENES}
    scenes["sphere (3,968 tri)"] = load_scene("sphere")
    scenes[ICOSPHERE] = icosphere_scene()
    knot_folder = tempfile.TemporaryDirectory()
    scenes[KNOT] = load_scene(knot_toml(knot_folder.name))
    if args.scenes:
        scenes = {name: scene for name, scene in scenes.items() if name.split()[0] in args.scenes}
    print(f"{W}x{H}, max depth 4, regular samples; GPU: median of {args.frames} frames after a "
          f"warm-up ({args.context}); reference: 1 frame")
    header = (f"{'scene':24} {'spp':>3} {'rays/frame':>12} {'GPU ms':>9} {'GPU Mrays/s':>11} "
              f"{'ref ms':>10} {'ref Mrays/s':>11} {'ref/GPU':>8}")
    print(header)
    print("-" * len(header))
    counts = {}
    figures = {"size": [W, H], "frames": args.frames, "context": args.context,
               "renderer": ctx.info["GL_RENDERER"], "target_ms": TARGET_MS,
               "reference_limit": REFERENCE_LIMIT, "rows": [], "specialisation": [], "raster": []}
    for name, scene in scenes.items():
        rs = ray_scene(scene)
        for spp in args.spp:
            options = RayOptions(samples=spp)
            with open_renderer(scene, (W, H), method="raytrace", context=ctx, options=options) as tracer:
                g = gpu_ms(tracer, args.frames)
            if spp > 1 and args.quick and name in counts:
                rays, r, mark = spp * counts[name], None, "~"
            else:
                twin = open_renderer(scene, (W, H), method="raytrace", backend="reference", options=options)
                twin.ray_scene = rs                              # made before, not timed
                with RayCount() as count:
                    start = time.perf_counter()
                    twin.render()
                    r = (time.perf_counter() - start) * 1000.0
                rays, mark = count.total, " "
                if spp == 1:
                    counts[name] = rays
            ref = (f"{r:10.0f} {rays / r / 1000:11.2f} {r / g:7.1f}x" if r is not None
                   else f"{'-':>10} {'-':>11} {'-':>8}")
            figures["rows"].append({"scene": name, "spp": spp, "rays": rays, "estimated": mark == "~",
                                    "gpu_ms": round(g, 1), "reference_ms": None if r is None else round(r, 1)})
            print(f"{name:24} {spp:3d} {mark}{rays:11,d} {g:9.1f} {rays / g / 1000:11.2f} {ref}",
                  flush=True)
    print(f"\nspecialisation, GPU, 1 spp (frames alternate; median of {args.frames}):")
    for name, scene in scenes.items():
        with open_renderer(scene, (W, H), method="raytrace", context=ctx) as fast, \
                open_renderer(scene, (W, H), method="raytrace", context=ctx,
                              options=RayOptions(specialise=False)) as every:
            a, b = fast.render(), every.render()
            same = np.array_equal(a.rgba8, b.rgba8) and np.array_equal(a.linear, b.linear)
            f, e = alternating_ms((fast.render, every.render), args.frames)
            left_out = [k for k in ("SPECULAR", "SHADOWS", "MESHES", "SECONDARY") if every.defines[k] and not fast.defines[k]]
            print(f"  {name:24} specialised {f:7.1f} ms, all features {e:7.1f} ms: {e / f:.2f}x "
                  f"(left out: {', '.join(left_out) or 'nothing'}; identical images: {same})")
            figures["specialisation"].append({"scene": name, "specialised_ms": round(f, 1), "all_ms": round(e, 1),
                                              "left_out": left_out, "identical": bool(same)})
    print(f"\nthe rasteriser against the ray tracer, GPU, 1 spp (frames alternate after a warm-up; "
          f"median of {args.frames}; colour and depth read back):")
    for name, scene in scenes.items():
        with open_renderer(scene, (W, H), context=ctx) as raster, \
                open_renderer(scene, (W, H), method="raytrace", context=ctx) as tracer:
            raster.render()                                       # warm-up
            tracer.render()
            r, t = alternating_ms((raster.render, tracer.render), args.frames)
            print(f"  {name:24} rasteriser {r:7.1f} ms, ray tracer {t:7.1f} ms: {t / r:.0f}x")
            figures["raster"].append({"scene": name, "raster_ms": round(r, 2), "raytrace_ms": round(t, 1)})
    print(f"\n{machine()}")
    ctx.release()
    knot_folder.cleanup()
    print(f"wrote {write_results('raytrace', figures, markdown)}")


def scene_label(name: str) -> str:
    """`classic`, `sphere` (3,968 tri), icosphere (20,480 tri): a built-in scene's name as code."""
    first, _, rest = name.partition(" ")
    label = first if name in (ICOSPHERE, KNOT) else f"`{first}`"
    return f"{label} {rest}".strip()


def markdown(document: dict) -> str:
    """The tables of docs/ray-tracing.md, "How fast", made from a results document (write_results)."""
    figures = document["figures"]
    (W, H), frames = figures["size"], figures["frames"]

    def ms(x: float) -> str:
        return f"{x:,.0f}" if x >= 100 else f"{x:.1f}"
    lines = [f"{W}×{H}, max depth 4, regular samples. GPU path: {figures['renderer']} "
             f"on {figures['context']}, the median of {frames} frames after a warm-up; reference: one frame. "
             "Rays per frame are counted in the reference (\"~\": spp times the 1-spp count, "
             "where the reference's frame was left out).", "",
             "| scene | spp | rays/frame | GPU ms | GPU Mrays/s | reference ms | reference Mrays/s | reference/GPU |",
             "| --- | ---: | ---: | ---: | ---: | ---: | ---: | ---: |"]
    for row in figures["rows"]:
        g, r, rays = row["gpu_ms"], row["reference_ms"], row["rays"]
        ref = (f"{ms(r)} | {rays / r / 1000:.2f} | {r / g:.1f}x" if r is not None else " | | ")
        lines.append(f"| {scene_label(row['scene'])} | {row['spp']} | {'~' if row['estimated'] else ''}{rays:,} | "
                     f"{ms(g)} | {rays / g / 1000:.1f} | {ref} |")
    lines += ["", f"Issue 14's targets: `classic` at 640×480, 1 spp, within {figures['target_ms']} ms a frame "
              f"on the GPU path; the reference within {figures['reference_limit']} times the GPU path's time.",
              "", "Specialised (only what the scene uses compiled in, the default) against every feature "
              f"compiled in (`specialise=False`), GPU, 1 spp, frames alternating, median of {frames}:", "",
              "| scene | left out | specialised ms | all features ms | all / specialised | identical images |",
              "| --- | --- | ---: | ---: | ---: | --- |"]
    for row in figures["specialisation"]:
        lines.append(f"| {scene_label(row['scene'])} | {', '.join(row['left_out']) or 'nothing'} | "
                     f"{row['specialised_ms']:,.1f} | {row['all_ms']:,.1f} | "
                     f"{row['all_ms'] / row['specialised_ms']:.2f}x | {'yes' if row['identical'] else 'no'} |")
    lines += ["", "The rasteriser against the ray tracer, GPU, 1 spp, frames alternating after a warm-up, "
              f"median of {frames}, colour and depth read back:", "",
              "| scene | rasteriser ms | ray tracer ms | ray tracer / rasteriser |", "| --- | ---: | ---: | ---: |"]
    for row in figures["raster"]:
        lines.append(f"| {scene_label(row['scene'])} | {row['raster_ms']:,.1f} | {row['raytrace_ms']:,.1f} | "
                     f"{row['raytrace_ms'] / row['raster_ms']:.1f}x |")
    return "\n".join(lines + ["", measured_line(document), ""])


if __name__ == "__main__":
    main()
