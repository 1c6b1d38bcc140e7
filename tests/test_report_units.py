"""The report spread over workers (renderer/study/report_units.py): how its (scene, setting)
units are cut into batches, and that a report whose batches ran on two workers in any order
has the rows of the one run in this process, apart from the times and who took them."""

import csv
import os
import random
import socket
from dataclasses import replace

import pytest

from renderer.core.scene_file import load_scene
from renderer.study.ray_report import RaySetting
from renderer.study.report import QUICK, Setting, run_report
from renderer.study.report_units import REFERENCE_WEIGHT, SceneWork, plan_batches, unit_cost

TIMING = ("median_ms", "worker")           # what may differ between two runs of one report


def _setting(backend, n, kind="pattern"):
    sampling = ("pattern", "jittered", n) if kind == "pattern" else ("adaptive", 4, n, 0.05)
    return Setting("antialiasing", f"{kind} {n}", backend, "jittered", ("truth",), sampling)


def test_a_unit_costs_the_frames_it_draws_the_reference_weighted():
    assert unit_cost(_setting("gpu", 16)) == 16
    assert unit_cost(_setting("reference", 16)) == 16 * REFERENCE_WEIGHT
    assert unit_cost(_setting("gpu", 64, "adaptive")) == 64          # at most TOTAL
    assert unit_cost(Setting("antialiasing", "msaa 4", "gpu", "msaa", ("truth",), ("msaa", 4))) == 1
    assert unit_cost(RaySetting("light_samples", "x", "gpu", "jittered", 4, 8, light_samples=16)) == 64


def _work():
    a = (_setting("gpu", 1), _setting("reference", 64), _setting("gpu", 4), _setting("reference", 1))
    b = (_setting("gpu", 16), _setting("reference", 4))
    return [SceneWork(0, "a", a, None), SceneWork(1, "b", b, None)]


def test_one_worker_runs_one_setting_at_a_time_in_sweep_order():
    batches = plan_batches(_work(), runs=5, workers=1)
    assert [(b.scene_index, [i for i, _ in b.units]) for b in batches] == \
        [(0, [0]), (0, [1]), (0, [2]), (0, [3]), (1, [0]), (1, [1])]
    assert {b.runs for b in batches} == {5}


def test_several_workers_get_batches_of_one_scene_longest_first():
    # total cost 1 + 512 + 4 + 8 + 16 + 32 = 573; 2 workers: cut at 573 / 8 = 71.6
    batches = plan_batches(_work(), runs=5, workers=2)
    assert [(b.scene_index, [i for i, _ in b.units]) for b in batches] == \
        [(0, [1]), (1, [1, 0]), (0, [3, 2, 0])]
    units = sorted((b.scene_index, i) for b in batches for i, _ in b.units)
    assert units == [(0, 0), (0, 1), (0, 2), (0, 3), (1, 0), (1, 1)]      # each exactly once


class ShuffledExecutor:
    """Two workers, batches in a shuffled order, each batch to either: what Ray may do."""
    kind, workers = "shuffled", 2

    def map(self, factory, batches):
        workers = [factory(), factory()]
        order = list(range(len(batches)))
        random.Random(19).shuffle(order)
        try:
            for turn, index in enumerate(order):
                yield index, workers[turn % 2].run(batches[index])
        finally:
            for worker in workers:
                worker.close()

    def tasks(self, function, args):
        args = list(enumerate(args))
        random.Random(1).shuffle(args)
        return ((index, function(*arguments)) for index, arguments in args)

    def describe(self):
        return "on two workers in a shuffled order"

    def __enter__(self):
        return self

    def __exit__(self, *exc):
        pass


def _rows(path):
    with open(path, newline="") as handle:
        return [{k: v for k, v in row.items() if k not in TIMING} for row in csv.DictReader(handle)]


@pytest.mark.slow                       # about 12 s: two tiny sweeps of every knob family
def test_a_report_on_two_workers_in_any_order_has_the_in_process_rows(tmp_path, monkeypatch):
    scenes = [load_scene("shadow_plane")]         # it has every knob family: shadow maps too
    sweep = replace(QUICK, sample_counts=(1, 4), levels=(0.5, 1.0), runs=1,
                    output_methods=("none", "floyd-steinberg"), output_bits=(1,))
    options = dict(size=(16, 12), cache_dir=tmp_path / "cache", sweep=sweep, context_kind="osmesa")
    here = run_report(scenes, tmp_path / "here", **options)
    monkeypatch.setattr("renderer.cluster.executor.open_executor",
                        lambda *args, **kwargs: ShuffledExecutor())
    spread = run_report(scenes, tmp_path / "spread", workers=2, **options)
    assert _rows(tmp_path / "spread" / "results.csv") == _rows(tmp_path / "here" / "results.csv")
    knobs = {row["knob"] for row in _rows(tmp_path / "here" / "results.csv")}
    assert {"antialiasing", "tessellation", "shading", "precision", "shadows-bias", "output"} <= knobs
    assert {row["worker"] for row in spread.rows} == {f"{socket.gethostname()}:{os.getpid()}"}
    assert "Where the settings ran: on two workers in a shuffled order." in \
        (tmp_path / "spread" / "report.md").read_text()
    assert "Where the settings ran: in this process." in (tmp_path / "here" / "report.md").read_text()


# Some of the quick sweep's knobs: against the truth, against ray-cast shadows, against the
# linear frame (antialiasing's 64-sample reference rows take minutes here).
QUICK_KNOBS = "shading,shadows,output"


def test_report_quick_on_ray_workers_has_the_in_process_rows(tmp_path, cli, ray_executor):
    """`renderer report --quick --address` (the run's local Ray, 2 workers): the rows
    and every error of the in-process report; each row timed by one of the two workers."""
    options = ("report", "--quick", "--knobs", QUICK_KNOBS, "--size", "32x24",
               "--cache", tmp_path / "cache")
    here = cli(*options, "--out", tmp_path / "here")
    assert here.returncode == 0, here.stderr
    spread = cli(*options, "--out", tmp_path / "ray", "--address", ray_executor.address)
    assert spread.returncode == 0, spread.stderr
    assert _rows(tmp_path / "ray" / "results.csv") == _rows(tmp_path / "here" / "results.csv")
    with open(tmp_path / "ray" / "results.csv", newline="") as handle:
        workers = {row["worker"] for row in csv.DictReader(handle)}
    assert len(workers) == 2
    report = (tmp_path / "ray" / "report.md").read_text()
    assert f"Where the settings ran: the Ray cluster at {ray_executor.address}, 2 workers" in report
