"""The golden suite spread: under pytest in one process against pytest-xdist's workers, and
its GPU half's frames through the executor in this process against Ray workers.

    .venv/bin/python benchmarks/bench_golden_spread.py [--workers 2] [--repeats 2] [--context egl]
                     [--frames N] [-k EXPR]

1. `pytest --all tests/test_goldens.py` in one process and with `-n WORKERS`, the runs taking
   turns (benchmarks/bench_tests.py's pytest_run: wall and CPU seconds, pytest's counts, the
   golden plugin's line); the one-process runs' per-test times (junit XML) split into the
   reference half (each golden against the NumPy reference), the GPU half (the GPU's frame
   against each golden) and the rest. -k EXPR selects tests (for a short trial run).
2. The frames that tests/test_goldens.py holds to its raster goldens (every built-in scene in
   each shading mode, and as authored where modes mix, at 256x256; --frames N: the first N)
   drawn by a worker holding one GL context (renderer/cluster/executor.py), in batches of
   executor.batch_size, in this process and on a local Ray of --workers actors (its start and
   stop included), in turn; each frame's pixel digest must equal its golden sidecar's.
3. A local Ray's fixed costs: its start, the memory of its processes (the proportional set
   size, PSS, of every process under this one, summed) after the start and with --workers
   actors holding a GL context each, and each actor's start, one after another, until it has
   answered its first call with its context made.

It writes benchmarks/results/golden_spread.json (the figures, with machine, date, load and
commit) and golden_spread.md (the tables made from it: `markdown`), which docs/goldens.md
includes ("Spreading the suite"). Not a test: this machine is shared and noisy; the load
average is in the results.
"""

from __future__ import annotations

import argparse
import json
import os
import statistics
import tempfile
import time
import xml.etree.ElementTree as ElementTree
from functools import partial
from pathlib import Path

from bench_tests import pytest_run                        # benchmarks/bench_tests.py
from common import machine, measured_line, write_results  # benchmarks/common.py
from renderer.checks.goldens import pixels_sha256
from renderer.cluster.executor import InProcessExecutor, batch_size, batches_of
from renderer.core.builtin import builtin_scenes
from renderer.core.scene import SHADING_MODES
from renderer.core.scene_file import load_scene

GOLDENS = Path(__file__).resolve().parent.parent / "tests" / "goldens"
SIZE = (256, 256)
SECONDS_PER_FRAME = 0.1          # about what a golden frame costs here, for the batch size


def variants() -> list[tuple[str, str]]:
    """(scene, mode) of every raster golden, as tests/test_goldens.py lists them."""
    out = []
    for name in sorted(builtin_scenes()):
        scene = load_scene(builtin_scenes()[name])
        modes = [*SHADING_MODES, *(["as-authored"] if len(scene.shading_modes()) > 1 else [])]
        out += [(name, mode) for mode in modes]
    return out


class GoldenWorker:
    """Draws golden frames on one context; answers each frame's pixels_sha256 (the sidecar's)."""

    def __init__(self, context_kind: str):
        self.context_kind, self.ctx = context_kind, None

    def run(self, batch: list[tuple[str, str]]) -> list[str]:
        from renderer.gpu.context import make_context
        from renderer.methods import open_renderer
        self.ctx = self.ctx or make_context(self.context_kind)
        digests = []
        for name, mode in batch:
            scene = load_scene(builtin_scenes()[name])
            scene = scene if mode == "as-authored" else scene.with_shading(mode)
            with open_renderer(scene, SIZE, context=self.ctx) as gpu:
                digests.append(pixels_sha256(gpu.render(depth=False).rgba8))
        return digests


def timed_run(open_executor, units: list, context_kind: str) -> tuple[float, int]:
    """(wall seconds, workers) of every unit through the executor open_executor() makes."""
    start = time.perf_counter()
    with open_executor() as executor:
        batches = batches_of(units, batch_size(SECONDS_PER_FRAME, len(units), executor.workers))
        for index, digests in executor.map(partial(GoldenWorker, context_kind), batches):
            for (name, mode), digest in zip(batches[index], digests):
                sidecar = json.loads((GOLDENS / f"{name}-{mode}.json").read_text())
                assert digest == sidecar["rgba_sha256"], f"{name}-{mode} differs from its golden"
        workers = executor.workers
    return time.perf_counter() - start, workers


def halves(junit: Path) -> dict:
    """Seconds of the tests in a junit XML file (setup, call and teardown), by half:
    "reference" (a golden against the NumPy reference), "gpu" (the GPU's frame against a
    golden), "other"; and "tests", their number."""
    seconds = {"reference": 0.0, "gpu": 0.0, "other": 0.0}
    cases = list(ElementTree.parse(junit).iter("testcase"))
    for case in cases:
        name = case.get("name")
        half = ("gpu" if name.startswith(("test_gpu_matches_golden", "test_ray_tracer_matches_golden"))
                else "reference" if "reference" in name.split("[")[0] else "other")
        seconds[half] += float(case.get("time"))
    return {half: round(value, 1) for half, value in seconds.items()} | {"tests": len(cases)}


def pytest_runs(workers: int, repeats: int, select: str | None) -> list[dict]:
    """The golden suite under pytest, in one process and with -n workers, in turn."""
    arguments = ["--all", "tests/test_goldens.py", *(["-k", select] if select else [])]
    runs = []
    with tempfile.TemporaryDirectory(prefix="bench-golden-spread-") as folder:
        for repeat in range(repeats):
            for kind, options in (("one process", []), (f"-n {workers}", ["-n", str(workers)])):
                junit = Path(folder) / f"{repeat}.xml" if not options else None
                run = {"run": kind} | pytest_run([*arguments, *options], junit)
                if junit is not None:
                    run["halves"] = halves(junit)
                print(f"pytest, {kind:12s} {run['seconds']:6.1f} s, CPU {run['cpu_seconds']:6.1f} s: "
                      f"{run['counts']}; goldens: {run['goldens']}", flush=True)
                runs.append(run)
    return runs


def process_memory(pid: int) -> int:
    """Bytes of a process's proportional set size (PSS; its VmRSS where smaps_rollup is not
    there), 0 once it has gone."""
    try:
        rollup = Path(f"/proc/{pid}/smaps_rollup")
        text = rollup.read_text() if rollup.exists() else Path(f"/proc/{pid}/status").read_text()
    except OSError:
        return 0
    for line in text.splitlines():
        if line.startswith(("Pss:", "VmRSS:")):
            return int(line.split()[1]) * 1024
    return 0


def descendants(pid: int) -> list[int]:
    """Every process under pid (/proc/*/stat's parent ids)."""
    children: dict[int, list[int]] = {}
    for stat in Path("/proc").glob("[0-9]*/stat"):
        try:
            fields = stat.read_text().rpartition(")")[2].split()
        except OSError:
            continue
        children.setdefault(int(fields[1]), []).append(int(stat.parent.name))
    found, queue = [], [pid]
    while queue:
        for child in children.get(queue.pop(), []):
            found.append(child)
            queue.append(child)
    return found


def ray_costs(workers: int, context_kind: str) -> dict:
    """A local Ray's start (s), its processes' memory (bytes) after it and with `workers`
    actors holding a GL context each, and each actor's start until its first answer (s)."""
    import ray
    from renderer.cluster.ray_executor import LocalRay, WorkerHost

    def memory() -> int:
        return sum(map(process_memory, descendants(os.getpid())))

    start = time.perf_counter()
    local = LocalRay(workers)
    started = time.perf_counter() - start
    try:
        time.sleep(1.0)                                   # let its processes settle
        at_start = memory()
        host = ray.remote(WorkerHost).options(num_cpus=1)
        actors, actor_s = [], []
        for _ in range(workers):
            start = time.perf_counter()
            actors.append(host.remote(partial(GoldenWorker, context_kind), False))
            ray.get(actors[-1].run.remote([]))            # the actor's first call makes its context
            actor_s.append(round(time.perf_counter() - start, 2))
        with_actors = memory()
    finally:
        local.stop()
    return {"version": ray.__version__, "start_s": round(started, 1), "memory": at_start,
            "memory_with_actors": with_actors, "actors": workers, "actor_s": actor_s}


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--workers", type=int, default=2)
    parser.add_argument("--repeats", type=int, default=2, help="runs of each kind, in turn")
    parser.add_argument("--context", choices=("egl", "osmesa"), default="egl")
    parser.add_argument("--frames", type=int, default=None, help="only the first N golden frames")
    parser.add_argument("-k", dest="select", default=None, help="pytest -k: only these tests")
    args = parser.parse_args()
    from renderer.cluster.ray_executor import RayExecutor
    print(f"before: {machine()}")
    suite = pytest_runs(args.workers, args.repeats, args.select)
    units = variants()[:args.frames]
    frames = []
    for _ in range(args.repeats):
        here, _ = timed_run(InProcessExecutor, units, args.context)
        ray, workers = timed_run(lambda: RayExecutor(workers=args.workers), units, args.context)
        print(f"{len(units)} golden frames at {SIZE[0]}x{SIZE[1]}, each equal to its golden: "
              f"in this process: {here:.1f} s; on a local Ray of {workers} workers: {ray:.1f} s "
              f"(start and stop included); ratio {here / ray:.2f}", flush=True)
        frames.append({"here_s": round(here, 2), "ray_s": round(ray, 2), "workers": workers})
    costs = ray_costs(args.workers, args.context)
    print(f"a local Ray {costs['version']}: start {costs['start_s']:.1f} s, its processes "
          f"{costs['memory'] / 2**20:.0f} MiB (PSS), {costs['memory_with_actors'] / 2**20:.0f} MiB "
          f"with {costs['actors']} actors; each actor's start with its context: {costs['actor_s']} s")
    print(f"after: {machine()}")
    figures = {"suite": suite, "frames": {"count": len(units), "size": list(SIZE), "runs": frames},
               "ray": costs}
    print(f"wrote {write_results('golden_spread', figures, markdown)}")


def markdown(document: dict) -> str:
    """The tables of docs/goldens.md ("Spreading the suite"), made from a results document."""
    f = document["figures"]
    mib = 1 << 20
    lines = ["The golden suite under pytest (`pytest --all tests/test_goldens.py`), the runs "
             "taking turns:", "",
             "| run | wall s | CPU s | tests | golden checks | reference half s | GPU half s | rest s |",
             "| --- | ---: | ---: | --- | --- | ---: | ---: | ---: |"]
    for run in f["suite"]:
        half = run.get("halves")
        times = (f"{half['reference']:.1f} | {half['gpu']:.1f} | {half['other']:.1f}" if half
                 else " | | ")
        lines.append(f"| {run['run']} | {run['seconds']:.1f} | {run['cpu_seconds']:.1f} | "
                     + ", ".join(f"{n} {word}" for word, n in run["counts"].items())
                     + f" | {run['goldens'] or ''} | {times} |")
    kinds = list(dict.fromkeys(run["run"] for run in f["suite"]))
    median = {kind: statistics.median(r["seconds"] for r in f["suite"] if r["run"] == kind)
              for kind in kinds}
    one = [run["halves"] for run in f["suite"] if run.get("halves")]
    per_test = statistics.median((h["reference"] + h["gpu"] + h["other"]) / h["tests"] for h in one)
    lines += ["", f"Wall time in one process over that with `{kinds[1]}` (medians): "
                  f"{median[kinds[0]] / median[kinds[1]]:.2f}. The halves are the one-process "
                  f"runs' own test times (junit XML: set-up, call and tear-down); a test costs "
                  f"{per_test:.2f} s on average.", ""]
    frames, ray = f["frames"], f["ray"]
    workers = frames["runs"][0]["workers"]
    lines += [f"The {frames['count']} raster golden frames at {frames['size'][0]}×{frames['size'][1]}, "
              f"each equal to its golden, drawn on one GL context per worker:", "",
              f"| in this process, s | on a local Ray of {workers} workers (its start and stop "
              f"included), s |", "| ---: | ---: |"]
    lines += [f"| {run['here_s']:.2f} | {run['ray_s']:.2f} |" for run in frames["runs"]]
    lines += ["", f"A local Ray ({ray['version']}) alone: its start {ray['start_s']:.1f} s; its "
                  f"processes' memory (PSS, summed) {ray['memory'] / mib:.0f} MiB after the start, "
                  f"{ray['memory_with_actors'] / mib:.0f} MiB with {ray['actors']} actors holding a "
                  f"GL context each; an actor's start until its first answer, its context made: "
                  + ", ".join(f"{s:.2f}" for s in ray["actor_s"]) + " s.",
              "", measured_line(document), ""]
    return "\n".join(lines)


if __name__ == "__main__":
    main()
