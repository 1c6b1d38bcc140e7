"""Batch rendering on Ray: items/s with 1 and 2 workers and in this process, the scaling
efficiency, what an item and a call cost, and whether every run wrote the same bytes.

    python benchmarks/bench_batch.py [--size 320x240] [--views 40] [--repeats 2]

The job (issue 19): 5 raster scenes x 40 orbit views = 200 items at 320x240, an sRGB png8
each. One local Ray with 2 CPUs serves every Ray run (its start is timed once, apart);
the runs take turns (in-process, Ray 1 worker, Ray 2 workers, then again), so that all see
the same load, and each writes a fresh folder with `run_job`, as `renderer batch` does.

Printed: per run kind the median wall seconds of the job (actors started, contexts made,
shaders compiled, every file written), items/s, the batch size run_plan chose and the
worker-measured ms per item (render + encode); the scaling efficiency rate(2) / (2 rate(1));
the driver's ms per item (writing the files and the manifest record: the one serial part,
so the ceiling of a cluster of any size); CPU ms per item after the first batch (CpuClock), which stays
put where wall time grows because other work shares the cores, and how many of the machine's
cores were busy meanwhile (all processes, /proc/stat: other sessions' work shows here); a call's round trip on an actor, alone and with
IN_FLIGHT calls queued; and whether all runs' manifests hold the same SHA-256 per file.
"""

from __future__ import annotations

import functools
import json
import os
import shutil
import statistics
import tempfile
import time
from pathlib import Path

from common import machine, parser

from renderer.batch import run as batch_run
from renderer.batch.items import expand
from renderer.batch.job_file import read_job
from renderer.batch.manifest import MANIFEST
from renderer.cluster.executor import InProcessExecutor, batch_size
from renderer.cluster.ray_executor import IN_FLIGHT, LocalRay, RayExecutor, WorkerHost

SCENES = ("sphere", "hierarchy", "coloured_lights", "flat_shading", "shadow_plane")
CPUS = 2
CALLS = 300                 # round trips timed for a call's overhead


class NoWork:
    """A worker that does nothing: what is left of a call is Ray's overhead."""

    def run(self, batch):
        return batch


def job_text(width: int, height: int, views: int) -> str:
    scenes = "".join(f'[[scenes]]\nscene = "{name}"\ncameras = {{ orbit = {{ views = {views} }} }}\n\n'
                     for name in SCENES)
    return (f'name = "bench-batch"\nseed = 7\nsize = [{width}, {height}]\n\n{scenes}'
            '[[settings]]\nname = "raster"\noutputs = [{ format = "png8", transfer = "srgb" }]\n')


def manifest(out: Path) -> list[dict]:
    return [json.loads(line) for line in (out / MANIFEST).read_text().splitlines()[1:]]


def file_hashes(out: Path) -> dict:
    return {record["key"]: [o["sha256"] for o in record["outputs"]] for record in manifest(out)}


class DriverClock:
    """Seconds the driver spends writing items (batch/run.py's _Writer.write), summed, and
    when the first and the last write began (perf_counter)."""

    def __init__(self):
        self.seconds = 0.0
        self.first = self.last = None
        self._write = batch_run._Writer.write

    def __enter__(self):
        original = self._write

        @functools.wraps(original)
        def timed(writer, *args, **kwargs):
            start = time.perf_counter()
            self.first = start if self.first is None else self.first
            self.last = start
            try:
                return original(writer, *args, **kwargs)
            finally:
                self.seconds += time.perf_counter() - start
        batch_run._Writer.write = timed
        return self

    def __exit__(self, *exc):
        batch_run._Writer.write = self._write


def cpu_seconds(pid: int) -> float:
    """User + system CPU seconds of a process, all its threads (/proc/PID/stat)."""
    fields = Path(f"/proc/{pid}/stat").read_text().rpartition(")")[2].split()
    return (int(fields[11]) + int(fields[12])) / os.sysconf("SC_CLK_TCK")


def machine_busy() -> tuple[float, float]:
    """(busy CPU seconds of the whole machine, perf_counter) from /proc/stat's cpu line."""
    ticks = [int(x) for x in Path("/proc/stat").read_text().split("\n", 1)[0].split()[1:]]
    idle = ticks[3] + ticks[4]                      # idle, iowait
    return (sum(ticks[:8]) - idle) / os.sysconf("SC_CLK_TCK"), time.perf_counter()


class CpuClock:
    """The executor, and the CPU seconds per item its workers spent between the first and
    the last batch handed on (start-up left out): on Ray read from the actors' processes
    (all threads; the map ends them after its last batch), in-process from this process
    (the driver's writing included)."""

    def __init__(self, executor):
        self.executor, self.per_item, self.busy_cores = executor, None, None
        self.kind, self.workers, self.describe = executor.kind, executor.workers, executor.describe

    def _now(self) -> float:
        if self.executor.kind == "ray":
            return sum(map(cpu_seconds, self.executor.worker_pids))
        return time.process_time()

    def map(self, factory, batches):
        first = None
        for count, (index, results) in enumerate(self.executor.map(factory, batches), 1):
            if count == 1:
                first, first_items, busy = self._now(), len(results), machine_busy()
            elif count == len(batches):
                total = sum(map(len, batches))
                self.per_item = (self._now() - first) / (total - first_items)
                (busy_end, end), (busy_start, start) = machine_busy(), busy
                self.busy_cores = (busy_end - busy_start) / (end - start)
            yield index, results


def run_once(job, out: Path, executor) -> dict:
    """The job's figures: wall seconds, seconds to the first item written (actors, contexts,
    shaders), items/s after it (steady), worker and driver ms per item, the files' hashes."""
    clock = CpuClock(executor)
    with DriverClock() as driver:
        start = time.perf_counter()
        summary = batch_run.run_job(job, out, clock, progress=False, say=lambda line: None)
    assert not summary.failed, summary.failed
    records = manifest(out)
    return {"seconds": summary.seconds, "items": summary.done, "first_s": driver.first - start,
            "cpu_ms": clock.per_item * 1e3, "busy_cores": clock.busy_cores,
            "steady": (summary.done - 1) / (driver.last - driver.first),
            "driver_ms": driver.seconds * 1e3 / summary.done,
            "item_ms": statistics.median(r["render_ms"] + r["encode_ms"] for r in records),
            "hashes": file_hashes(out)}


def call_overhead_ms() -> tuple[float, float]:
    """(ms per call alone, ms per call with IN_FLIGHT queued) of an empty batch on one actor."""
    import ray
    actor = ray.remote(WorkerHost).options(num_cpus=1).remote(NoWork, False)
    ray.get(actor.run.remote([0]))
    start = time.perf_counter()
    for n in range(CALLS):
        ray.get(actor.run.remote([n]))
    alone = (time.perf_counter() - start) * 1e3 / CALLS
    start = time.perf_counter()
    refs = [actor.run.remote([n]) for n in range(IN_FLIGHT)]
    for n in range(IN_FLIGHT, CALLS + IN_FLIGHT):
        ray.get(refs.pop(0))
        if n < CALLS:
            refs.append(actor.run.remote([n]))
    queued = (time.perf_counter() - start) * 1e3 / CALLS
    ray.kill(actor)
    return alone, queued


def main() -> None:
    options = parser(__doc__, "views", 40)
    options.add_argument("--repeats", type=int, default=2)
    args = options.parse_args()
    width, height = args.size if args.size != (640, 480) else (320, 240)
    print(f"bench_batch: {len(SCENES)} scenes x {args.views} views at {width}x{height}, png8; "
          f"{args.repeats} repeats in turn")
    print(f"before: {machine()}")
    folder = Path(tempfile.mkdtemp(prefix="bench-batch-"))
    try:
        job_path = folder / "job.toml"
        job_path.write_text(job_text(width, height, args.views))
        job = read_job(job_path)
        start = time.perf_counter()
        local = LocalRay(CPUS)
        ray_start = time.perf_counter() - start
        try:
            kinds = {"in-process": InProcessExecutor, "ray, 1 worker": lambda: RayExecutor(workers=1),
                     "ray, 2 workers": lambda: RayExecutor(workers=2)}
            runs = {kind: [] for kind in kinds}
            for repeat in range(args.repeats):
                for kind, make in kinds.items():
                    with make() as executor:
                        out = folder / f"out-{len(runs[kind])}-{kind.replace(' ', '').replace(',', '')}"
                        runs[kind].append(run_once(job, out, executor))
                    shutil.rmtree(out)
            alone, queued = call_overhead_ms()
        finally:
            local.stop()
        report(runs, job, ray_start, alone, queued)
    finally:
        shutil.rmtree(folder, ignore_errors=True)
    print(f"after: {machine()}")


def report(runs: dict, job, ray_start: float, alone: float, queued: float) -> None:
    items = runs["in-process"][0]["items"]
    print(f"{'run':15s} {'wall s':>6s} {'items/s':>7s} {'1st item s':>10s} {'steady/s':>8s} "
          f"{'batch':>5s} {'worker ms/item':>14s} {'CPU ms/item':>11s} {'driver ms/item':>14s} "
          f"{'machine busy':>12s}")
    rates, steady = {}, {}
    for kind, results in runs.items():
        median = {name: statistics.median(r[name] for r in results)
                  for name in ("seconds", "first_s", "steady", "item_ms", "cpu_ms", "driver_ms",
                               "busy_cores")}
        rates[kind], steady[kind] = items / median["seconds"], median["steady"]
        workers = 2 if "2" in kind else 1
        size = batch_size(max(map(batch_run.item_seconds, expand(job))), items, workers)
        print(f"{kind:15s} {median['seconds']:6.2f} {rates[kind]:7.1f} {median['first_s']:10.2f} "
              f"{steady[kind]:8.1f} {size:5d} {median['item_ms']:14.1f} {median['cpu_ms']:11.1f} "
              f"{median['driver_ms']:14.1f} {median['busy_cores']:7.2f} cores")
    one, two = "ray, 1 worker", "ray, 2 workers"
    print(f"scaling efficiency rate(2) / (2 x rate(1)) = {rates[two] / (2 * rates[one]):.2f} "
          f"(steady: {steady[two] / (2 * steady[one]):.2f}); "
          f"Ray 1 worker / in-process = {rates[one] / rates['in-process']:.2f}")
    print(f"local Ray start: {ray_start:.1f} s (once per `renderer batch` without --address)")
    print(f"a call's round trip (empty batch): {alone:.2f} ms alone, {queued:.2f} ms with "
          f"{IN_FLIGHT} in flight")
    every = [r["hashes"] for results in runs.values() for r in results]
    print(f"manifests: {len(every)} runs, {items} items each: "
          f"{'the same SHA-256 for every file' if all(h == every[0] for h in every) else 'HASHES DIFFER'}")


if __name__ == "__main__":
    main()
