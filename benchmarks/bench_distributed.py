"""The distributed effects' speed (issue 16's benchmark): samples per second for each effect,
GPU and reference, and what each costs over the same scene without it, printed.

    .venv/bin/python benchmarks/bench_distributed.py [--size 320x240] [--frames 5]
        [--spp 16] [--light-samples 4] [--reference-size 80x60] [--context egl]

For each built-in effect scene (soft_shadows: area lights; depth_of_field: the thin lens;
motion_blur: moving objects over an open shutter; glossy: glossy reflection), jittered
samples:
- GPU (renderer/gpu/raytracer.py) at --size, --spp samples per pixel (soft_shadows: and
  --light-samples points per area light and hit): the median of --frames frames, each
  RayTracer.render() (the draw and the read-back), alternating with the same scene with the
  effect at its degenerate setting (point lights, a pinhole, a closed shutter, mirrors), whose
  tracer compiles the effect out (the ratio is the effect's cost);
- reference (reference/raytrace/pipeline.py) at --reference-size (it is ~1000 times slower),
  one frame each, the effect and the degenerate scene;
- samples per second: pixels x spp / time (camera samples, each carrying one lens point, one
  time and one glossy direction per hit); for soft_shadows also light samples per second
  (pixels x spp x M per area light).
Not a test: this machine is shared and noisy; the load average is printed. The figures go to
benchmarks/results/distributed.json and .md (benchmarks/common.py write_results; `markdown`
makes the .md), which docs/ray-tracing.md includes.
"""

from __future__ import annotations

import time
from dataclasses import replace

from renderer.cli.options import parse_size
from renderer.core.builtin import builtin_scenes
from renderer.core.ray_options import RayOptions
from renderer.core.raytrace_scene import ray_scene
from renderer.core.scene_file import load_scene
from renderer.gpu.context import make_context
from renderer.methods import open_renderer

from common import alternating_ms, machine, measured_line, parser, write_results       # benchmarks/common.py

EFFECTS = {"soft_shadows": "area lights", "depth_of_field": "thin lens",
           "motion_blur": "motion blur", "glossy": "glossy reflection"}


def without_effect(scene):
    """`scene` with its distributed effect at the degenerate setting: no light areas, no
    aperture, a closed shutter, mirror materials."""
    lights = [replace(light, area=None) for light in scene.point_lights]
    camera = replace(scene.camera, aperture=None, shutter=(0.0, 0.0))
    objects = [replace(obj, material=replace(obj.material, gloss=None)) for obj in scene.objects]
    return replace(scene, point_lights=lights, camera=camera, objects=objects)


def main() -> None:
    p = parser(__doc__, "frames", 5)
    p.set_defaults(size=(320, 240))
    p.add_argument("--spp", type=int, default=16)
    p.add_argument("--light-samples", type=int, default=4)
    p.add_argument("--reference-size", type=parse_size, default=(80, 60))
    args = p.parse_args()
    width, height = args.size
    rw, rh = args.reference_size
    print(machine())
    print(f"GPU {width}x{height}, reference {rw}x{rh}; {args.spp} jittered samples per pixel; "
          f"soft_shadows {args.light_samples} light samples per hit; GPU: median of {args.frames} "
          "frames, alternating effect / without")
    ctx = make_context(args.context)
    print(f"GL_RENDERER: {ctx.info['GL_RENDERER']}")
    print()
    print("| scene | effect | GPU ms | GPU Msamples/s | without ms | effect / without | "
          "reference s | reference ksamples/s | without s | effect / without | light Msamples/s (GPU) |")
    print("| --- | --- | ---: | ---: | ---: | ---: | ---: | ---: | ---: | ---: | ---: |")
    figures = {"size": list(args.size), "reference_size": [rw, rh], "spp": args.spp,
               "light_samples": args.light_samples, "frames": args.frames, "context": args.context,
               "renderer": ctx.info["GL_RENDERER"], "rows": []}
    for name, effect in EFFECTS.items():
        scene = load_scene(builtin_scenes()[name])
        plain = without_effect(scene)
        m = args.light_samples if name == "soft_shadows" else 1
        options = RayOptions(samples=args.spp, pattern="jittered", light_samples=m)
        with open_renderer(scene, args.size, method="raytrace", context=ctx, options=options) as tracer, \
                open_renderer(plain, args.size, method="raytrace", context=ctx, options=options) as bare:
            tracer.render()
            bare.render()
            ms, bare_ms = alternating_ms([tracer.render, bare.render], args.frames)
        seconds = []
        for drawn in (scene, plain):
            twin = open_renderer(drawn, (rw, rh), method="raytrace", backend="reference", options=options)
            twin.ray_scene = ray_scene(drawn)                     # made before, not timed
            start = time.perf_counter()
            twin.render()
            seconds.append(time.perf_counter() - start)
        samples = width * height * args.spp
        light = f"{samples * m / ms / 1e3:.2f}" if name == "soft_shadows" else ""
        print(f"| {name} | {effect} | {ms:.1f} | {samples / ms / 1e3:.2f} | {bare_ms:.1f} | "
              f"{ms / bare_ms:.2f} | {seconds[0]:.2f} | {rw * rh * args.spp / seconds[0] / 1e3:.1f} | "
              f"{seconds[1]:.2f} | {seconds[0] / seconds[1]:.2f} | {light} |")
        figures["rows"].append({"scene": name, "effect": effect, "light_samples": m,
                                "gpu_ms": round(ms, 2), "gpu_without_ms": round(bare_ms, 2),
                                "reference_s": round(seconds[0], 4), "reference_without_s": round(seconds[1], 4)})
    ctx.release()
    print(f"wrote {write_results('distributed', figures, markdown)}")


def markdown(document: dict) -> str:
    """The table of docs/ray-tracing.md, "Distributed ray tracing", "Speed", made from a results
    document (write_results)."""
    figures = document["figures"]
    (width, height), (rw, rh) = figures["size"], figures["reference_size"]
    spp = figures["spp"]
    lines = [f"GPU path ({figures['renderer']} on {figures['context']}) at {width}×{height}, the median of "
             f"{figures['frames']} frames alternating with the scene without its effect; reference at "
             f"{rw}×{rh}, one frame each; {spp} jittered samples per pixel (soft_shadows: "
             f"{figures['light_samples']} light samples per hit).", "",
             "| scene | GPU Msamples/s | effect / without (GPU) | reference ksamples/s | effect / without (reference) |",
             "| --- | ---: | ---: | ---: | ---: |"]
    for row in figures["rows"]:
        samples = width * height * spp
        rate = f"{samples / row['gpu_ms'] / 1e3:.2f}"
        if row["scene"] == "soft_shadows":
            rate += f" ({samples * row['light_samples'] / row['gpu_ms'] / 1e3:.1f} M light samples/s)"
        lines.append(f"| {row['scene']} ({row['effect']}) | {rate} | {row['gpu_ms'] / row['gpu_without_ms']:.2f} | "
                     f"{rw * rh * spp / row['reference_s'] / 1e3:.0f} | "
                     f"{row['reference_s'] / row['reference_without_s']:.2f} |")
    return "\n".join(lines + ["", measured_line(document), ""])


if __name__ == "__main__":
    main()
