"""Radiosity's cost against its element count (issue 33), printed and written to
benchmarks/results/radiosity.json and .md (docs/radiosity.md includes the .md):

    .venv/bin/python benchmarks/bench_radiosity.py [--sizes 0.12,0.08,0.05,0.035] [--hemicube 64]
                                                   [--twin-up-to 1500]

The Cornell box (scene cornell_box_radiosity) cut at each element size: the form factors drawn
on the GPU (llvmpipe) and summed (hemicubes per second, the drawing and the summing apart), the
twin's hemicubes per second where there are at most --twin-up-to elements (its O(E^2) NumPy
rasterisation), the sparse matrix's stored pairs and bytes, the peak of Python's allocations
while the matrix is made (tracemalloc; GL's own memory is not in it), and each solver's time,
iterations and final residual (Gauss-Seidel and progressive refinement, tolerance 1e-6).
Medians of --repeats runs of the GPU's form factors. Not a test: this machine is shared and noisy.
"""

from __future__ import annotations

import argparse
import statistics
import time
import tracemalloc

import numpy as np

from reference.radiosity.item_buffer import draw as twin_draw
from renderer.core.builtin import builtin_scenes
from renderer.core.form_factors import form_factors, rows_from_items
from renderer.core.radiosity import elements_for
from renderer.core.radiosity_options import RadiosityOptions
from renderer.core.radiosity_solve import gauss_seidel, progressive
from renderer.core.scene_file import load_scene
from renderer.gpu.context import make_context
from renderer.gpu.item_buffers import ItemBuffers

from common import measured_line, write_results          # benchmarks/common.py


def measure(ctx, scene, size: float, n: int, repeats: int, twin_up_to: int) -> dict:
    elements = elements_for(scene, RadiosityOptions(element_size=size, hemicube=n))
    count = len(elements)
    buffers = ItemBuffers(ctx, elements, n)
    try:
        drawing, summing, totals = [], [], []
        for _ in range(repeats):
            draw_s = sum_s = 0.0
            start = time.perf_counter()
            for first in range(0, count, buffers.batch):
                t0 = time.perf_counter()
                items = buffers.draw(np.arange(first, min(first + buffers.batch, count)))
                t1 = time.perf_counter()
                rows_from_items(items, n, count)
                draw_s, sum_s = draw_s + t1 - t0, sum_s + time.perf_counter() - t1
            totals.append(time.perf_counter() - start)
            drawing.append(draw_s)
            summing.append(sum_s)
        tracemalloc.start()
        matrix = form_factors(count, n, buffers.draw, buffers.batch)
        peak = tracemalloc.get_traced_memory()[1]
        tracemalloc.stop()
    finally:
        buffers.release()
    row = {"element_size": size, "elements": count, "hemicube": n,
           "gpu_s": statistics.median(totals), "draw_s": statistics.median(drawing),
           "sum_s": statistics.median(summing), "pairs": int(len(matrix.values)),
           "matrix_bytes": int(matrix.nbytes), "peak_bytes": int(peak)}
    row["hemicubes_per_s"] = count / row["gpu_s"]
    if count <= twin_up_to:
        sample = np.arange(0, count, max(1, count // 64))
        start = time.perf_counter()
        twin_draw(elements, n, sample)
        row["twin_hemicubes_per_s"] = len(sample) / (time.perf_counter() - start)
    for name, solver in (("gauss_seidel", lambda: gauss_seidel(matrix, elements.reflectance, elements.emission,
                                                                tolerance=1e-6)),
                         ("progressive", lambda: progressive(matrix, elements.areas, elements.reflectance,
                                                             elements.emission, tolerance=1e-6))):
        start = time.perf_counter()
        solution = solver()
        row[f"{name}_s"] = time.perf_counter() - start
        row[f"{name}_iterations"] = solution.iterations
        row[f"{name}_residual"] = solution.residuals[-1]
        row[f"{name}_converged"] = solution.converged
    return row


def markdown(document: dict) -> str:
    """docs/radiosity.md's table, from a results document (write_results)."""
    figures = document["figures"]
    lines = [f"The Cornell box (`cornell_box_radiosity`) at each element size, hemicubes of "
             f"{figures['hemicube']}; the GPU's form factors the median of {figures['repeats']} runs "
             "(drawn, then summed); the twin's on a sample of the hemicubes; memory: the sparse "
             "matrix and the peak of Python's allocations while it is made; the solvers to a "
             "residual of 1e-6 (sweeps or shots).", "",
             "| element size | elements | GPU hemicubes/s | drawn | summed | twin hemicubes/s | pairs | "
             "matrix | peak | Gauss-Seidel | sweeps | progressive | shots |",
             "| ---: | ---: | ---: | ---: | ---: | ---: | ---: | ---: | ---: | ---: | ---: | ---: | ---: |"]
    mib = lambda b: f"{b / 2 ** 20:.1f} MiB"       # noqa: E731
    for r in figures["rows"]:
        twin = f"{r['twin_hemicubes_per_s']:.0f}" if "twin_hemicubes_per_s" in r else "not run"
        lines.append(f"| {r['element_size']:g} | {r['elements']:,} | {r['hemicubes_per_s']:.0f} | "
                     f"{r['draw_s']:.2f} s | {r['sum_s']:.2f} s | {twin} | {r['pairs']:,} | "
                     f"{mib(r['matrix_bytes'])} | {mib(r['peak_bytes'])} | {r['gauss_seidel_s']:.2f} s | "
                     f"{r['gauss_seidel_iterations']} | {r['progressive_s']:.2f} s | {r['progressive_iterations']:,} |")
    return "\n".join(lines) + "\n\n" + measured_line(document) + "\n"


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--sizes", default="0.12,0.08,0.05,0.035")
    parser.add_argument("--hemicube", type=int, default=64)
    parser.add_argument("--repeats", type=int, default=3)
    parser.add_argument("--twin-up-to", type=int, default=1500)
    parser.add_argument("--context", choices=("egl", "osmesa"), default="egl")
    args = parser.parse_args()
    scene = load_scene(builtin_scenes()["cornell_box_radiosity"])
    ctx = make_context(args.context)
    rows = []
    for size in (float(s) for s in args.sizes.split(",")):
        row = measure(ctx, scene, size, args.hemicube, args.repeats, args.twin_up_to)
        rows.append(row)
        print(f"size {size:g}: {row['elements']:,} elements, {row['hemicubes_per_s']:.0f} hemicubes/s "
              f"(draw {row['draw_s']:.2f} s, sum {row['sum_s']:.2f} s), {row['pairs']:,} pairs, "
              f"peak {row['peak_bytes'] / 2 ** 20:.1f} MiB, Gauss-Seidel {row['gauss_seidel_s']:.2f} s "
              f"({row['gauss_seidel_iterations']}), progressive {row['progressive_s']:.2f} s "
              f"({row['progressive_iterations']})", flush=True)
    path = write_results("radiosity", {"hemicube": args.hemicube, "repeats": args.repeats, "rows": rows},
                         markdown)
    print(f"wrote {path}")


if __name__ == "__main__":
    main()
