"""Two versions of the GPU ray tracer (or rasteriser) timed side by side, frames interleaved, printed.

    .venv/bin/python benchmarks/ab_raytrace.py BASE [HEAD] [--scene classic] [--size 640x480]
        [--spp 1] [--max-depth 4] [--rounds 15] [--context egl] [--method raytrace]

BASE and HEAD are git revisions of this repository (`HEAD~1`, a branch, a commit); HEAD
defaults to the working tree (`.`, uncommitted changes included). Each version is exported
whole (its renderer/ and glsl/, so a change on either side of the twin is measured as it
runs), and traces the frame in its own worker process on its own context; the workers take
turns, one frame each per round (A B, then B A, ... so that neither always goes first), and
only one runs at a time, so both see the same machine. The scene (--scene: a built-in
name, or a path; `classic` is the ray tracer's benchmark scene) is read from the working
tree for both.

`--method raster` times GpuRenderer.render() instead (the rasteriser's frame, with its depth
read back), e.g. of a scene whose programs a change should leave as they were.

Printed: each version's median RayTracer.render() time (the draw and the read-back, as
benchmarks/bench_raytrace.py), the ratio of the medians, the median of the per-round
ratios (paired, so robust to load that changes during the run), and whether the two
versions' rgba8 images are identical. Not a test: this machine is shared and noisy, which
is why the comparison is paired; the load average is printed.
"""

from __future__ import annotations

import argparse
import hashlib
import io
import json
import os
import platform
import statistics
import subprocess
import sys
import tarfile
import tempfile
import time
from pathlib import Path

ROOT = Path(__file__).resolve().parent.parent
CLASSIC = ("assets/scenes/classic.toml", "assets/raytrace/classic.toml")


def scene_path(name: str) -> str:
    """A path to the scene, absolute, or a built-in scene's name as given."""
    if name == "classic":
        name = next(p for p in CLASSIC if (ROOT / p).is_file())
    path = Path(name)
    if path.suffix == ".toml":
        return str(path if path.is_absolute() else (ROOT / path).resolve())
    return name


def export(revision: str, into: Path) -> Path:
    """The tree of `revision` (or the working tree for '.') under `into`: its Python and GLSL."""
    if revision == ".":
        return ROOT
    data = subprocess.run(["git", "-C", str(ROOT), "archive", revision, "renderer", "glsl", "reference", "assets"],
                          check=True, capture_output=True).stdout
    with tarfile.open(fileobj=io.BytesIO(data)) as archive:
        archive.extractall(into, filter="data")
    return into


def open_tracer(args, scene, ctx):
    """The exported tree's renderer of --method on `ctx`: through its open_renderer
    (renderer/methods), or, in a revision from before that factory (issue 29), by the
    classes it wraps, with the same arguments. (The tree is asked, not the import system: an
    editable install of the working tree would supply the working tree's renderer/methods.)"""
    import renderer
    if not (Path(renderer.__file__).parent / "methods").is_dir():
        return open_before_factory(args, scene, ctx)
    from renderer.methods import open_renderer
    if args.method == "raster":
        return open_renderer(scene, args.size, context=ctx)
    from renderer.core.ray_options import RayOptions
    return open_renderer(scene, args.size, method="raytrace", context=ctx,
                         options=RayOptions(samples=args.spp, max_depth=args.max_depth))


def open_before_factory(args, scene, ctx):
    """open_tracer in a revision without renderer/methods: its own constructors."""
    if args.method == "raster":
        from renderer.gpu import GpuRenderer
        return GpuRenderer(scene, *args.size, context=ctx)
    from renderer.gpu.raytracer import RayTracer
    return RayTracer(scene, *args.size, context=ctx, samples=args.spp, max_depth=args.max_depth)


def worker(args) -> None:
    """Runs in the exported tree: traces on request, one frame per line on stdin."""
    from renderer.core.scene_file import load_scene
    from renderer.gpu.context import make_context

    ctx = make_context(args.context)
    tracer = open_tracer(args, load_scene(args.scene), ctx)
    frame = tracer.render()                                   # compiles; not timed
    print(json.dumps({"rgba8": hashlib.sha256(frame.rgba8.tobytes()).hexdigest(),
                      "renderer": ctx.info["GL_RENDERER"]}), flush=True)
    for _ in sys.stdin:
        start, cpu = time.perf_counter(), time.process_time()
        tracer.render()
        print(json.dumps([(time.perf_counter() - start) * 1000.0,
                          (time.process_time() - cpu) * 1000.0]), flush=True)
    tracer.release()


def start(tree: Path, args) -> tuple[subprocess.Popen, dict]:
    env = dict(os.environ, PYTHONPATH=str(tree))
    command = [sys.executable, str(Path(__file__).resolve()), "--worker", "--scene", args.scene,
               "--size", f"{args.size[0]}x{args.size[1]}", "--spp", str(args.spp),
               "--max-depth", str(args.max_depth), "--context", args.context, "--method", args.method]
    process = subprocess.Popen(command, env=env, stdin=subprocess.PIPE, stdout=subprocess.PIPE,
                               text=True, cwd=tree)
    return process, json.loads(process.stdout.readline())


def frame_ms(process: subprocess.Popen) -> tuple[float, float]:
    """(wall, CPU) milliseconds of one frame."""
    process.stdin.write("\n")
    process.stdin.flush()
    return tuple(json.loads(process.stdout.readline()))


def load() -> str:
    return ", ".join(f"{x:.2f}" for x in os.getloadavg())


def parse_size(text: str) -> tuple[int, int]:
    width, height = text.lower().split("x")
    return int(width), int(height)


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("base", nargs="?")
    parser.add_argument("head", nargs="?", default=".")
    parser.add_argument("--scene", default="classic")
    parser.add_argument("--size", type=parse_size, default=(640, 480))
    parser.add_argument("--spp", type=int, default=1)
    parser.add_argument("--max-depth", type=int, default=4)
    parser.add_argument("--rounds", type=int, default=15)
    parser.add_argument("--context", choices=("egl", "osmesa"), default="egl")
    parser.add_argument("--method", choices=("raytrace", "raster"), default="raytrace")
    parser.add_argument("--worker", action="store_true", help=argparse.SUPPRESS)
    args = parser.parse_args()
    if args.worker:
        worker(args)
        return
    if args.base is None:
        parser.error("give the revision to compare against, e.g. HEAD~1")
    compare(args, echo=True)


def compare(args, echo: bool = False) -> dict:
    """Frames of args.base and args.head (the options of `main`) interleaved: {"wall", "cpu":
    {"a", "b", "a_min", "b_min", "ratio" (of the medians), "paired" (median of the rounds'
    ratios)}, "identical", "renderer", "load"}; printed as it goes with `echo`."""
    scene = scene_path(args.scene)
    args = argparse.Namespace(**{**vars(args), "scene": scene})
    with tempfile.TemporaryDirectory() as a_dir, tempfile.TemporaryDirectory() as b_dir:
        names = (args.base, args.head)
        processes, infos = zip(*(start(export(r, Path(d)), args) for r, d in zip(names, (a_dir, b_dir))))
        what = (f"{args.spp} spp, max depth {args.max_depth}" if args.method == "raytrace"
                else "rasterised")
        if echo:
            print(f"{platform.node()}: {os.cpu_count()} CPUs; {infos[0]['renderer']}; "
                  f"{time.strftime('%Y-%m-%d %H:%M')}; load average {load()}")
            print(f"{Path(args.scene).name} {args.size[0]}x{args.size[1]}, {what}, {args.context}; "
                  f"{args.rounds} rounds, frames interleaved")
        times = ([], [])
        for k in range(args.rounds):
            for i in ((0, 1) if k % 2 == 0 else (1, 0)):
                times[i].append(frame_ms(processes[i]))
        for process in processes:
            process.stdin.close()
            process.wait()
    result = {"identical": infos[0]["rgba8"] == infos[1]["rgba8"], "renderer": infos[0]["renderer"],
              "load": load()}
    for column, what in enumerate(("wall", "CPU")):
        t_a, t_b = ([t[column] for t in ts] for ts in times)
        a, b = statistics.median(t_a), statistics.median(t_b)
        paired = statistics.median(x / y for x, y in zip(t_a, t_b))
        result[what.lower()] = {"a": round(a, 2), "b": round(b, 2), "a_min": round(min(t_a), 2),
                                "b_min": round(min(t_b), 2), "ratio": round(a / b, 3), "paired": round(paired, 3)}
        if echo:
            print(f"  {what:4} A {a:7.1f} ms (min {min(t_a):6.1f})  B {b:7.1f} ms (min {min(t_b):6.1f})  "
                  f"A/B {a / b:.3f} (medians), {paired:.3f} (paired rounds)")
    if echo:
        print(f"  A = {names[0]}, B = {names[1]}; identical rgba8: {result['identical']}; "
              f"load average {result['load']}")
    return result


if __name__ == "__main__":
    main()
