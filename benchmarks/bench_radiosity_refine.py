"""Radiosity's refinement and its lights held against the path tracer (issue 33), printed and
written to benchmarks/results/radiosity_refine.json and .md (docs/radiosity.md includes the .md):

    .venv/bin/python benchmarks/bench_radiosity_refine.py [--size 80x60] [--truth-frames 8]
                                                          [--levels 0,1,2,3]

The open room lit through a window (scene radiosity_window): no surface emits; the sun, a
directional light, reaches radiosity through its light buffer (renderer/core/light_buffers.py)
and the path tracer through next-event estimation, and the sky (the background) through what
each hemicube sees of nothing and through paths that leave. The truth: the GPU path tracer's
average of --truth-frames frames of 256 paths a pixel. Radiosity at its default options and
each refinement level (--refine: elements cut where the display would differ from their
radiosity by more than 4 levels, renderer/core/radiosity.py needs_refining), timed from
nothing (light buffers, hemicubes, solution, display) on the GPU (llvmpipe), its display drawn
at 4 times the size and each 4 x 4 block averaged (renderer/checks/radiosity_vs_pathtrace.py
footprint_image); against the truth, on 8-bit levels of the clamped linear colour, the mean
over the pixels of |difference| x 255 and its 95th percentile. And the lights' own check: the
floor's power from the light buffer, the sum of H A over its elements, against the sun's power
through the window, I A_window cos. Not a test: this machine is shared and noisy.
"""

from __future__ import annotations

import argparse
import time

import numpy as np

from renderer.checks.radiosity_vs_pathtrace import FOOTPRINT, footprint_image, path_traced
from renderer.core.builtin import builtin_scenes
from renderer.core.path_options import PathOptions
from renderer.core.radiosity_options import RadiosityOptions
from renderer.core.scene_file import load_scene
from renderer.gpu.context import make_context
from renderer.methods import open_renderer

from common import measured_line, write_results          # benchmarks/common.py

WINDOW_AREA = 1.6 * 1.1                                   # assets/scenes/radiosity_window.toml


def measure(ctx, size, level: int, truth: np.ndarray) -> dict:
    scene = load_scene(builtin_scenes()["radiosity_window"])
    width, height = size
    start = time.perf_counter()
    with open_renderer(scene, (FOOTPRINT * width, FOOTPRINT * height), method="radiosity",
                       options=RadiosityOptions(refine=level), context=ctx) as renderer:
        frame = renderer.render(linear=True)
        solution = renderer.solution
    seconds = time.perf_counter() - start
    levels = np.abs(footprint_image(frame, width, height) - truth) * 255.0
    sun = scene.directional_lights[0]
    direction = np.asarray(sun.direction, np.float64) / np.linalg.norm(sun.direction)
    floor = solution.elements.obj == 0
    power = (solution.irradiance[floor] * solution.elements.areas[floor, None]).sum(axis=0)
    through_window = np.asarray(sun.intensity) * WINDOW_AREA * -direction[0]
    return {"refine": level, "levels_made": solution.levels, "elements": len(solution.elements),
            "seconds": seconds, "mean_levels": float(levels.mean()),
            "p95_levels": float(np.percentile(levels, 95)),
            "floor_power_error": float(np.abs(power / through_window - 1).max())}


def markdown(document: dict) -> str:
    """docs/radiosity.md's table, from a results document (write_results)."""
    f = document["figures"]
    lines = [f"`radiosity_window` at {f['size']}, radiosity at its default options and each level of "
             f"refinement against {f['truth_paths']:,} paths a pixel (the truth's standard error "
             f"{f['truth_error'] * 255:.2f} levels), each timed from nothing on the GPU; the floor's "
             "light-buffer power against the sun's through the window.", "",
             "| refine | elements | time | mean difference | 95th percentile | floor's power |",
             "| ---: | ---: | ---: | ---: | ---: | ---: |"]
    for r in f["rows"]:
        lines.append(f"| {r['refine']} | {r['elements']:,} | {r['seconds']:.1f} s | {r['mean_levels']:.2f} levels | "
                     f"{r['p95_levels']:.2f} levels | {100 * r['floor_power_error']:.2f} % off |")
    return "\n".join(lines) + "\n\n" + measured_line(document) + "\n"


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--size", default="80x60")
    parser.add_argument("--truth-frames", type=int, default=8)
    parser.add_argument("--levels", default="0,1,2,3")
    parser.add_argument("--context", choices=("egl", "osmesa"), default="egl")
    args = parser.parse_args()
    size = tuple(int(v) for v in args.size.split("x"))
    ctx = make_context(args.context)
    scene = load_scene(builtin_scenes()["radiosity_window"])
    truth, truth_s, truth_error = path_traced(scene, size, PathOptions(samples=256), args.truth_frames,
                                              first=1 << 24, context=ctx)
    truth = np.clip(truth, 0.0, 1.0)
    print(f"truth: {256 * args.truth_frames} paths a pixel in {truth_s:.1f} s, "
          f"standard error {truth_error * 255:.2f} levels", flush=True)
    rows = []
    for level in (int(v) for v in args.levels.split(",")):
        row = measure(ctx, size, level, truth)
        rows.append(row)
        print(f"refine {level}: {row['elements']:,} elements, {row['seconds']:.1f} s, mean "
              f"{row['mean_levels']:.2f} levels, 95th percentile {row['p95_levels']:.2f}, floor's power "
              f"{100 * row['floor_power_error']:.2f} % off", flush=True)
    path = write_results("radiosity_refine", {"size": args.size, "truth_paths": 256 * args.truth_frames,
                                              "truth_error": truth_error, "truth_s": truth_s, "rows": rows},
                         markdown)
    print(f"wrote {path}")


if __name__ == "__main__":
    main()
