"""Peak memory of the GPU path and the reference against image size and triangle count, beside
the estimate renderer/core/memory.py makes before rendering, and the limit refusing before
anything is allocated.

    .venv/bin/python benchmarks/bench_memory.py            # sizes up to 2048x2048 (a minute or two)
    .venv/bin/python benchmarks/bench_memory.py --full     # and 4096x4096

"gpu rt" and "reference rt" rows: a 488,600-triangle mesh ray traced at 64x64 (the estimate:
renderer/core/memory.py's raytrace_*_bytes).

Then whole commands under a limit (renderer/study/peak_memory.py): `renderer render` of a
large mesh file (loaded, merged and creased, then ray traced or rasterised) and of a large
texture, each with --max-memory set to the command's own estimate (the larger of loading's
step and the renderers' Need), and the 5,005,448-triangle PLY refused at 3G and 5G: the
estimate, the limit and the whole process's measured peak (VmHWM).

It writes benchmarks/results/memory.json (the figures, with machine, date, load and commit)
and memory.md (the tables made from it: `markdown`), which docs/memory.md includes.

Each case runs in a new process; the figure is its peak resident memory (ru_maxrss) above
what the process held after importing and building the scene, so that the baseline of
Python, NumPy and the scene is left out; the estimate is the same difference.
"""

from __future__ import annotations

import argparse
import json
import subprocess
import sys
import tempfile
import time
from pathlib import Path

from common import machine, measured_line, revision, write_results

CHILD = r"""
import json, resource, sys, warnings
warnings.simplefilter("ignore")
backend, width, height, segments = sys.argv[1], int(sys.argv[2]), int(sys.argv[3]), int(sys.argv[4])
method = sys.argv[5] if len(sys.argv) > 5 else "raster"
import reference.pipeline, renderer.gpu.pipeline     # open_renderer's backends, loaded before the baseline
import reference.raytrace.pipeline, renderer.gpu.raytracer
from renderer.core import memory
from renderer.core.scene_file import scene_from_dict
from renderer.methods import open_renderer
scene = scene_from_dict({
    "camera": {"eye": [0, 0, 4], "look": [0, 0, 0]},
    "lights": [{"type": "directional", "direction": [0, -0.5, -1]}],
    "objects": [{"name": "ball", "material": {"shading": "phong"},
                 "mesh": {"primitive": "uv_sphere", "segments": segments, "rings": segments // 2}}]})
triangles = sum(o.mesh.triangle_count for o in scene.objects)
before = resource.getrusage(resource.RUSAGE_SELF).ru_maxrss * 1024
with open_renderer(scene, (width, height), method=method, backend=backend, context_kind="egl") as r:
    frame = r.render(depth=True)
estimate = {("raster", "gpu"): memory.gpu_bytes, ("raster", "reference"): memory.reference_bytes,
            ("raytrace", "gpu"): memory.raytrace_gpu_bytes,
            ("raytrace", "reference"): memory.raytrace_reference_bytes}[method, backend](width, height, triangles)
peak = resource.getrusage(resource.RUSAGE_SELF).ru_maxrss * 1024
print(json.dumps({"triangles": triangles, "measured": peak - before, "estimate": estimate}))
"""


def measure(backend: str, width: int, height: int, segments: int, method: str = "raster") -> dict:
    start = time.perf_counter()
    result = subprocess.run([sys.executable, "-c", CHILD, backend, str(width), str(height),
                             str(segments), method], capture_output=True, text=True, check=True)
    return json.loads(result.stdout.splitlines()[-1]) | {"seconds": time.perf_counter() - start}


def refusal(width: int, height: int, limit: str) -> dict:
    """`renderer render` at a size over the limit: its status, its one line, its peak memory
    (the whole process's, renderer/study/peak_memory.py) and its wall time."""
    from renderer.study.peak_memory import measure_command
    run = measure_command("render", "sphere", "--size", f"{width}x{height}", "--max-memory", limit,
                          "-o", "/tmp/never.png")
    return {"status": run.status, "line": run.stderr.strip(), "peak": run.peak, "seconds": run.seconds}


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--full", action="store_true", help="also 4096x4096")
    args = parser.parse_args()
    mib = 1 << 20
    sizes = [256, 1024, 2048] + ([4096] if args.full else [])
    print(f"{'backend':10} {'size':>11} {'triangles':>10} {'measured MiB':>13} {'estimate MiB':>13} "
          f"{'estimate/measured':>18} {'s':>6}")
    cases = [(b, s, 8, "raster") for b in ("gpu", "reference") for s in sizes]
    cases += [(b, 256, segments, "raster") for b in ("gpu", "reference") for segments in (256, 1024)]
    # A large mesh ray traced (ray_scene, the BVH and its build, the GPU's float textures).
    cases += [(b, 64, 700, "raytrace") for b in ("gpu", "reference")]
    estimates = []
    for backend, size, segments, method in cases:
        r = measure(backend, size, size, segments, method)
        name = backend if method == "raster" else f"{backend} rt"
        print(f"{name:10} {f'{size}x{size}':>11} {r['triangles']:>10,} {r['measured'] / mib:>13.0f} "
              f"{r['estimate'] / mib:>13.0f} {r['estimate'] / max(r['measured'], 1):>18.2f} "
              f"{r['seconds']:>6.1f}")
        estimates.append({"backend": backend, "method": method, "size": [size, size]} | r)
    r = refusal(16384, 16384, "1G")
    print(f"\nrenderer render sphere --size 16384x16384 --max-memory 1G: status {r['status']} in "
          f"{r['seconds']:.1f} s, peak {r['peak'] / mib:.0f} MiB (the whole process)\n  {r['line']}")
    figures = {"estimates": estimates, "refusal": r, "whole_commands": under_limits()}
    print(f"wrote {write_results('memory', figures, markdown)}")


def markdown(document: dict) -> str:
    """The tables of docs/memory.md, made from a results document (write_results)."""
    mib = 1 << 20
    figures = document["figures"]
    lines = ["| path | size | triangles | measured MiB | estimate MiB |", "| --- | ---: | ---: | ---: | ---: |"]
    for r in figures["estimates"]:
        path = ("GPU" if r["backend"] == "gpu" else "reference") + (", ray traced" if r["method"] == "raytrace" else "")
        lines.append(f"| {path} | {r['size'][0]}×{r['size'][1]} | {r['triangles']:,} | "
                     f"{r['measured'] / mib:.0f} | {r['estimate'] / mib:.0f} |")
    refusal = figures["refusal"]
    lines += ["", f"`renderer render sphere --size 16384x16384 --max-memory 1G`: status "
              f"{refusal['status']} in {refusal['seconds']:.1f} s, a peak of {refusal['peak'] / mib:.0f} MiB "
              f"for the whole process.", "",
              "Whole commands (`renderer render` at 64×48; the peak is the process's VmHWM):", "",
              "| case | estimate MiB | limit | peak MiB | peak / limit | status | s |",
              "| --- | ---: | ---: | ---: | ---: | ---: | ---: |"]
    for r in figures["whole_commands"]:
        lines.append(f"| {r['case']} | {r['estimate'] / mib:.0f} | {r['limit']} | {r['peak'] / mib:.0f} | "
                     f"{r['share']:.2f} | {r['status']} | {r['seconds']:.1f} |")
    return "\n".join(lines + ["", measured_line(document), ""])


def under_limits() -> list[dict]:
    """Whole commands under --max-memory (module docstring): a row each."""
    from renderer.core import memory
    from renderer.core.textures import TEXTURE_BYTES_PER_TEXEL
    from renderer.methods import METHODS
    from renderer.study.peak_memory import grid_scene, measure_command, texture_scene
    mib = 1 << 20
    print(f"\nWhole commands, renderer render at 64x48 (peak: VmHWM of the process)\n"
          f"{'case':44} {'estimate MiB':>12} {'limit':>6} {'peak MiB':>9} {'peak/limit':>10} "
          f"{'status':>6} {'s':>6}")
    rows = []

    def row(case, estimate, limit, *args):
        run = measure_command("render", *args, "--size", "64x48", "--max-memory", limit, "-q",
                              "-o", Path(folder) / "out.png")
        share = run.peak / memory.parse_size(limit)
        print(f"{case:44} {estimate / mib:>12.0f} {limit:>6} {run.peak / mib:>9.0f} {share:>10.2f} "
              f"{run.status:>6} {run.seconds:>6.1f}", flush=True)
        rows.append({"case": case, "estimate": estimate, "limit": limit, "peak": run.peak,
                     "share": share, "status": run.status, "seconds": run.seconds})
        if run.status:
            print(f"  {run.stderr.strip()}")

    def method_options(method):
        return ["--method", method, "--backend", backend]

    with tempfile.TemporaryDirectory() as folder:
        scene, triangles = grid_scene(Path(folder), 707)
        for method, backend in (("raytrace", "gpu"), ("raytrace", "reference"), ("raster", "gpu"),
                                ("raster", "reference")):
            need = METHODS[method].need((64, 48), [backend], METHODS[method].options())
            estimate = max(memory.PROCESS_BYTES + triangles * memory.MESH_BUILD_BYTES_PER_TRIANGLE,
                           need.bytes_for(triangles))
            row(f"{triangles:,}-triangle PLY, {method} {backend}", estimate,
                f"{estimate // mib + 1}M", scene, *method_options(method))
        scene = texture_scene(Path(folder), 4096)
        for method, backend in (("raster", "gpu"), ("raster", "reference"), ("raytrace", "gpu")):
            need = METHODS[method].need((64, 48), [backend], METHODS[method].options())
            estimate = max(memory.PROCESS_BYTES + 4096 * 4096 * TEXTURE_BYTES_PER_TEXEL,
                           need.bytes_for(2))
            row(f"4096x4096 texture, {method} {backend}", estimate, f"{estimate // mib + 1}M",
                scene, *method_options(method))
        scene, triangles = grid_scene(Path(folder), 1582)
        backend = "gpu"
        need = METHODS["raytrace"].need((64, 48), ["gpu"], METHODS["raytrace"].options())
        for limit in ("3G", "5G"):
            row(f"{triangles:,}-triangle PLY, raytrace gpu", need.bytes_for(triangles), limit,
                scene, *method_options("raytrace"))
    print(f"\n{machine()}; {revision()}; {time.strftime('%Y-%m-%d')}")
    return rows


if __name__ == "__main__":
    main()
