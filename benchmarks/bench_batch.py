"""Batch rendering on Ray: items/s with 1 and 2 workers and in this process, the scaling
efficiency, what an item and a call cost, and whether every run wrote the same bytes.

    python benchmarks/bench_batch.py [--size 320x240] [--views 40] [--repeats 2]

The job (issue 19): 5 raster scenes x 40 orbit views = 200 items at 320x240, an sRGB png8
each. One local Ray with 2 CPUs serves every Ray run (its start is timed once, apart);
the runs take turns (in-process, Ray 1 worker, Ray 2 workers, then again), so that all see
the same load, and each writes a fresh folder with `run_job`, as `renderer batch` does.

Printed per run kind (medians of the repeats):
- wall s and items/s of the whole job (actors started, contexts made, shaders compiled);
- 1st item s (until the first item is written) and steady items/s (after it);
- the batch size run_plan chose (executor.batch_size);
- worker ms per item (render + encode, wall, measured on the worker) and CPU ms per item
  (CpuClock: the workers' processes, all threads, after the first batch), which stays put
  where the wall time grows because other work shares the cores;
- driver ms per item (writing the files and the manifest record: the one serial part, so
  the ceiling of a cluster of any size);
- the machine's busy cores meanwhile (/proc/stat, every process: other sessions' work too).
Then the scaling efficiency rate(2) / (2 x rate(1)), the local Ray's start, a call's round
trip on an actor (alone, and with IN_FLIGHT queued), and whether all runs' manifests hold
the same SHA-256 for every file.

It writes benchmarks/results/batch.json (the figures, with machine, date, load and commit)
and batch.md (the table made from it: `markdown`), which docs/cluster.md includes.
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

from common import machine, measured_line, parser, write_results

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
    orbit = f"cameras = {{ orbit = {{ views = {views} }} }}"
    scenes = "".join(f'[[scenes]]\nscene = "{name}"\n{orbit}\n\n' for name in SCENES)
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
            kinds = {"in-process": InProcessExecutor,
                     "ray, 1 worker": lambda: RayExecutor(workers=1),
                     "ray, 2 workers": lambda: RayExecutor(workers=2)}
            runs = {kind: [] for kind in kinds}
            for repeat in range(args.repeats):
                for kind, make in kinds.items():
                    with make() as executor:
                        out = folder / f"out-{repeat}-{kind.replace(' ', '').replace(',', '')}"
                        runs[kind].append(run_once(job, out, executor))
                    shutil.rmtree(out)
            alone, queued = call_overhead_ms()
        finally:
            local.stop()
        figures = report(runs, job, ray_start, alone, queued)
    finally:
        shutil.rmtree(folder, ignore_errors=True)
    print(f"after: {machine()}")
    figures["job"] = {"scenes": len(SCENES), "views": args.views, "size": [width, height],
                      "repeats": args.repeats}
    print(f"wrote {write_results('batch', figures, markdown)}")


def report(runs: dict, job, ray_start: float, alone: float, queued: float) -> dict:
    """Prints the table and the lines below it; the figures, for the results file."""
    items = runs["in-process"][0]["items"]
    rows = []
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
        rows.append({"run": kind, "workers": workers, "seconds": round(median["seconds"], 2),
                     "items_per_s": round(rates[kind], 1), "first_item_s": round(median["first_s"], 2),
                     "steady_items_per_s": round(steady[kind], 1), "batch": size,
                     "worker_ms": round(median["item_ms"], 1), "cpu_ms": round(median["cpu_ms"], 1),
                     "driver_ms": round(median["driver_ms"], 2),
                     "busy_cores": round(median["busy_cores"], 2)})
    one, two = "ray, 1 worker", "ray, 2 workers"
    print(f"scaling efficiency rate(2) / (2 x rate(1)) = {rates[two] / (2 * rates[one]):.2f} "
          f"(steady: {steady[two] / (2 * steady[one]):.2f}); "
          f"Ray 1 worker / in-process = {rates[one] / rates['in-process']:.2f}")
    print(f"local Ray start: {ray_start:.1f} s (once per `renderer batch` without --address)")
    print(f"a call's round trip (empty batch): {alone:.2f} ms alone, {queued:.2f} ms with "
          f"{IN_FLIGHT} in flight")
    every = [r["hashes"] for results in runs.values() for r in results]
    same = all(hashes == every[0] for hashes in every)
    print(f"manifests: {len(every)} runs, {items} items each: "
          f"{'the same SHA-256 for every file' if same else 'HASHES DIFFER'}")
    return {"items": items, "runs": rows,
            "efficiency": round(rates[two] / (2 * rates[one]), 2),
            "steady_efficiency": round(steady[two] / (2 * steady[one]), 2),
            "ray_1_over_in_process": round(rates[one] / rates["in-process"], 2),
            "ray_start_s": round(ray_start, 1), "call_ms": round(alone, 2),
            "call_queued_ms": round(queued, 2), "in_flight": IN_FLIGHT,
            "runs_compared": len(every), "same_bytes": same}


def markdown(document: dict) -> str:
    """The table of docs/cluster.md ("How it scales"), made from a results document."""
    f = document["figures"]
    job = f["job"]
    lines = [f"{job['scenes']} scenes × {job['views']} orbit views = {f['items']} items at "
             f"{job['size'][0]}×{job['size'][1]}, an sRGB png8 each; the runs take turns, "
             f"{job['repeats']} of each kind (medians):", "",
             "| run | wall s | items/s | 1st item s | steady items/s | batch | worker ms/item "
             "| CPU ms/item | driver ms/item | machine busy, cores |",
             "| --- | ---: | ---: | ---: | ---: | ---: | ---: | ---: | ---: | ---: |"]
    for r in f["runs"]:
        lines.append(f"| {r['run']} | {r['seconds']:.2f} | {r['items_per_s']:.1f} | "
                     f"{r['first_item_s']:.2f} | {r['steady_items_per_s']:.1f} | {r['batch']} | "
                     f"{r['worker_ms']:.1f} | {r['cpu_ms']:.1f} | {r['driver_ms']:.2f} | "
                     f"{r['busy_cores']:.2f} |")
    ray = [r for r in f["runs"] if r["run"] != "in-process"]
    driver_ms = max(r["driver_ms"] for r in ray)
    cpu_ms = max(r["cpu_ms"] for r in ray)
    lines += ["",
              f"Scaling efficiency rate(2 workers) / (2 × rate(1 worker)): {f['efficiency']:.2f} "
              f"with the start, {f['steady_efficiency']:.2f} steady; 1 Ray worker against one "
              f"process: {f['ray_1_over_in_process']:.2f} of its rate. A local Ray's start: "
              f"{f['ray_start_s']:.1f} s. A call's round trip (an empty batch, on one actor): "
              f"{f['call_ms']:.2f} ms alone, {f['call_queued_ms']:.2f} ms with {f['in_flight']} "
              f"in flight. The driver's writing (the one serial part, up to {driver_ms:.2f} ms "
              f"an item) caps a cluster at about {1000 / driver_ms:,.0f} items/s at this item "
              f"size, some {cpu_ms / driver_ms:.0f} workers of {cpu_ms:.1f} CPU-ms an item. "
              f"{f['runs_compared']} runs' manifests: "
              + ("the same SHA-256 for every file." if f["same_bytes"] else "the files' SHA-256 DIFFER."),
              "", measured_line(document), ""]
    return "\n".join(lines)


if __name__ == "__main__":
    main()
