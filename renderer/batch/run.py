"""Running a job: plan (check everything, read what DIR holds), then render the rest on an
executor's workers and write each item as its result arrives.

    with locked(out) as out:                     # one driver per DIR (folder.py)
        plan = plan_job(job, out, compare=False) # UserError before anything is written
        with open_executor(address, workers) as executor:
            summary = run_plan(plan, executor)   # or run_job(job, out, executor)

Only this driver writes: each item's files in one `outputs()` transaction (all or none),
then its manifest record (renderer/batch/manifest.py). A worker killed mid-item leaves
nothing, and an interrupted job resumes where it stopped.

Batches: the items to do are grouped by renderer (scene and setting, items.Item.group) and
cut into batches of executor.batch_size(estimate, ...), so that a worker reuses one
renderer along a batch; `item_seconds` estimates an item's cost from its pixels and
samples (measured here, Mesa llvmpipe: about 40 ms for a raster item at 320x240 with its PNG,
60-150 ms for 4 ray-traced samples per pixel), enough to size batches near
TARGET_BATCH_SECONDS. Nothing of the result depends on the batches.

With --compare every item is also drawn by the NumPy reference (executor.tasks, plain
tasks) and compared as `renderer compare` does: its gpu.png, reference.png and diff.png go
to the item's compare/ folder and the figures into its record.

Every file goes under DIR through real folders only (folder.check_inside, at the plan and
again before each item is written). Ctrl-C (KeyboardInterrupt) while the items render is
raised again as Interrupted, which says how many of the job's items are complete: the
items written so far keep their files and records, the one being written is all or none.
"""

from __future__ import annotations

import contextlib
import functools
import hashlib
import os
import signal
import sys
import threading
import time
from dataclasses import dataclass, field
from pathlib import Path

from renderer.batch.folder import check_inside, locked
from renderer.batch.items import ITEMS_FOLDER, Item, Job, expand, job_identity
from renderer.batch.manifest import MANIFEST, Manifest, Resume, header_for, read_manifest
from renderer.batch.job_file import need
from renderer.methods import METHODS
from renderer.batch.render_item import ItemResult, ItemWorker, item_scene, load_source, reference_item
from renderer.cluster.executor import batch_size, batches_of, worker_label
from renderer.core import memory
from renderer.core.imageio import check_folder, check_outputs, outputs

COMPARE_FILES = ("gpu.png", "reference.png", "diff.png")
ITEM_OVERHEAD_S = 0.02            # per item: camera update, read-back, hashing
# Per pixel and sample (Method.samples: the ray tracer's samples times light samples), with
# the output stage and PNG encoding; a method not measured costs the most of them.
PIXEL_SAMPLE_S = {"raster": 2.5e-7, "raytrace": 1.5e-7}


def item_seconds(item: Item) -> float:
    """A rough cost of one item on llvmpipe (module docstring), for batch sizes only."""
    setting = item.setting
    pixels = setting.size[0] * setting.size[1]
    per_sample = PIXEL_SAMPLE_S.get(setting.method, max(PIXEL_SAMPLE_S.values()))
    return ITEM_OVERHEAD_S + pixels * per_sample * METHODS[setting.method].samples(setting.options)


def compare_files(item: Item) -> tuple[str, ...]:
    return tuple(f"{ITEMS_FOLDER}/{item.key}/compare/{name}" for name in COMPARE_FILES)


@dataclass
class Plan:
    """A checked job and what of it is left to do in `out` (nothing written yet)."""
    job: Job
    out: Path
    items: list[Item]
    todo: list[Item]
    resume: Resume
    compare: bool = False


def plan_job(job: Job, out, *, compare: bool = False, say=None) -> Plan:
    """Check the output folder, every output name and DIR's manifest (another job's is a
    UserError); the items whose records do not count are the ones to do. `say` gets the
    warning line for records dropped unread (manifest.Resume.warning)."""
    out = check_folder(out)
    items = expand(job)
    if compare:                      # the reference's memory too (job_file checked the GPU's)
        for item in {(item.scene.digest, item.setting.name): item for item in items}.values():
            both = need(item.setting, ["gpu", "reference"])
            with memory.planned(both):
                scene = load_source(item.scene)
            both.check(item_scene(scene, item))
    wanted = {item.key: [*item.files, *(compare_files(item) if compare else ())] for item in items}
    check_outputs(out / MANIFEST, *(out / path for paths in _to_check(out, wanted) for path in paths))
    check_inside(out, (path for paths in wanted.values() for path in paths))
    header = header_for(job, job_identity(job, items), len(items))
    resume = read_manifest(out, header, wanted)
    if resume.warning() is not None:
        (say or say_above_bar)(resume.warning())
    todo = [item for item in items if item.key not in resume.records]
    return Plan(job, out, items, todo, resume, compare)


def _to_check(out: Path, wanted: dict[str, list[str]]):
    """The items' files for check_outputs: the first item's (its folders on the way are
    every item's, and where one is not a folder the line says so as for any output) and
    those of items whose folder is already there (a folder where a file goes). The files of
    an item whose folder is not there yet are new names under real folders (check_inside),
    each its own (keys and names are unique): asking for each would cost a job of many
    items seconds of stat calls."""
    for n, (key, paths) in enumerate(wanted.items()):
        if n == 0 or os.path.lexists(out / ITEMS_FOLDER / key):
            yield paths


@dataclass
class Summary:
    """What a run did: items in the job, skipped (already complete), done now, failed
    (key, error), seconds rendering, and per worker (host/pid) the items and busy
    milliseconds; `wall`: the command's whole time (the driver sets it: reading the job,
    starting and stopping the workers included), when known."""
    items: int
    skipped: int
    done: int = 0
    failed: list[tuple[str, str]] = field(default_factory=list)
    seconds: float = 0.0
    wall: float | None = None
    where: str = ""
    workers: dict[str, list] = field(default_factory=dict)

    def lines(self) -> list[str]:
        if self.skipped == self.items:
            return [f"batch: {self.items} items: all already complete, nothing to render"]
        rate = self.done / self.seconds if self.seconds > 0 else 0.0
        whole = "" if self.wall is None else \
            f"; {self.wall:.1f} s in all, with reading the job and starting and stopping the workers"
        lines = [f"batch: {self.items} items: {self.done} rendered, {self.skipped} already "
                 f"complete, {len(self.failed)} failed, in {self.seconds:.1f} s "
                 f"({rate:.1f} items/s; {self.where}){whole}"]
        for label, (count, busy_ms) in sorted(self.workers.items()):
            lines.append(f"batch: worker {label}: {count} items, "
                         f"{count / (busy_ms / 1000.0) if busy_ms > 0 else 0.0:.1f} items/s busy")
        return lines


def _record(item: Item, result: ItemResult, files: dict[str, bytes], compare: dict | None) -> dict:
    record = {"key": item.key, "seed": item.seed, "setting": item.setting.describe(),
              "camera": item.camera.describe(), "overrides": dict(item.scene.overrides),
              "outputs": [{"path": path, "sha256": hashlib.sha256(data).hexdigest(),
                           "pixels_sha256": result.pixels.get(path)}
                          for path, data in files.items()],
              "render_ms": round(result.render_ms, 3), "encode_ms": round(result.encode_ms, 3),
              "worker": result.worker}
    if compare is not None:
        record["compare"] = compare
    return record


class _Writer:
    """Writes finished items and keeps the summary's counts."""

    def __init__(self, plan: Plan, summary: Summary, say):
        self.out, self.summary, self.say = plan.out, summary, say
        self.manifest = Manifest(plan.resume).begin()

    def failed(self, key: str, error: str, bug: bool = False) -> None:
        self.summary.failed.append((key, error))
        if bug:
            _above_bar(error.rstrip("\n"))
        self.say(f"{key}: failed: {error.strip().splitlines()[-1]}")

    def write(self, item: Item, result: ItemResult, extra: dict[str, bytes] | None = None,
              compare: dict | None = None) -> None:
        files = dict(result.files) | (extra or {})
        check_inside(self.out, files)                 # no link made since the plan
        with _interrupts_held():                      # files, record and count: all or none
            with outputs() as written:                # the item's files: all or none
                for path, data in files.items():
                    written.bytes(self.out / path, data)
            self.manifest.append(_record(item, result, files, compare))
            self.summary.done += 1
        label = worker_label(result.worker)
        counts = self.summary.workers.setdefault(label, [0, 0.0])
        counts[0] += 1
        counts[1] += result.render_ms + result.encode_ms


@contextlib.contextmanager
def _interrupts_held():
    """Ctrl-C held off while the block runs (in the main thread), then raised: an item is
    written with its record and counted, or not at all, and the count said is the manifest's."""
    if threading.current_thread() is not threading.main_thread():
        yield
        return
    caught = []
    previous = signal.signal(signal.SIGINT, lambda number, frame: caught.append(number))
    try:
        yield
    finally:
        signal.signal(signal.SIGINT, previous)
        if caught:
            raise KeyboardInterrupt


def _above_bar(text: str) -> None:
    """Lines on stderr that a progress bar running there leaves whole."""
    from tqdm import tqdm
    tqdm.write(text, file=sys.stderr)


def say_above_bar(line: str) -> None:
    """`renderer: LINE` on stderr, above the progress bar: run_plan's default `say`."""
    _above_bar(f"renderer: {line}")


def _bar(total: int, unit: str, progress: bool):
    from tqdm import tqdm
    return tqdm(total=total, unit=unit, file=sys.stderr, mininterval=0.5, dynamic_ncols=True,
                disable=not progress or total == 0)


class Interrupted(KeyboardInterrupt):
    """Ctrl-C while a job's items rendered: how many of them are complete (written before,
    or now), for the one line `renderer batch` ends with (status 130)."""

    def __init__(self, complete: int, items: int):
        super().__init__(complete, items)
        self.complete, self.items = complete, items

    def line(self) -> str:
        return (f"interrupted; {self.complete} of {self.items} items done; run the same "
                f"command to resume")


def run_plan(plan: Plan, executor, *, context_kind: str = "auto", progress: bool = True,
             say=say_above_bar) -> Summary:
    """Render and write the plan's items on `executor` (renderer/cluster/executor.py);
    Ctrl-C is raised as Interrupted."""
    summary = Summary(len(plan.items), len(plan.items) - len(plan.todo), where=executor.describe())
    try:
        return _run(plan, executor, summary, context_kind, progress, say)
    except KeyboardInterrupt:
        raise Interrupted(summary.skipped + summary.done, summary.items) from None


def _run(plan: Plan, executor, summary: Summary, context_kind: str, progress: bool,
         say) -> Summary:
    start = time.perf_counter()
    writer = _Writer(plan, summary, say)
    todo = sorted(plan.todo, key=lambda item: item.group)          # stable: file order within
    size = batch_size(max(map(item_seconds, todo), default=0.0), len(todo), executor.workers)
    batches = batches_of(todo, size)
    factory = functools.partial(ItemWorker, context_kind, keep_frames=plan.compare)
    held = []                                  # --compare: GPU results awaiting the reference
    # closed on the way out: a Ctrl-C while an item is written (outside the generator) cancels
    # the calls in flight and stops the actors here, not when the exception is freed, after
    # the executor has closed (Ray then retries them, and says so on stdout)
    with _bar(len(todo), "item", progress) as bar, \
            contextlib.closing(executor.map(factory, batches)) as finished:
        for index, results in finished:
            for item, result in zip(batches[index], results):
                if result.error is not None:
                    writer.failed(item.key, result.error, result.bug)
                elif plan.compare:
                    held.append((item, result))
                else:
                    writer.write(item, result)
                bar.update(1)
    if held:
        _compare(held, executor, writer, progress)
    summary.seconds = time.perf_counter() - start
    return summary


def _compare(held, executor, writer: _Writer, progress: bool) -> None:
    """The reference of each held item, in plain tasks; then its files and record."""
    args = [(item, *result.frame) for item, result in held]
    with _bar(len(held), "reference", progress) as bar, \
            contextlib.closing(executor.tasks(reference_item, args)) as finished:
        for index, outcome in finished:
            item, result = held[index]
            if outcome.error is not None:
                writer.failed(item.key, outcome.error, outcome.bug)
            else:
                result.frame = None
                writer.write(item, result, dict(zip(compare_files(item), outcome.files)),
                             outcome.figures)
            bar.update(1)


def run_job(job: Job, out, executor, *, compare: bool = False, context_kind: str = "auto",
            progress: bool = True, say=say_above_bar) -> Summary:
    """plan_job then run_plan, `out` locked: the job's items not yet complete in `out`,
    rendered and written."""
    with locked(out) as out:
        return run_plan(plan_job(job, out, compare=compare, say=say), executor,
                        context_kind=context_kind, progress=progress, say=say)
