"""What adaptive supersampling saves, in samples and in time, against every pixel at N samples.

    .venv/bin/python benchmarks/bench_adaptive.py [--size 640x480] [--frames 5] [--quick]
                     [--thresholds 1,2,4] [--context egl]

Scenes: the built-in `classic` and the built-in `sphere` (3,968 triangles). Per scene, N = 16:
- jittered 4 (the first set alone), jittered 16 (the full N), and adaptive 16 at each
  threshold of --thresholds (in 8-bit steps, 1/255 each; 2 is the default);
- samples per pixel: the mean of Frame.samples, and the share of pixels refined;
- GPU ms (renderer/gpu/raytracer.py): the median of --frames frames after a warm-up, the
  patterns' frames interleaved so that the machine's load falls on all alike;
- reference ms (reference/raytrace/pipeline.py): one frame (the ray scene made before, not
  timed); --quick leaves the reference out;
- error against a 64-spp jittered GPU frame (another seed): the RMS and largest difference of
  the clamped linear colour, in 8-bit steps (x 255), over all pixels.
Not a test: this machine is shared and noisy; the load average is printed. The figures go to
benchmarks/results/adaptive.json and .md (benchmarks/common.py write_results; `markdown`
makes the .md), which docs/ray-tracing.md includes.
"""

from __future__ import annotations

import argparse
import statistics
import time

import numpy as np

from renderer.cli.options import parse_size
from renderer.core.ray_options import RayOptions
from renderer.core.raytrace_scene import ray_scene
from renderer.core.scene_file import load_scene
from renderer.gpu.context import make_context
from renderer.methods import open_renderer

from common import machine, measured_line, write_results       # benchmarks/common.py

N, TRUTH_SPP, TRUTH_SEED = 16, 64, 64


def error_steps(frame, truth) -> tuple[float, float]:
    """(RMS, largest) difference of the clamped linear colours, in 8-bit steps."""
    difference = (np.clip(frame.linear[..., :3], 0, 1).astype(np.float64)
                  - np.clip(truth.linear[..., :3], 0, 1)) * 255.0
    return float(np.sqrt(np.mean(difference ** 2))), float(np.abs(difference).max())


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--size", type=parse_size, default=(640, 480))
    parser.add_argument("--frames", type=int, default=5)
    parser.add_argument("--quick", action="store_true", help="no reference frames")
    parser.add_argument("--thresholds", default="1,2,4", help="adaptive thresholds in 8-bit steps")
    parser.add_argument("--context", choices=("egl", "osmesa"), default="egl")
    args = parser.parse_args()
    W, H = args.size
    steps = [float(t) for t in args.thresholds.split(",")]
    ctx = make_context(args.context)
    print(f"{machine()}; {ctx.info['GL_RENDERER']}; {time.strftime('%Y-%m-%d %H:%M')}")
    print(f"{W}x{H}, max depth 4, N = {N}; GPU: median of {args.frames} interleaved frames after a "
          f"warm-up ({args.context}); reference: 1 frame; error against {TRUTH_SPP} spp jittered, "
          f"in 8-bit steps")
    scenes = {"classic": load_scene("classic"), "sphere (3,968 tri)": load_scene("sphere")}
    runs = {"jittered 4": RayOptions(samples=4, pattern="jittered"),
            f"jittered {N}": RayOptions(samples=N, pattern="jittered"),
            **{f"adaptive {N} T={t:g}/255": RayOptions(samples=N, pattern="adaptive",
                                                       adaptive_threshold=t / 255) for t in steps}}
    figures = {"size": [W, H], "frames": args.frames, "context": args.context, "renderer": ctx.info["GL_RENDERER"],
               "n": N, "truth_spp": TRUTH_SPP, "rows": []}
    header = (f"{'scene':20} {'pattern':22} {'spp':>6} {'refined':>8} {'GPU ms':>8} {'ref ms':>8} "
              f"{'RMS err':>8} {'max err':>8}")
    print(header)
    print("-" * len(header))
    for name, scene in scenes.items():
        truth_options = RayOptions(samples=TRUTH_SPP, pattern="jittered", seed=TRUTH_SEED)
        with open_renderer(scene, (W, H), method="raytrace", context=ctx, options=truth_options) as tracer:
            truth = tracer.render()
        tracers = {label: open_renderer(scene, (W, H), method="raytrace", context=ctx, options=options)
                   for label, options in runs.items()}
        try:
            frames = {label: tracer.render() for label, tracer in tracers.items()}     # warm-up
            times = {label: [] for label in tracers}
            for _ in range(args.frames):
                for label, tracer in tracers.items():
                    start = time.perf_counter()
                    tracer.render()
                    times[label].append((time.perf_counter() - start) * 1000.0)
        finally:
            for tracer in tracers.values():
                tracer.release()
        rs = ray_scene(scene)
        for label, options in runs.items():
            frame = frames[label]
            ref, ref_ms = "-", None
            if not args.quick:
                twin = open_renderer(scene, (W, H), method="raytrace", backend="reference", options=options)
                twin.ray_scene = rs                              # made before, not timed
                start = time.perf_counter()
                twin.render()
                ref_ms = (time.perf_counter() - start) * 1000.0
                ref = f"{ref_ms:.0f}"
            rms, worst = error_steps(frame, truth)
            print(f"{name:20} {label:22} {frame.samples.mean():6.2f} {np.mean(frame.samples > 4):8.1%} "
                  f"{statistics.median(times[label]):8.1f} {ref:>8} {rms:8.3f} {worst:8.1f}", flush=True)
            figures["rows"].append({
                "scene": name, "pattern": options.pattern, "samples": options.samples,
                "threshold": round(options.adaptive_threshold * 255, 3) if options.pattern == "adaptive" else None,
                "mean_spp": round(float(frame.samples.mean()), 3),
                "refined": round(float(np.mean(frame.samples > 4)), 4),
                "gpu_ms": round(statistics.median(times[label]), 1),
                "reference_ms": None if ref_ms is None else round(ref_ms, 1),
                "rms_error": round(rms, 3), "largest_error": round(worst, 1)})
    print(f"\n{machine()}")
    ctx.release()
    print(f"wrote {write_results('adaptive', figures, markdown)}")


def markdown(document: dict) -> str:
    """The table of docs/ray-tracing.md, "Adaptive supersampling", made from a results document
    (write_results)."""
    figures = document["figures"]
    (W, H) = figures["size"]

    def ms(x: float) -> str:
        return f"{x:,.0f}" if x >= 100 else f"{x:.1f}"
    lines = [f"{W}×{H}, max depth 4, N = {figures['n']}. GPU path ({figures['renderer']} on {figures['context']}): "
             f"the median of {figures['frames']} frames after a warm-up, the patterns' frames interleaved; "
             f"reference: one frame. Error in 8-bit steps against a {figures['truth_spp']}-spp jittered GPU frame "
             "(another seed), over all pixels.", "",
             "| scene | pattern | mean spp | refined | GPU ms | reference ms | RMS error | largest error |",
             "| --- | --- | ---: | ---: | ---: | ---: | ---: | ---: |"]
    for row in figures["rows"]:
        first, _, rest = row["scene"].partition(" ")
        pattern = f"{row['pattern']} {row['samples']}"
        refined = ""
        if row["threshold"] is not None:
            pattern += f", threshold {row['threshold']:g}/255"
            refined = f"{row['refined']:.1%}"
        ref = "" if row["reference_ms"] is None else ms(row["reference_ms"])
        lines.append(f"| {f'`{first}` {rest}'.strip()} | {pattern} | {row['mean_spp']:.2f} | {refined} | {ms(row['gpu_ms'])} | "
                     f"{ref} | {row['rms_error']:.2f} | {row['largest_error']:.1f} |")
    return "\n".join(lines + ["", measured_line(document), ""])


if __name__ == "__main__":
    main()
