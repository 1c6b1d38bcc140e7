"""The report's units of work and the executor that runs them (issue 19).

A unit is one row of results.csv: a (scene, setting) pair. A batch is some settings of ONE
scene, with what a worker needs to run them: the scene, its ground truth (computed once per
scene by the driver, from its disk cache, and shipped inside the batch) and the runs per
setting. A ReportWorker (renderer/cluster/executor.py's worker: one GL context, a SceneRun
or RaySceneRun per scene it has seen lately) runs a batch and answers one UnitResult per
setting: the row, timed on that worker and tagged with it (`worker`: host:pid), and the GL
facts the plan depends on, which the driver checks against its own.

    rows = run_units(executor, runner, work, runs, facts, size, context_kind, bar)

In this process (one worker) the batches are single settings in the sweep's order, exactly
the loop the report always ran. Over N workers they are cut by a rough cost (unit_cost) and
sent longest first, so that no heavy setting starts last. Either way the rows come back
sorted into (scene, setting) order: results.csv is the same wherever it ran, apart from the
timings, which are measured where each row ran (and, with several workers on one machine,
while the others compete for its cores).
"""

from __future__ import annotations

from collections import OrderedDict
from dataclasses import dataclass
from typing import NamedTuple

import numpy as np

from renderer.cluster.executor import BATCHES_PER_WORKER, worker_identity, worker_label
from renderer.errors import UserError

CACHED_SCENES = 2           # SceneRuns a worker keeps (each holds a renderer per drawn variant)
REFERENCE_WEIGHT = 8        # the reference's time per sample over the GPU's: 3 to 30 in
                            # docs/report/results.csv, median 7


@dataclass(frozen=True)
class SceneWork:
    """One scene's part of the report: its settings in plan order, its truth or None."""
    index: int
    scene: object
    settings: tuple
    truth: np.ndarray | None


@dataclass(frozen=True)
class ReportBatch:
    """Some settings of one scene: (plan index, setting) pairs, with the scene and truth."""
    scene_index: int
    scene: object
    truth: np.ndarray | None
    units: tuple
    runs: int


class UnitResult(NamedTuple):
    row: dict               # a results.csv row, `worker` included
    gl: tuple               # the worker's GL facts (gl_facts), checked by the driver


def gl_facts(ctx) -> tuple:
    """What the plan and the reference's errors depend on in a GL context: the sub-pixel bits
    the reference snaps to and the MSAA sample counts that decide which msaa rows exist."""
    from renderer.gpu.pipeline import multisample_counts
    return int(ctx.info["GL_SUBPIXEL_BITS"]), tuple(multisample_counts(ctx))


# A raster ground truth (one reference frame of 16 x 16 times the pixels) costs about as much
# as this many reference passes of its scene at the report's size: 149 s against 1.8 s a pass,
# summed over the 20 built-in raster scenes at 160x120 (1.7 to 470 passes scene by scene).
RASTER_TRUTH_PASSES = 80


def truth_cost(method: str, scene) -> float:
    """A ground truth's rough cost in unit_cost's units: for the progress bar's estimate only."""
    if method == "raytrace":
        from renderer.study.ground_truth import RAY_TRUTH_PASSES, RAY_TRUTH_SAMPLES, truth_light_samples
        return REFERENCE_WEIGHT * RAY_TRUTH_SAMPLES * RAY_TRUTH_PASSES * truth_light_samples(scene)
    if method == "radiosity":                            # paths on the GPU, a few bounces each
        from renderer.study.ground_truth import PATH_TRUTH_PASSES, PATH_TRUTH_SAMPLES
        return 4 * PATH_TRUTH_SAMPLES * PATH_TRUTH_PASSES
    return REFERENCE_WEIGHT * RASTER_TRUTH_PASSES


def unit_cost(setting) -> float:
    """A setting's rough relative cost, only to cut and order batches (no figure depends on
    it): the frames it draws per run (samples, light samples), the reference's weighted."""
    if hasattr(setting, "cost"):                                    # a radiosity setting's own
        return setting.cost
    samples = getattr(setting, "samples", None)                     # a ray-tracing setting
    if samples is None:
        kind, *args = setting.sampling                             # see report.Setting
        samples = 1 if kind == "msaa" else args[1]
    weight = REFERENCE_WEIGHT if setting.backend == "reference" else 1
    return weight * samples * getattr(setting, "light_samples", 1)


def plan_batches(work: list[SceneWork], runs: int, workers: int) -> list[ReportBatch]:
    """The batches: one per setting in sweep order for one worker; for several, each scene's
    settings longest first, cut where a batch reaches 1 / (BATCHES_PER_WORKER x workers) of
    the total cost, and the batches of all scenes longest first."""
    def batch(scene: SceneWork, units) -> ReportBatch:
        return ReportBatch(scene.index, scene.scene, scene.truth, tuple(units), runs)

    if workers <= 1:
        return [batch(scene, [unit]) for scene in work for unit in enumerate(scene.settings)]
    target = sum(unit_cost(s) for scene in work for s in scene.settings) / (BATCHES_PER_WORKER * workers)
    batches = []
    for scene in work:
        units = sorted(enumerate(scene.settings), key=lambda unit: -unit_cost(unit[1]))
        current = []
        for unit in units:
            current.append(unit)
            if sum(unit_cost(s) for _, s in current) >= target:
                batches.append(batch(scene, current))
                current = []
        if current:
            batches.append(batch(scene, current))
    return sorted(batches, key=lambda b: -sum(unit_cost(s) for _, s in b.units))


class ReportWorker:
    """Runs report batches: one GL context (made on the first batch), the SceneRuns of the
    last CACHED_SCENES scenes, so that a scene's renderers serve all its settings here."""

    def __init__(self, runner, size: tuple[int, int], context_kind: str = "auto"):
        self.runner, self.size, self.context_kind = runner, size, context_kind
        self.ctx, self.facts = None, None
        self.runs: OrderedDict[int, object] = OrderedDict()
        self.name = worker_label(worker_identity())

    def scene_run(self, batch: ReportBatch):
        if batch.scene_index not in self.runs:
            if len(self.runs) >= CACHED_SCENES:
                self.runs.popitem(last=False)[1].release()
            self.runs[batch.scene_index] = self.runner.scene_run(batch.scene, *self.size, self.ctx)
        self.runs.move_to_end(batch.scene_index)
        return self.runs[batch.scene_index]

    def run(self, batch: ReportBatch) -> list[UnitResult]:
        if self.ctx is None:
            from renderer.gpu.context import make_context
            self.ctx = make_context(self.context_kind)
            self.facts = gl_facts(self.ctx)
        run = self.scene_run(batch)
        results = []
        for _, setting in batch.units:
            image, samples, ms = run.timed(setting, batch.runs)
            row = {"scene": batch.scene.name, **setting.columns(), "samples": samples,
                   "runs": batch.runs, "median_ms": ms, "worker": self.name,
                   **run.errors(setting, image, batch.truth)}
            results.append(UnitResult(row, self.facts))
        return results

    def close(self) -> None:
        for run in self.runs.values():
            run.release()
        self.runs.clear()
        if self.ctx is not None:
            from renderer.gpu.context import release_context
            release_context(self.ctx)
            self.ctx = None


def run_units(executor, runner, work: list[SceneWork], runs: int, facts: tuple,
              size: tuple[int, int], context_kind: str, bar) -> list[dict]:
    """Every unit of `work` through `executor`; the rows in (scene, plan) order. A worker
    whose GL facts differ from the driver's `facts` (the plan's) is refused: one line. `bar`
    (tqdm) moves by each batch's unit_cost times `runs`."""
    from contextlib import closing
    from functools import partial
    batches = plan_batches(work, runs, executor.workers)
    total = sum(len(batch.units) for batch in batches)
    rows = {}
    # closed on the way out (an error, Ctrl-C), before the executor is: its calls end first
    with closing(executor.map(partial(ReportWorker, runner, size, context_kind), batches)) as finished:
        for index, results in finished:
            batch = batches[index]
            for (plan_index, _), result in zip(batch.units, results):
                if result.gl != facts:
                    raise UserError(f"worker {result.row['worker']} has GL_SUBPIXEL_BITS and MSAA "
                                    f"counts {result.gl}, this machine {facts}: the plan and the "
                                    "reference's errors would differ; use workers alike",
                                    key="--address")
                rows[(batch.scene_index, plan_index)] = result.row
            bar.set_description(f"settings ({len(rows)} of {total} done, {batch.scene.name})")
            bar.update(runs * sum(unit_cost(setting) for _, setting in batch.units))
    return [rows[key] for key in sorted(rows)]
