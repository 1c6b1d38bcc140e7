"""`renderer report` (renderer/study/report.py, report_output.py) and its ground truth
(renderer/study/ground_truth.py)."""

import csv
import math
from dataclasses import replace

import numpy as np
import pytest

from renderer.core.builtin import builtin_scenes
from renderer.study.ground_truth import ground_truth
from renderer.study.report import QUICK, metrics, settings
from renderer.study.report_settings import CSV_COLUMNS
from renderer.study.report_output import convergence_slopes, pareto_front
from renderer.core.scene_file import load_scene


def test_ground_truth_is_cached_by_scene_content(tmp_path):
    scene = load_scene(builtin_scenes()["point_light_plane"])
    first, hit_first = ground_truth(scene, 8, 6, tmp_path)
    second, hit_second = ground_truth(scene, 8, 6, tmp_path)
    assert (hit_first, hit_second) == (False, True)
    assert np.array_equal(first, second) and first.shape == (6, 8, 3)
    assert 0.0 <= first.min() and first.max() <= 1.0
    # Another light, another size: misses, and each is stored beside the first.
    brighter = replace(scene, ambient=(0.3, 0.3, 0.3))
    assert ground_truth(brighter, 8, 6, tmp_path)[1] is False
    assert ground_truth(scene, 6, 6, tmp_path)[1] is False
    assert len(list(tmp_path.glob("*.npy"))) == 3


def test_metrics_on_the_zero_to_one_scale():
    truth = np.zeros((2, 2, 3))
    image = truth.copy()
    image[0, 0, 1] = 0.1                            # one channel of one pixel off by 0.1
    figures = metrics(image, truth)
    assert figures["rmse"] == pytest.approx(math.sqrt(0.01 / 12))
    assert figures["max_abs"] == pytest.approx(0.1)
    assert figures["psnr"] == pytest.approx(10 * math.log10(12 / 0.01))
    assert figures["mismatched_fraction"] == 0.25   # 26/255 off in one pixel of four
    assert figures["flip_mean"] > 0
    assert metrics(truth, truth)["psnr"] == math.inf


def test_pareto_front_keeps_what_nothing_beats_in_both_time_and_error():
    points = [(1.0, 5.0), (2.0, 3.0), (3.0, 4.0), (4.0, 1.0), (2.0, 3.5)]
    assert pareto_front(points) == [0, 1, 3]


def test_convergence_slope_is_fitted_across_scenes_with_their_own_intercepts():
    rows = [{"scene": scene, "knob": "antialiasing", "pattern": "random", "backend": "gpu",
             "samples": n, "rmse": scale * n ** -0.5}
            for scene, scale in (("a", 0.1), ("b", 0.02)) for n in (1, 4, 16, 64)]
    fit = convergence_slopes(rows)[("random", "gpu")]
    assert fit.slope == pytest.approx(-0.5) and fit.points == 8 and fit.samples == (1, 64)
    assert fit.per_scene == pytest.approx([-0.5, -0.5])


def test_every_knob_runs_on_its_backends():
    plan = settings(QUICK, [1, 4])
    backends = {(s.knob, s.backend) for s in plan}
    assert backends == {("antialiasing", "gpu"), ("antialiasing", "reference"),
                        ("tessellation", "gpu"), ("tessellation", "reference"),
                        ("shading", "gpu"), ("shading", "reference"), ("precision", "reference")}
    assert {s.setting for s in plan if s.pattern == "msaa"} == {"msaa 1", "msaa 4"}
    assert {s.setting for s in plan if s.pattern == "regular" and s.knob == "antialiasing"} == \
        {"regular 1", "regular 4", "regular 16", "regular 64"}       # the squares only


@pytest.mark.slow                       # the quick sweep, through the command line
def test_report_command_writes_csv_plots_and_markdown(tmp_path, cli):
    out = tmp_path / "report"
    result = cli("report", "point_light_plane", "--quick", "--size", "16x12", "--out", str(out),
                 "--cache", str(tmp_path / "cache"), "--context", "osmesa")
    assert result.returncode == 0, result.stderr
    with open(out / "results.csv", newline="") as handle:
        reader = csv.DictReader(handle)
        assert tuple(reader.fieldnames) == CSV_COLUMNS
        rows = list(reader)
    assert len(rows) == len(settings(QUICK, [1, 4]))
    assert {row["scene"] for row in rows} == {"point_light_plane"}
    assert all(int(row["runs"]) >= 5 and float(row["median_ms"]) > 0 for row in rows)
    assert all(0 <= float(row["rmse"]) <= float(row["max_abs"]) <= 1 for row in rows)
    # More samples, smaller error: jittered 16 beats one sample on both backends.
    error = {(row["setting"], row["backend"]): float(row["rmse"]) for row in rows}
    for backend in ("gpu", "reference"):
        assert error[("jittered 16", backend)] < error[("jittered 1", backend)]
    plots = sorted(path.name for path in (out / "plots").iterdir())
    assert plots == [f"point_light_plane-{knob}.png"
                     for knob in ("antialiasing", "precision", "shading", "tessellation")]
    assert all((out / "plots" / name).read_bytes().startswith(b"\x89PNG") for name in plots)
    report = (out / "report.md").read_text()
    for heading in ("# Error against run time", "## Method", "## Convergence of the sampling patterns",
                    "## Cheapest setting reaching RMSE <= 0.01 ", "## Cheapest setting reaching RMSE <= 0.003 ",
                    "## Plots"):
        assert heading in report
    for name in plots:
        assert f"](plots/{name})" in report
    assert "| jittered | reference |" in report and "N^-0.75 at edges" in report
    assert "| point_light_plane |" in report
    assert "wrote" in result.stdout and "%" in result.stderr          # the progress bar


@pytest.mark.parametrize("args, reason", [
    (("no_such_scene",), "no_such_scene: no such scene file or built-in scene"),
    (("sphere", "--size", "400x300"), "--size: 400x300 is too large for the ground truth"),
])
def test_bad_input_is_one_line_and_writes_nothing(tmp_path, args, reason, cli):
    out = tmp_path / "report"
    result = cli("report", *args, "--out", str(out), "--cache", str(tmp_path / "cache"))
    assert result.returncode == 2
    assert result.stderr.strip().splitlines() == [result.stderr.strip()]
    assert reason in result.stderr and "Traceback" not in result.stderr
    assert not out.exists() and not (tmp_path / "cache").exists()
