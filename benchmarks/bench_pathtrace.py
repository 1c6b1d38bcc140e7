"""The path tracer's speed and error against run time, and radiosity held against it (issue 33),
printed and written to benchmarks/results/pathtrace.json and .md (docs/pathtrace.md includes
the .md):

    .venv/bin/python benchmarks/bench_pathtrace.py [--size 160x120] [--truth-frames 16]
                                                   [--sizes 0.12,0.08,0.05,0.035,0.025] [--hemicube 64]

The Cornell box (scene cornell_box_radiosity), its light an emitting surface, which both methods
read the same way (docs/pathtrace.md, "Units"). The truth: the GPU path tracer's average of
--truth-frames frames of 256 paths a pixel, each frame new samples (first_sample). Paths per
second on the GPU (llvmpipe) at --size and 64 paths a pixel, and by the twin at a quarter of the
pixels and 16 paths. Then, against the truth, on 8-bit levels of the clamped linear colour (the
mean over the pixels of |difference| x 255, and its 95th percentile):
- the path tracer at 16, 64 and 256 paths a pixel (error against time: Monte Carlo's slope -1/2);
- radiosity (Gauss-Seidel, hemicubes of --hemicube) at each element size: its form factors,
  solution and display timed together, the display drawn at 4 times the size and each 4 x 4
  block averaged (renderer/checks/radiosity_vs_pathtrace.py footprint_image: the pixel's mean, as the
  truth's paths; a pixel-centre image would add its edges' aliasing to radiosity's error);
- and element by element, for the element sizes of at most --elements-up-to elements (the
  twin's paths are slow): each
  element's radiosity B_i against its path-traced value, the mean over --element-paths paths
  of the twin's path_trace (float32) started by a ray onto a uniform point of the element along
  its normal: what the path tracer shows of that point, pi L, its exitance B for a Lambertian
  surface (emission, next-event estimation, bounces), with the paths' standard error: the
  area-weighted mean |difference| in 8-bit levels of the clamped B, and its RMS with the paths'
  variance taken out (radiosity's own error, unbiased), the emitting elements left out (their
  B is E, far above 1).
The truth's own noise is in every row (its standard error is printed). Not a test: this
machine is shared and noisy.
"""

from __future__ import annotations

import argparse
import math
import time

import numpy as np

from renderer.core.builtin import builtin_scenes
from renderer.core.path_options import PathOptions
from renderer.core.radiosity_options import RadiosityOptions
from renderer.core.scene_file import load_scene
from renderer.gpu.context import make_context
from renderer.methods import open_renderer
from renderer.checks.radiosity_vs_pathtrace import FOOTPRINT, footprint_image, path_traced

from common import measured_line, write_results          # benchmarks/common.py

TRUTH_SAMPLES = 256
TRUTH_FIRST = 1 << 24          # the truth's sample indices: none of the rows' (they start at 0)


def levels(image, truth):
    """(mean, 95th percentile) of |clamped image - clamped truth| in 8-bit levels."""
    d = np.abs(np.clip(image, 0, 1) - np.clip(truth, 0, 1)).max(-1) * 255
    return float(d.mean()), float(np.percentile(d, 95))


def path_frames(scene, size, samples, frames, ctx, first=0):
    """(mean linear RGB over `frames` frames of `samples` paths from sample index `first`,
    seconds, the standard error of the mean from the frames' spread)."""
    return path_traced(scene, size, PathOptions(samples=samples), frames, first=first, context=ctx)


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--size", default="160x120")
    parser.add_argument("--truth-frames", type=int, default=16)
    parser.add_argument("--sizes", default="0.12,0.08,0.05,0.035,0.025")
    parser.add_argument("--hemicube", type=int, default=64)
    parser.add_argument("--elements-up-to", type=int, default=1500)
    parser.add_argument("--element-paths", type=int, default=2048)
    args = parser.parse_args()
    size = tuple(int(v) for v in args.size.split("x"))
    scene = load_scene(builtin_scenes()["cornell_box_radiosity"])
    ctx = make_context("egl")
    pixels = size[0] * size[1]

    truth, truth_s, truth_error = path_frames(scene, size, TRUTH_SAMPLES, args.truth_frames, ctx, TRUTH_FIRST)
    print(f"truth: {TRUTH_SAMPLES * args.truth_frames} paths a pixel in {truth_s:.1f} s, "
          f"standard error {truth_error:.2g}", flush=True)
    _, gpu_s, _ = path_frames(scene, size, 64, 1, ctx)
    small = (size[0] // 2, size[1] // 2)
    start = time.perf_counter()
    with open_renderer(scene, small, method="pathtrace", backend="reference",
                       options=PathOptions(samples=16)) as twin:
        twin.render()
    twin_s = time.perf_counter() - start
    speed = {"gpu_paths_per_s": pixels * 64 / gpu_s, "twin_paths_per_s": small[0] * small[1] * 16 / twin_s}
    print(f"GPU {speed['gpu_paths_per_s'] / 1e6:.3f} M paths/s, twin {speed['twin_paths_per_s'] / 1e6:.3f} M paths/s",
          flush=True)

    path_rows = []
    for samples in (16, 64, 256):
        image, seconds, _ = path_frames(scene, size, samples, 1, ctx)
        mean, p95 = levels(image, truth)
        path_rows.append({"samples": samples, "seconds": seconds, "mean_levels": mean, "p95_levels": p95})
        print(f"pathtrace {samples} spp: {seconds:.2f} s, mean {mean:.2f} levels, p95 {p95:.1f}", flush=True)
    radiosity_rows = []
    for element_size in (float(s) for s in args.sizes.split(",")):
        options = RadiosityOptions(element_size=element_size, hemicube=args.hemicube)
        start = time.perf_counter()
        with open_renderer(scene, (FOOTPRINT * size[0], FOOTPRINT * size[1]), method="radiosity",
                           options=options, context=ctx) as radiosity:
            image = footprint_image(radiosity.render(linear=True), *size)
            solution = radiosity.solution
        seconds = time.perf_counter() - start
        elements = len(solution.elements)
        mean, p95 = levels(image, truth)
        row = {"element_size": element_size, "elements": elements, "seconds": seconds,
               "mean_levels": mean, "p95_levels": p95}
        if elements <= args.elements_up_to:
            row.update(per_element(scene, solution, args.element_paths))
        radiosity_rows.append(row)
        per = (f"; per element {row['element_levels']:.2f} levels (paths' standard error "
               f"{row['element_noise_levels']:.2f}; RMS less the noise {row['element_rms_levels']:.2f})"
               if "element_levels" in row else "")
        print(f"radiosity {element_size:g} ({elements:,} elements): {seconds:.2f} s, mean {mean:.2f} "
              f"levels, p95 {p95:.1f}{per}", flush=True)
    figures = {"size": list(size), "truth_paths": TRUTH_SAMPLES * args.truth_frames, "truth_s": truth_s,
               "truth_standard_error": truth_error, "hemicube": args.hemicube, **speed,
               "pathtrace": path_rows, "radiosity": radiosity_rows}
    print(f"wrote {write_results('pathtrace', figures, markdown)}")


def per_element(scene, solution, paths: int, chunk: int = 1 << 18) -> dict:
    """Radiosity's B_i against E_i + rho_i H_i path traced (module docstring): the area-weighted
    mean |difference| and the mean standard error of the paths' values, in 8-bit levels."""
    from reference.lighting import Lights
    from reference.raytrace.pathtrace import path_trace
    from reference.raytrace.sampling import RaySamples
    from renderer.core.path_emitters import path_emitters
    from renderer.core.ray_sampling import ray_sampling
    from renderer.core.raytrace_scene import ray_scene
    elements, b = solution.elements, solution.solution.radiosity
    rs = ray_scene(scene)
    eye = np.asarray(scene.camera.eye, np.float64)
    lights = Lights.from_scene(scene, np.float32, origin=eye)
    emitters = path_emitters(scene, rs)
    sampling = ray_sampling("random", 1, seed=7)
    rng = np.random.default_rng(7)
    count = len(elements)
    owner = np.repeat(np.arange(count), paths)
    r1, r2 = np.sqrt(rng.random(len(owner))), rng.random(len(owner))
    corners = elements.corners[owner] - eye
    points = (corners[:, 0] * (1 - r1)[:, None] + corners[:, 1] * (r1 * (1 - r2))[:, None]
              + corners[:, 2] * (r1 * r2)[:, None])
    n = elements.normals[owner]
    origins, directions = points + 1e-4 * n, -n        # onto the point, from just in front
    values = np.zeros((len(owner), 3))
    for first in range(0, len(owner), chunk):
        part = slice(first, first + chunk)
        k = np.arange(first, min(first + chunk, len(owner)), dtype=np.uint32)
        samples = RaySamples(owner[part].astype(np.uint32), np.zeros(len(k), np.uint32), k, 0, sampling)
        values[part] = path_trace(rs, lights, origins[part].astype(np.float32), directions[part].astype(np.float32),
                                  0.0, np.inf, scene.background, 32, True, None, samples, None,
                                  emitters=emitters)[0]
    B = values.reshape(count, paths, 3)
    traced, noise = B.mean(axis=1), B.std(axis=1, ddof=1) / np.sqrt(paths)
    shown = ~(elements.emission > 0).any(axis=1)
    weights = elements.areas[shown] / elements.areas[shown].sum()
    difference = (np.clip(b, 0, 1) - np.clip(traced, 0, 1))[shown] * 255
    noise = noise[shown] * 255
    # the mean square difference less the paths' variance: radiosity's own RMS error, unbiased
    excess = float(weights @ (difference ** 2 - noise ** 2).mean(axis=1))
    return {"element_levels": float(weights @ np.abs(difference).max(axis=1)),
            "element_noise_levels": float(weights @ noise.max(axis=1)),
            "element_rms_levels": math.sqrt(max(excess, 0.0)), "element_paths": paths}


def slope(rows) -> float:
    """The least-squares slope of log(mean error) against log(seconds)."""
    x = np.log([r["seconds"] for r in rows])
    y = np.log([r["mean_levels"] for r in rows])
    return float(np.polyfit(x, y, 1)[0])


def markdown(document: dict) -> str:
    """docs/pathtrace.md's tables, from a results document (write_results)."""
    f = document["figures"]
    w, h = f["size"]
    lines = [f"The Cornell box (`cornell_box_radiosity`) at {w}x{h}. The path tracer on the GPU "
             f"(llvmpipe): {f['gpu_paths_per_s'] / 1e6:.3f} M paths a second; the twin "
             f"{f['twin_paths_per_s'] / 1e6:.3f} M (at a quarter of the pixels). The truth: "
             f"{f['truth_paths']:,} paths a pixel ({f['truth_s']:.0f} s; standard error "
             f"{f['truth_standard_error']:.1e}). Differences from it in 8-bit levels of the clamped "
             "colour, the mean over the pixels and the 95th percentile:", "",
             "Radiosity's display is drawn at 4 times the size and box-filtered: the pixel's mean.", "",
             "| method | setting | time | mean | 95th percentile |",
             "| --- | --- | ---: | ---: | ---: |"]
    for r in f["pathtrace"]:
        lines.append(f"| path tracing | {r['samples']} paths a pixel | {r['seconds']:.2f} s | "
                     f"{r['mean_levels']:.2f} | {r['p95_levels']:.1f} |")
    for r in f["radiosity"]:
        lines.append(f"| radiosity | elements of {r['element_size']:g} ({r['elements']:,}), hemicubes of "
                     f"{f['hemicube']} | {r['seconds']:.2f} s | {r['mean_levels']:.2f} | {r['p95_levels']:.1f} |")
    lines += ["", f"Slope of the mean error against time: path tracing {slope(f['pathtrace']):.2f} "
              f"(Monte Carlo: -0.5), radiosity {slope(f['radiosity']):.2f}."]
    by_element = [r for r in f["radiosity"] if "element_levels" in r]
    if by_element:
        lines += ["", "Element by element: each element's radiosity against its path-traced value "
                  f"({by_element[0]['element_paths']:,} paths onto uniform points of it; the emitting "
                  "elements left out), area-weighted, in 8-bit levels:", "",
                  r"| elements | mean \|difference\| | paths' standard error | RMS less the paths' noise |",
                  "| ---: | ---: | ---: | ---: |"]
        lines += [f"| {r['elements']:,} | {r['element_levels']:.2f} | {r['element_noise_levels']:.2f} | "
                  f"{r['element_rms_levels']:.2f} |" for r in by_element]
    lines += ["", measured_line(document)]
    return "\n".join(lines) + "\n"


if __name__ == "__main__":
    main()
