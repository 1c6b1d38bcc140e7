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
from renderer.core.sampling import PATTERNS
from renderer.study.distributed_report import (LIGHT_CARRIER_SAMPLES, distributed_sections,
                                               scene_effects)
from renderer.core.shadow_settings import BIAS_RULES, DEFAULT_FILTER, FILTERS, named_bias
from renderer.study.report import EXHAUSTIVE, QUICK, RasterStudy, ReportResult, metrics, run_report, settings
from renderer.study.report_settings import (CSV_COLUMNS, DISTRIBUTED_KNOBS, RADIOSITY_CSV_COLUMNS,
                                            RAY_BASE_SAMPLES, RAY_CSV_COLUMNS, SHADOW_COLUMNS, SHADOW_TARGETS, ShadowTarget)
from renderer.study.shadow_report import cheapest_shadow, shadow_sections, with_shadow_setting
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


def test_each_ground_truth_is_told_as_it_is_ready(tmp_path):
    """The report's bar moves per truth (a miss takes minutes at full size), cached ones first."""
    from renderer.study.ground_truth import ground_truths
    scenes = [load_scene(builtin_scenes()[name]) for name in ("point_light_plane", "flat_shading")]
    ground_truth(scenes[1], 8, 6, tmp_path)                     # cached beforehand
    told = []
    ground_truths(scenes, 8, 6, tmp_path, done=lambda scene: told.append(scene.name))
    assert told == ["flat_shading", "point_light_plane"]


def test_a_ray_truth_tells_its_progress_frame_by_frame(tmp_path):
    """Inside a ray-traced truth (16 frames of 64 samples, minutes at full size) the bar moves
    as rows are traced, up to the whole truth, never back."""
    from renderer.study.ground_truth import RAY_TRUTH_PASSES, ground_truths
    scene = load_scene(builtin_scenes()["classic"])
    shares = []
    ground_truths([scene], 4, 3, tmp_path, method="raytrace",
                  step=lambda scene, share: shares.append(share))
    assert shares == sorted(shares) and shares[-1] == 1.0
    assert len(shares) >= RAY_TRUTH_PASSES


def test_the_default_sweep_stops_at_16_samples_and_exhaustive_is_asked_for():
    """`renderer report` with no options must finish on the 2-core machine in under 30 minutes
    (benchmarks/bench_report.py): the 64-sample rows and the fifth run are --exhaustive's."""
    from renderer.cli import build_parser
    from renderer.study.ray_report import RayStudy
    for study in (RasterStudy(), RayStudy()):
        standard, exhaustive = study.sweep("standard"), study.sweep("exhaustive")
        assert max(standard.sample_counts) == 16 and standard.runs == 3
        assert max(exhaustive.sample_counts) == 64 and exhaustive.runs == 5
    parse = build_parser().parse_args
    assert not parse(["report", "--out", "o"]).exhaustive
    assert parse(["report", "--out", "o", "--exhaustive"]).exhaustive
    from renderer.errors import UsageError
    with pytest.raises(UsageError, match="--exhaustive: not allowed with argument --quick"):
        parse(["report", "--out", "o", "--quick", "--exhaustive"])


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
                        ("shading", "gpu"), ("shading", "reference"), ("precision", "reference"),
                        *((f"shadows-{knob}", b) for knob in ("resolution", "filter", "bias")
                          for b in ("gpu", "reference")),
                        *((knob, b) for knob in ("filter", "texture_resolution", "output")
                          for b in ("gpu", "reference"))}
    assert {s.setting for s in plan if s.pattern == "msaa"} == {"msaa 1", "msaa 4"}
    assert {s.setting for s in plan if s.pattern == "regular" and s.knob == "antialiasing"} == \
        {"regular 1", "regular 4", "regular 16"}       # the squares only, up to 16 in --quick
    assert {s.setting for s in settings(EXHAUSTIVE, [1, 4]) if s.pattern == "regular"
            and s.knob == "antialiasing"} == {"regular 1", "regular 4", "regular 16", "regular 64"}


@pytest.mark.slow                       # the quick sweep, through the command line, on a scene
                                        # whose lights get shadow maps (point_light_plane has none)
def test_report_command_writes_csv_plots_and_markdown(tmp_path, cli):
    out = tmp_path / "report"
    result = cli("report", "shadow_plane", "--quick", "--size", "16x12", "--out", str(out),
                 "--cache", str(tmp_path / "cache"), "--context", "osmesa")
    assert result.returncode == 0, result.stderr
    with open(out / "results.csv", newline="") as handle:
        reader = csv.DictReader(handle)
        assert tuple(reader.fieldnames) == CSV_COLUMNS
        rows = list(reader)
    assert len(rows) == len([s for s in settings(QUICK, [1, 4]) if s.variant[0] != "texture"])
    assert {row["scene"] for row in rows} == {"shadow_plane"}
    assert all(int(row["runs"]) >= QUICK.runs and float(row["median_ms"]) > 0 for row in rows)
    image_rows = [row for row in rows if not row["knob"].startswith(("shadows-", "output"))]
    assert all(0 <= float(row["rmse"]) <= float(row["max_abs"]) <= 1 for row in image_rows)
    # More samples, smaller error: jittered 16 beats one sample on both backends.
    error = {(row["setting"], row["backend"]): float(row["rmse"]) for row in image_rows}
    for backend in ("gpu", "reference"):
        assert error[("jittered 16", backend)] < error[("jittered 1", backend)]
    plots = sorted(path.name for path in (out / "plots").iterdir())
    assert plots == [f"shadow_plane-{knob}.png"
                     for knob in ("antialiasing", "output", "precision", "shading", "shadows-bias",
                                  "shadows-filter", "shadows-resolution", "tessellation")]
    assert all((out / "plots" / name).read_bytes().startswith(b"\x89PNG") for name in plots)
    report = (out / "report.md").read_text()
    for heading in ("# Error against run time", "## Method", "## Convergence of the sampling patterns",
                    "## Cheapest setting reaching RMSE <= 0.01 ", "## Cheapest setting reaching RMSE <= 0.003 ",
                    "## Output: quantisation, dithering and half-toning", "## Plots"):
        assert heading in report
    for name in plots:
        assert f"](plots/{name})" in report
    assert "| jittered | reference |" in report and "N^-0.75 at edges" in report
    assert "| shadow_plane |" in report
    assert "wrote" in result.stdout and "%" in result.stderr          # the progress bar


@pytest.mark.parametrize("args, reason", [
    (("no_such_scene",), "no_such_scene: no such scene file or built-in scene"),
    (("sphere", "--size", "400x300"), "--size: 400x300 is too large for the ground truth"),
    (("sphere", "--method", "raytrace", "--size", "400x300"),
     "--size: 400x300 is too large for the ray tracer's ground truth"),
    (("sphere", "--knobs", "shading,shadow"), "--knobs: shadow: no such knob for --method raster"),
    (("sphere", "--method", "raytrace", "--knobs", "shadows"),
     "--knobs: shadows: no such knob for --method raytrace"),
    (("sphere", "--address", "127.0.0.1:1"), "--address: no Ray head answers at 127.0.0.1:1"),
])
def test_bad_input_is_one_line_and_writes_nothing(tmp_path, args, reason, cli_here):
    out = tmp_path / "report"
    result = cli_here("report", *args, "--out", str(out), "--cache", str(tmp_path / "cache"))
    assert result.returncode == 2
    assert result.stderr.strip().splitlines() == [result.stderr.strip()]
    assert reason in result.stderr and "Traceback" not in result.stderr
    assert not out.exists() and not (tmp_path / "cache").exists()


# -- the shadow knobs (renderer/study/shadow_report.py) ----------------------------------------

def test_shadow_knobs_sweep_resolution_filter_and_bias_one_at_a_time():
    plan = [s for s in settings(EXHAUSTIVE, [1, 4]) if s.knob.startswith("shadows-")]
    by_knob = {knob: [(s.setting, s.variant) for s in plan if s.knob == knob and s.backend == "gpu"]
               for knob in ("shadows-resolution", "shadows-filter", "shadows-bias")}
    assert by_knob["shadows-resolution"] == [(str(r), ("shadow", "resolution", r))
                                             for r in (256, 512, 1024, 2048, 4096)]
    assert by_knob["shadows-filter"] == [(f, ("shadow", "filter", f)) for f in FILTERS]
    assert by_knob["shadows-bias"] == [(b, ("shadow", "bias", b)) for b in BIAS_RULES]
    assert len(plan) == 2 * (5 + 4 + 4)                       # each on both backends
    assert {s.sampling for s in plan} == {("pattern", "regular", 1)}     # one sample, a frame


def test_a_shadow_setting_changes_every_light_with_a_map_and_nothing_else():
    scene = load_scene(builtin_scenes()["coloured_lights"])    # 2 directional, 2 point lights
    scene = replace(scene, point_lights=[replace(scene.point_lights[0], shadow=replace(
        scene.point_lights[0].shadow, enabled=False)), *scene.point_lights[1:]])
    lights = lambda s: [*s.directional_lights, *s.point_lights]          # noqa: E731
    for field, value, expected in (("resolution", 512, {"resolution": 512}),
                                   ("filter", "pcf5x5", {"filter": "pcf5x5"}),
                                   ("bias", "slope", {"bias": named_bias("slope", DEFAULT_FILTER)})):
        changed = with_shadow_setting(scene, field, value)
        for before, after in zip(lights(scene), lights(changed)):
            wanted = replace(before.shadow, **expected) if before.shadow.enabled else before.shadow
            assert after == replace(before, shadow=wanted)
    assert named_bias("slope", DEFAULT_FILTER) != named_bias("auto", DEFAULT_FILTER)


def test_a_scene_gets_the_shadow_settings_its_maps_allow():
    plan = settings(EXHAUSTIVE, [1])
    shadowless = replace(load_scene(builtin_scenes()["shadow_plane"]),
                         objects=[replace(o, casts_shadows=False)
                                  for o in load_scene(builtin_scenes()["shadow_plane"]).objects])
    room = load_scene(builtin_scenes()["shadow_room"])         # a point light: six layers
    shadow_settings = lambda scene: {s.setting for s in RasterStudy().scene_settings(   # noqa: E731
        plan, scene, 160, 120) if s.knob == "shadows-resolution"}
    assert shadow_settings(shadowless) == set()
    assert "2048" in shadow_settings(room) and "4096" not in shadow_settings(room)   # 6 x 4096^2 texels
    assert len(RasterStudy().scene_settings(plan, shadowless, 160, 120)) == \
        len([s for s in plan if s.variant[0] not in ("shadow", "texture")])    # nor textures


def _shadow_row(scene, setting, backend, ms, outside, wrong, acne):
    return {"scene": scene, "knob": "shadows-filter", "setting": setting, "backend": backend,
            "median_ms": ms, "wrong_outside_band_fraction": outside, "wrong_fraction": wrong,
            "acne_pixels": acne, "peter_panning_max_texels": 0}


def test_the_cheapest_shadow_setting_is_the_fastest_meeting_every_bound_of_the_target():
    target = ShadowTarget(wrong_outside_band=0.001, wrong=0.002, acne_pixels=0)
    rows = [_shadow_row("a", "none", "gpu", 1.0, 0.0, 0.001, 3),        # fastest, but acne
            _shadow_row("a", "hard", "gpu", 2.0, 0.001, 0.001, 0),      # 0.1 % outside: not below
            _shadow_row("a", "pcf2x2", "gpu", 3.0, 0.0005, 0.0025, 0),  # too wrong in all
            _shadow_row("a", "pcf3x3", "gpu", 5.0, 0.0, 0.002, 0),      # meets it (at the bound)
            _shadow_row("a", "pcf5x5", "gpu", 4.0, 0.0, 0.0019, 0),     # meets it, faster
            _shadow_row("a", "pcf5x5", "reference", 0.5, 0.0, 0.0019, 0),      # another backend
            _shadow_row("b", "pcf5x5", "gpu", 0.5, 0.0, 0.0, 0),               # another scene
            {"scene": "a", "knob": "shading", "backend": "gpu", "median_ms": 0.1, "rmse": 0.1}]
    assert cheapest_shadow(rows, "a", "gpu", target)["setting"] == "pcf5x5"
    assert cheapest_shadow(rows, "a", "gpu", target)["median_ms"] == 4.0
    assert cheapest_shadow(rows[:3], "a", "gpu", target) is None
    loose = ShadowTarget(wrong_outside_band=0.002, wrong=1.0, acne_pixels=0)
    assert cheapest_shadow(rows, "a", "gpu", loose)["setting"] == "hard"
    # report.md: a section per target (SHADOW_TARGETS: the second also bounds wrong in all)
    first, second = "\n".join(shadow_sections(rows[:3] + rows[5:], ["a", "b"])).split("\n## ")[1:]
    assert first.startswith(f"Cheapest shadow setting: {SHADOW_TARGETS[0].text()}")
    assert "| a | filter: pcf2x2 | 3 | 0.050% | 0.250% | filter: pcf5x5 | 0.5 |" in first
    assert "| a | none reaches it |  |  |  | filter: pcf5x5 | 0.5 |" in second
    assert "| b | filter: pcf5x5 | 0.5 | 0.000% | 0.000% | none reaches it |  |" in second


@pytest.mark.slow                       # about 3 s idle: plots, a context, 16 frames
def test_a_tiny_shadow_sweep_writes_its_rows_plots_and_targets(tmp_path):
    scene = load_scene(builtin_scenes()["shadow_plane"])
    sweep = replace(QUICK, shadow_resolutions=(256,), shadow_filters=("hard",),
                    shadow_biases=("auto", "none"), runs=1)
    result = run_report([scene], tmp_path, sweep_name="quick", size=(16, 12), knobs=("shadows",),
                        sweep=sweep, context_kind="osmesa")
    assert [(r["setting"], r["backend"]) for r in result.rows] == [
        (name, b) for name in ("256", "hard", "auto", "none") for b in ("gpu", "reference")]
    assert result.truth_hits == 0 and not any("rmse" in r for r in result.rows)  # no image truth
    figures = {r["setting"]: tuple(r[c] for c in SHADOW_COLUMNS) for r in result.rows}
    assert figures["auto"][2] == 0 < figures["none"][2]          # no bias: acne
    with open(tmp_path / "results.csv", newline="") as handle:
        assert tuple(csv.DictReader(handle).fieldnames) == CSV_COLUMNS
    assert sorted(p.name for p in (tmp_path / "plots").iterdir()) == [
        f"shadow_plane-shadows-{knob}.png" for knob in ("bias", "filter", "resolution")]
    report = (tmp_path / "report.md").read_text()
    assert f"## Cheapest shadow setting: {SHADOW_TARGETS[0].text()}" in report
    assert "| shadow_plane |" in report and "## Convergence" not in report
    assert "Generated by `renderer report --quick --knobs shadows`" in report


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
        ("max_depth", "reference"), ("precision", "reference"),
        *((knob, backend) for knob in DISTRIBUTED_KNOBS for backend in ("gpu", "reference"))}
    lights = [s for s in plan if s.knob == "light_samples" and s.backend == "gpu"]
    assert {(s.pattern, s.samples, s.light_samples) for s in lights} == {
        (p, LIGHT_CARRIER_SAMPLES, m) for p in PATTERNS for m in RAY_QUICK.light_counts}
    lens = {s.setting for s in plan if s.knob == "lens" and s.backend == "gpu"}
    assert lens == {s.setting for s in plan if s.knob == "antialiasing" and s.backend == "gpu"
                    and s.pattern != "adaptive"}           # the same pattern series, lens spent
    assert all(s.light_samples == 1 for s in plan if s.knob != "light_samples")
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


def test_distributed_knobs_go_to_the_scenes_that_use_their_effect():
    """soft_shadows: light samples per hit beside the pixel samples that carry them;
    depth_of_field: its pattern series is the lens knob (the same frames antialiasing would
    trace); classic: none of them."""
    plan = ray_settings(RAY_QUICK)
    study = RayStudy()
    knobs = {name: {s.knob for s in study.scene_settings(plan, load_scene(builtin_scenes()[name]), 8, 6)}
             for name in ("soft_shadows", "depth_of_field", "classic")}
    assert knobs["soft_shadows"] == {"antialiasing", "max_depth", "precision", "light_samples"}
    assert knobs["depth_of_field"] == {"max_depth", "precision", "lens"}
    assert knobs["classic"] == {"antialiasing", "max_depth", "precision"}
    assert scene_effects(load_scene(builtin_scenes()["depth_of_field"])) == {"lens"}
    assert scene_effects(load_scene(builtin_scenes()["motion_blur"])) == {"time"}
    assert scene_effects(load_scene(builtin_scenes()["glossy"])) == {"glossy"}


@pytest.mark.slow                       # the truth of 4096 shadow rays per pixel
def test_a_tiny_light_samples_sweep_gpu_and_reference(tmp_path, gl_contexts):
    """soft_shadows at 8x6: more light samples per hit, less error (the penumbrae's; the 4
    pixel samples' error at edges stays); the GPU's error that of the reference, which traces
    the same rays."""
    scene = load_scene(builtin_scenes()["soft_shadows"])
    truth, _ = ground_truth(scene, 8, 6, tmp_path, method="raytrace")
    run = RaySceneRun(scene, 8, 6, gl_contexts["egl"])
    error = {}
    for backend, m in (("reference", 1), ("reference", 64), ("gpu", 64)):
        setting = RaySetting("light_samples", f"jittered 4x{m}", backend, "jittered", 4,
                             RAY_TRUTH_DEPTH, light_samples=m)
        image, _, _ = run.timed(setting, 1)
        error[(backend, m)] = metrics(image, truth)["rmse"]
    assert error[("reference", 64)] < 0.8 * error[("reference", 1)]       # measured 0.72
    assert error[("gpu", 64)] == pytest.approx(error[("reference", 64)], abs=1e-5)


def test_distributed_section_fits_each_knob_in_its_own_samples():
    rows = [{"scene": "s", "knob": "light_samples", "setting": f"{p} 4x{m}", "pattern": p,
             "backend": "gpu", "threshold": None, "samples": 4, "light_samples": m,
             "median_ms": float(m), "rmse": m ** slope}
            for p, slope in (("random", -0.5), ("jittered", -0.75)) for m in (1, 4, 16)]
    rows += [{**rows[0], "knob": "lens", "setting": f"jittered {n}", "pattern": "jittered",
              "samples": n, "light_samples": 1, "median_ms": float(n), "rmse": n ** -0.6}
             for n in (1, 4, 16)]
    text = "\n".join(distributed_sections(rows))
    assert "| light_samples | random | gpu | -0.50 |" in text
    assert "| light_samples | jittered | gpu | -0.75 |" in text
    assert "| lens | jittered | gpu | -0.60 |" in text
    assert distributed_sections([r for r in rows if r["knob"] == "antialiasing"]) == []


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
                               (64, 48), RAY_QUICK, "quick")
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
    classic = load_scene(builtin_scenes()["classic"])
    assert len(rows) == len(RayStudy().scene_settings(ray_settings(RAY_QUICK), classic, 16, 12))
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


# -- radiosity's report (renderer/study/radiosity_report.py) --------------------------------------

def test_radiosity_truth_is_path_traced_and_cached(tmp_path):
    """The Cornell box's truth at 8x6: the path tracer's, under its own name, made once."""
    from renderer.study.ground_truth import PATH_TRUTH_PASSES, PATH_TRUTH_SAMPLES
    scene = load_scene(builtin_scenes()["cornell_box_radiosity"])
    truth, hit = ground_truth(scene, 8, 6, tmp_path, method="radiosity")
    assert not hit and truth.shape == (6, 8, 3) and 0 < truth.mean() < 1
    assert ground_truth(scene, 8, 6, tmp_path, method="radiosity")[1] is True
    assert [p.name.split("-")[-3] for p in tmp_path.glob("*.npy")] == ["pathtrace"]
    assert PATH_TRUTH_SAMPLES * PATH_TRUTH_PASSES == 4096


def test_radiosity_settings_cover_each_knob():
    from renderer.study.radiosity_report import RADIOSITY_SWEEPS, radiosity_settings
    from renderer.study.report_settings import TWIN_ACROSS
    plan = radiosity_settings(RADIOSITY_SWEEPS["standard"])
    assert {s.knob for s in plan} == {"element_size", "hemicube", "iterations"}
    assert {s.across for s in plan if s.backend == "reference"} == {3, 6} and TWIN_ACROSS == 6
    assert [s.setting for s in plan if s.knob == "iterations"] == ["1 sweep", "2 sweeps", "4 sweeps",
                                                                   "8 sweeps", "converged"]
    assert all(s.options().elements_across == s.across for s in plan)


@pytest.mark.slow     # 10 s, most of it the path-traced truth: the full run's (the default run 90 s with it)
def test_a_tiny_radiosity_sweep_gpu_and_twin(tmp_path, gl_contexts):
    """The Cornell box at 16x12 against its path-traced truth: finer elements, less error; one
    Gauss-Seidel sweep more error than converged; the twin's error the GPU's (the same item
    buffers, the same solution)."""
    from renderer.study.radiosity_report import RadiositySceneRun, RadiositySetting
    scene = load_scene(builtin_scenes()["cornell_box_radiosity"])
    truth, _ = ground_truth(scene, 16, 12, tmp_path, method="radiosity")
    run = RadiositySceneRun(scene, 16, 12, gl_contexts["egl"])
    error, elements = {}, {}
    for setting in (RadiositySetting("element_size", "3", "gpu", across=3),
                    RadiositySetting("element_size", "3", "reference", across=3),
                    RadiositySetting("element_size", "8", "gpu", across=8),
                    RadiositySetting("iterations", "1", "gpu", across=8, sweeps=1)):
        image, elements[setting], ms = run.timed(setting, 1)
        error[setting.setting, setting.backend] = metrics(image, truth)["rmse"]
        assert ms > 0
    assert error["8", "gpu"] < error["3", "gpu"]
    assert error["1", "gpu"] > 1.5 * error["8", "gpu"]
    assert error["3", "reference"] == pytest.approx(error["3", "gpu"], abs=1e-6)
    assert 100 < min(elements.values()) < max(elements.values())


def test_radiosity_report_markdown_states_the_truth_and_the_slopes():
    from renderer.study.radiosity_report import RADIOSITY_SWEEPS, RadiosityStudy
    rows = [{"scene": "s", "knob": "element_size", "setting": f"diagonal / {a}", "backend": "gpu",
             "samples": float(a * a * 10), "median_ms": float(a ** 4), "rmse": a ** -1.0,
             "mismatched_fraction": 0.5, "psnr": 20.0} for a in (3, 6, 12)]
    result = ReportResult(rows=rows, scenes={"s": (38, 1, 1418)}, gl_renderer="llvmpipe")
    text = RadiosityStudy().markdown(result, {("s", "element_size"): "plots/s-element_size.png"},
                                     (64, 48), RADIOSITY_SWEEPS["quick"], "quick")
    assert "renderer report --method radiosity --quick" in text
    assert "| s | 38 | 1 | 1,418 |" in text
    assert "4096 jittered paths a pixel" in text
    assert "| s | -0.25 | -0.50 |  |" in text          # rmse ~ elements^-1/2 ~ time^-1/4


@pytest.mark.slow                       # the quick radiosity sweep's element sizes, through the command line
def test_radiosity_report_command_writes_csv_plots_and_markdown(tmp_path, cli):
    """The facing plates' element sizes (--knobs element_size: the Cornell box's whole quick
    sweep takes 45 s here; the other knobs' settings are test_a_tiny_radiosity_sweep_gpu_and_twin's)."""
    out = tmp_path / "report"
    result = cli("report", "radiosity_plates", "--method", "radiosity", "--quick", "--size", "16x12",
                 "--knobs", "element_size", "--out", out, "--cache", tmp_path / "cache", timeout=900)
    assert result.returncode == 0, result.stderr
    with open(out / "results.csv", newline="") as handle:
        reader = csv.DictReader(handle)
        assert tuple(reader.fieldnames) == RADIOSITY_CSV_COLUMNS
        rows = list(reader)
    assert len(rows) == 5
    error = {(row["setting"], row["backend"]): float(row["rmse"]) for row in rows}
    for across in (3, 6):                 # the same item buffers: the same error (its fall with
        setting = f"diagonal / {across}"  # the elements: the tiny sweep's, on the Cornell box)
        assert error[(setting, "gpu")] == pytest.approx(error[(setting, "reference")], abs=1e-6)
    assert sorted(path.name for path in (out / "plots").iterdir()) == ["radiosity_plates-element_size.png"]
    assert "# Error against run time: radiosity" in (out / "report.md").read_text()
