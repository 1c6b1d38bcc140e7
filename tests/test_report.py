"""`renderer report` (renderer/study/report.py, report_output.py) and its ground truth
(renderer/study/ground_truth.py)."""

import csv
import math
from dataclasses import replace

import numpy as np
import pytest

from conftest import RAYTRACE_SCENES

from renderer.core.builtin import builtin_scenes, made_for_raytracing
from renderer.study.ground_truth import RAY_TRUTH_DEPTH, ground_truth
from renderer.study.ray_report import (RAY_QUICK, RayStudy, RaySceneRun, RaySetting,
                                       ray_settings)
from renderer.study.report import QUICK, ReportResult, metrics, settings
from renderer.study.report_settings import CSV_COLUMNS, RAY_BASE_SAMPLES, RAY_CSV_COLUMNS
from renderer.study.report_output import convergence_slopes, pareto_front, series_name
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
    (("sphere", "--method", "raytrace", "--size", "400x300"),
     "--size: 400x300 is too large for the ray tracer's ground truth"),
])
def test_bad_input_is_one_line_and_writes_nothing(tmp_path, args, reason, cli_here):
    out = tmp_path / "report"
    result = cli_here("report", *args, "--out", str(out), "--cache", str(tmp_path / "cache"))
    assert result.returncode == 2
    assert result.stderr.strip().splitlines() == [result.stderr.strip()]
    assert reason in result.stderr and "Traceback" not in result.stderr
    assert not out.exists() and not (tmp_path / "cache").exists()


# -- the ray tracer's report (renderer/study/ray_report.py) ------------------------------------

MIRROR_SCENE = """
background = [0.3, 0.4, 0.6]
[camera]
eye = [0.0, 1.0, 4.0]
look = [0.0, 0.5, 0.0]
[materials.floor]
kd = [0.7, 0.7, 0.6]
[materials.mirror]
kd = [0.1, 0.1, 0.1]
kr = [0.8, 0.8, 0.8]
[[lights]]
type = "directional"
direction = [0.5, -1.0, -0.3]
[[objects]]
name = "floor"
shape = { type = "plane", normal = [0.0, 1.0, 0.0], offset = 0.0 }
material = "floor"
[[objects]]
name = "ball"
shape = { type = "sphere", centre = [0.0, 0.7, 0.0], radius = 0.7 }
material = "mirror"
"""


def test_ray_truth_is_the_background_where_no_ray_hits_and_is_cached(tmp_path):
    scene = load_scene(builtin_scenes()["classic"])
    # Looking up and away from the spheres: the floor is below the lowest ray (7.5 degrees up).
    sky = replace(scene, camera=replace(scene.camera, look=(0.0, 10.0, 20.0)))
    truth, hit = ground_truth(sky, 4, 3, tmp_path, method="raytrace")
    assert hit is False and truth.shape == (3, 4, 3)
    assert np.array_equal(truth, np.broadcast_to(np.float32(scene.background), (3, 4, 3)))
    assert ground_truth(sky, 4, 3, tmp_path, method="raytrace")[1] is True
    assert [path.name.split("-")[:2] for path in tmp_path.glob("*.npy")] == [["classic", "raytrace"]]


def test_ray_settings_cover_each_knob_on_its_backends():
    plan = ray_settings(RAY_QUICK)
    assert {(s.knob, s.backend) for s in plan} == {
        ("antialiasing", "gpu"), ("antialiasing", "reference"), ("max_depth", "gpu"),
        ("max_depth", "reference"), ("precision", "reference")}
    sampled = [s for s in plan if s.knob == "antialiasing"]
    assert {s.max_depth for s in sampled} == {RAY_TRUTH_DEPTH}      # the sampling error alone
    assert {s.setting for s in sampled if s.pattern == "regular"} == {"regular 1", "regular 4",
                                                                      "regular 16"}
    adaptive = {(s.setting, s.samples, s.threshold) for s in sampled if s.pattern == "adaptive"}
    assert adaptive == {("adaptive 4->4 @4/255", 4, 4 / 255), ("adaptive 4->16 @4/255", 16, 4 / 255)}
    depths = [s for s in plan if s.knob == "max_depth" and s.backend == "gpu"]
    assert [s.max_depth for s in depths] == list(RAY_QUICK.depths)
    assert {(s.pattern, s.samples) for s in depths} == {("jittered", RAY_BASE_SAMPLES)}
    assert [s.dtype for s in plan if s.knob == "precision"] == ["float32", "float64"]


def test_adaptive_thresholds_are_series_of_their_own_fitted_in_samples_and_in_time():
    rows = [{"scene": "a", "knob": "antialiasing", "pattern": "adaptive", "backend": "gpu",
             "threshold": levels / 255, "samples": n, "median_ms": 3.0 * n ** 0.5,
             "rmse": 0.1 * n ** -1.0}
            for levels in (1, 16) for n in (4, 9, 36)]
    rows += [{**rows[0], "pattern": "jittered", "threshold": None}]        # one point: no fit
    assert [series_name(r) for r in rows[::3]] == ["adaptive @1/255", "adaptive @16/255", "jittered"]
    names = ["adaptive @1/255", "adaptive @16/255", "jittered"]
    in_samples = convergence_slopes(rows, names)
    in_time = convergence_slopes(rows, names, x="median_ms")
    assert set(in_samples) == {("adaptive @1/255", "gpu"), ("adaptive @16/255", "gpu")}
    assert in_samples[("adaptive @1/255", "gpu")].slope == pytest.approx(-1.0)
    assert in_time[("adaptive @1/255", "gpu")].slope == pytest.approx(-2.0)     # t ~ N^0.5
    assert in_time[("adaptive @16/255", "gpu")].samples == (4, 36)


def test_the_scenes_made_for_the_ray_tracer(tmp_path):
    """What `renderer report` reports by default with each --method: the description says."""
    assert {name for name in builtin_scenes() if made_for_raytracing(name)} == RAYTRACE_SCENES
    mine = tmp_path / "mine.toml"
    mine.write_text('description = "Mirrors (--method raytrace)"\n')
    assert made_for_raytracing(str(mine))


def test_a_tiny_ray_sweep_gpu_and_reference(tmp_path, gl_contexts):
    """One scene at 8x6 (a mirror ball on a floor): more samples, less error; no bounce, a
    blank mirror; the GPU's error that of the reference, which traces the same rays."""
    path = tmp_path / "mirror.toml"
    path.write_text(MIRROR_SCENE)
    scene = load_scene(path)
    truth, _ = ground_truth(scene, 8, 6, tmp_path, method="raytrace")
    run = RaySceneRun(scene, 8, 6, gl_contexts["egl"])
    error, spent = {}, {}
    for knob, name, backend, pattern, n, depth, threshold in (
            ("antialiasing", "jittered 1", "reference", "jittered", 1, RAY_TRUTH_DEPTH, None),
            ("antialiasing", "jittered 16", "reference", "jittered", 16, RAY_TRUTH_DEPTH, None),
            ("antialiasing", "jittered 16", "gpu", "jittered", 16, RAY_TRUTH_DEPTH, None),
            ("antialiasing", "adaptive", "reference", "adaptive", 16, RAY_TRUTH_DEPTH, 1 / 255),
            ("max_depth", "depth 0", "reference", "jittered", 16, 0, None)):
        setting = RaySetting(knob, name, backend, pattern, n, depth, threshold)
        image, spent[name], ms = run.timed(setting, 1)
        error[(name, backend)] = metrics(image, truth)["rmse"]
        assert ms > 0
    assert error[("jittered 16", "reference")] < error[("jittered 1", "reference")]
    assert error[("depth 0", "reference")] > 5 * error[("jittered 16", "reference")]
    assert error[("jittered 16", "gpu")] == pytest.approx(error[("jittered 16", "reference")], abs=1e-5)
    assert spent["jittered 1"] == 1 and spent["depth 0"] == 16
    assert 4 < spent["adaptive"] < 16    # the first 4 everywhere, 16 where they disagree


def test_ray_report_markdown_has_the_slopes_in_samples_and_in_time():
    rows = [{"scene": "s", "knob": "antialiasing", "setting": f"{p} {n}", "pattern": p,
             "backend": b, "threshold": None, "samples": n, "median_ms": float(n), "rmse": n ** -0.5}
            for p in ("random", "jittered") for b in ("gpu", "reference") for n in (1, 4, 16)]
    result = ReportResult(rows=rows, scenes={"s": (3, 1, 0, "yes")}, gl_renderer="llvmpipe")
    text = RayStudy().markdown(result, {("s", "antialiasing"): "plots/s-antialiasing.png"},
                               (64, 48), RAY_QUICK, quick=True)
    assert "renderer report --method raytrace --quick" in text
    assert "| s | 3 | 1 | 0 | yes |" in text
    assert "| random | gpu | -0.50 | -0.50 (-0.50 to -0.50) | -0.50 |" in text
    assert "![s: antialiasing](plots/s-antialiasing.png)" in text


@pytest.mark.slow                       # the quick ray-tracing sweep, through the command line
def test_ray_report_command_writes_csv_plots_and_markdown(tmp_path, cli):
    out = tmp_path / "report"
    result = cli("report", "--method", "raytrace", "--quick", "--size", "16x12",      # classic
                 "--out", out, "--cache", tmp_path / "cache", "--context", "osmesa", timeout=900)
    assert result.returncode == 0, result.stderr
    with open(out / "results.csv", newline="") as handle:
        reader = csv.DictReader(handle)
        assert tuple(reader.fieldnames) == RAY_CSV_COLUMNS
        rows = list(reader)
    assert len(rows) == len(ray_settings(RAY_QUICK))
    error = {(row["setting"], row["backend"]): float(row["rmse"]) for row in rows}
    samples = {(row["setting"], row["backend"]): float(row["samples"]) for row in rows}
    for backend in ("gpu", "reference"):
        assert error[("jittered 16", backend)] < error[("jittered 1", backend)]
        assert error[("depth 0", backend)] > error[(f"depth {RAY_TRUTH_DEPTH}", backend)]
        assert 4 < samples[("adaptive 4->16 @4/255", backend)] < 16
    for setting, backend in error:            # the same rays: the same error
        if backend == "gpu":
            assert error[(setting, "gpu")] == pytest.approx(error[(setting, "reference")], abs=1e-5)
    plots = sorted(path.name for path in (out / "plots").iterdir())
    assert plots == [f"classic-{knob}.png" for knob in ("antialiasing", "max_depth", "precision")]
    report = (out / "report.md").read_text()
    for heading in ("# Error against run time: the ray tracer", "## Method",
                    "## Convergence of the sampling patterns", "slope in time",
                    "| adaptive @4/255 | reference |", "## Cheapest setting reaching RMSE <= 0.01 "):
        assert heading in report
    assert "wrote" in result.stdout
