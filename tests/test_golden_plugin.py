"""Specification of the golden-image pytest plugin (renderer/checks/pytest_plugin.py), one hand-checked
case per rule.

Each case writes a small test file into a `pytester` folder and runs pytest on it in this
process; the plugin is loaded there through its `pytest11` entry point, as in any project
that installs this package. The frames are tiny synthetic images (flat grey 32x32, edited a
few pixels at a time), so every figure a case asserts can be worked out by hand and nothing
but the last case needs GL.

A test file written here checks `frame(...)`: flat grey 128, opaque, with some edits applied.
The outer test picks the phase through the environment: phase "before" (the default) makes
the frame the goldens are made from, phase "after" the changed frame checked against them.

    run(...)                           pytest            (compare only)
    run("--update-goldens", ...)       pytest --update-goldens
"""

from __future__ import annotations

import hashlib
import io
import json
import textwrap
from pathlib import Path

import numpy as np
import pytest
from PIL import Image

import renderer
from renderer.checks.goldens import check_golden, pixels_sha256, read_golden
from renderer.checks.perceptual import flip_error

pytest_plugins = ["pytester"]

# Prepended to every test file run under pytester.
PRELUDE = '''
import os

import numpy as np
import pytest

PHASE = os.environ.get("GOLDEN_SPEC_PHASE", "before")
GL_A = {"GL_RENDERER": "A", "GL_VERSION": "4.5", "context": "egl"}
GL_B = {"GL_RENDERER": "B", "GL_VERSION": "4.5", "context": "egl"}


def frame(after=(), *, before=(), size=(32, 32)):
    """Flat grey 128, alpha 255, with the edits of this phase: each (index, delta) adds
    delta to R, G and B of rgba[index], e.g. (np.s_[5, 5], 1) or (np.s_[:, :], 3)."""
    width, height = size
    rgba = np.full((height, width, 4), 128, dtype=np.int16)
    rgba[..., 3] = 255
    for index, delta in (after if PHASE == "after" else before):
        rgba[index + (slice(0, 3),)] += delta
    return np.clip(rgba, 0, 255).astype(np.uint8)

'''

GREY = np.full((32, 32, 4), 128, dtype=np.uint8)
GREY[..., 3] = 255


@pytest.fixture
def spec(pytester, monkeypatch):
    """Write and run golden tests under pytester."""
    return Spec(pytester, monkeypatch)


class Spec:
    def __init__(self, pytester, monkeypatch):
        self.pytester, self.monkeypatch = pytester, monkeypatch
        self.path: Path = pytester.path
        self.goldens = self.path / "goldens"
        self.results = self.path / "golden-results"

    def write(self, source: str, name: str = "test_spec") -> None:
        self.pytester.makepyfile(**{name: PRELUDE + textwrap.dedent(source)})

    def run(self, *args, phase: str = "before"):
        self.monkeypatch.setenv("GOLDEN_SPEC_PHASE", phase)
        # In process, the inner run inherits this run's warning filters: keep GoldenWarning a
        # warning even under `pytest -W error`, as it is in a run of its own.
        return self.pytester.runpytest_inprocess(
            "-p", "no:cacheprovider", "-W", "default::renderer.checks.pytest_plugin.GoldenWarning", *args)


def outcomes(result) -> dict[str, str]:
    """{test name: "passed" | "failed" | "skipped"} of a pytester run (call phase, or the
    phase that failed)."""
    out = {}
    for report in result.reprec.getreports("pytest_runtest_logreport"):
        name = report.nodeid.split("::")[-1]
        if report.when == "call" or report.failed:
            out[name] = report.outcome
    return out


def failure(result, test: str) -> str:
    """The failure text pytest shows for `test`."""
    texts = [r.longreprtext for r in result.reprec.getfailures() if r.nodeid.split("::")[-1] == test]
    assert texts, f"{test} did not fail: {outcomes(result)}"
    return texts[0]


def assert_clean_failure(text: str) -> None:
    """A failure given as a message (pytest.fail(..., pytrace=False)), not as a traceback."""
    assert "Traceback" not in text
    assert "During handling of the above exception" not in text    # the cause is not shown again
    assert "direct cause" not in text
    assert "def " not in text               # no source lines of the test or the plugin
    assert "\nE   " not in text and not text.startswith("E   ")


def snapshot(folder: Path) -> dict[str, tuple[bytes, int]]:
    """{file name: (bytes, mtime_ns)} of every file in `folder`."""
    return {p.name: (p.read_bytes(), p.stat().st_mtime_ns) for p in sorted(folder.iterdir())}


def write_rgba(path: Path, rgba: np.ndarray) -> None:
    Image.fromarray(rgba).save(path, format="PNG")


# --- 1, 2: making a golden ------------------------------------------------------------------

ONE_GOLDEN = """
def test_sky(golden):
    golden.check(frame(), scene="sky", gl_info=GL_A)
"""


def test_missing_golden_fails_names_its_path_and_writes_nothing(spec):
    spec.write(ONE_GOLDEN)
    result = spec.run()
    assert outcomes(result) == {"test_sky": "failed"}
    text = failure(result, "test_sky")
    assert "golden 'test_sky' does not exist (goldens/test_sky.png)" in text
    assert "run pytest --update-goldens" in text
    assert_clean_failure(text)
    assert not spec.goldens.exists()
    # The frame is kept for review: the results folder has it, and only it.
    assert sorted(p.name for p in (spec.results / "test_sky").iterdir()) == ["actual.png", "figures.json"]
    assert np.array_equal(read_golden(spec.results / "test_sky" / "actual.png"), GREY)


def test_update_creates_png_and_sidecar_beside_the_test_file(spec):
    spec.write(ONE_GOLDEN)
    result = spec.run("--update-goldens")
    assert outcomes(result) == {"test_sky": "passed"}
    result.stdout.fnmatch_lines(["*- golden images -*", "goldens: 1 created", "written: goldens/test_sky.png"])
    assert sorted(p.name for p in spec.goldens.iterdir()) == ["test_sky.json", "test_sky.png"]

    assert np.array_equal(np.asarray(Image.open(spec.goldens / "test_sky.png")), GREY)
    sidecar = json.loads((spec.goldens / "test_sky.json").read_text())
    assert sidecar["name"] == "test_sky"
    assert sidecar["scene"] == "sky"
    assert sidecar["size"] == [32, 32]
    assert sidecar["policy"] == {"name": "threshold", "threshold": 2, "deviation": 1, "max_failing_pixels": 0}
    assert sidecar["renderer_version"] == renderer.__version__
    assert sidecar["gl_renderer"] == "A"
    assert sidecar["gl_version"] == "4.5"
    assert sidecar["context"] == "egl"
    # SHA-256 of "WxH:" followed by the RGBA bytes, row 0 first.
    assert sidecar["rgba_sha256"] == hashlib.sha256(b"32x32:" + GREY.tobytes()).hexdigest()
    # The new golden is on the review page (there is nothing to compare it with yet).
    page = (spec.results / "index.html").read_text()
    assert "0 failing, 1 written" in page and 'src="test_sky/actual.png"' in page
    assert not (spec.results / "test_sky" / "expected.png").exists()


def test_golden_passes_on_the_next_run_and_a_second_update_rewrites_nothing(spec):
    spec.write(ONE_GOLDEN)
    spec.run("--update-goldens").assert_outcomes(passed=1)
    before = snapshot(spec.goldens)

    result = spec.run()
    result.assert_outcomes(passed=1)
    result.stdout.fnmatch_lines(["goldens: 1 passed"])

    result = spec.run("--update-goldens")
    result.assert_outcomes(passed=1)
    result.stdout.fnmatch_lines(["goldens: 1 unchanged"])
    result.stdout.no_fnmatch_line("written: *")
    assert snapshot(spec.goldens) == before          # same bytes, same mtime


def test_parametrized_test_names_its_golden_after_its_id(spec):
    spec.write("""
        @pytest.mark.parametrize("level", ["a-b", "c/d"])
        def test_param(golden, level):
            golden.check(frame())
    """)
    spec.run("--update-goldens").assert_outcomes(passed=2)
    assert sorted(p.name for p in spec.goldens.glob("*.png")) == ["test_param-a-b.png", "test_param-c_d.png"]


# --- 3, 4: a changed frame ------------------------------------------------------------------

# Phase "after": three pixels one level off (they differ, but pass the default threshold of
# 2/255) and two pixels ten levels off (they fail: no pixel within ±1 is within 2 of them).
CHANGED = """
def test_sky(golden):
    golden.check(frame(after=[(np.s_[0, 0], 1), (np.s_[0, 10], 1), (np.s_[0, 20], 1),
                              (np.s_[20, 5], 10), (np.s_[20, 25], 10)]))
"""


def test_changed_frame_fails_with_figures_and_the_results_page(spec):
    spec.write(CHANGED)
    spec.run("--update-goldens").assert_outcomes(passed=1)
    result = spec.run(phase="after")
    assert outcomes(result) == {"test_sky": "failed"}

    text = failure(result, "test_sky")
    assert_clean_failure(text)
    assert "golden 'test_sky' (goldens/test_sky.png) does not match under " \
           "threshold(threshold=2, deviation=1, max_failing_pixels=0)" in text
    assert "5 pixels differ at all, 2 fail (no match within ±1 px at 2/255), " \
           "largest channel difference 10/255" in text
    assert "images: golden-results/test_sky/; all failures: golden-results/index.html" in text
    assert "pytest --update-goldens" in text
    result.stdout.fnmatch_lines(["goldens: 1 failed", "results: golden-results/index.html"])

    entry = spec.results / "test_sky"
    assert sorted(p.name for p in entry.iterdir()) == [
        "actual.png", "diff.png", "expected.png", "figures.json", "flip.png"]
    assert np.array_equal(read_golden(entry / "expected.png"), GREY)
    actual = read_golden(entry / "actual.png")
    assert actual[20, 5, 0] == 138 and actual[0, 0, 0] == 129
    figures = json.loads((entry / "figures.json").read_text())
    assert figures["pixels_differing"] == 5
    assert figures["pixels_failing"] == 2
    assert figures["max_channel_difference"] == 10
    assert figures["test"] == "test_spec.py::test_sky"
    assert figures["status"] == "failed"
    page = (spec.results / "index.html").read_text()
    assert "1 failing" in page and "test_sky" in page
    for image in ("expected", "actual", "diff", "flip"):
        assert f'src="test_sky/{image}.png"' in page


def test_results_folder_can_be_named_on_the_command_line(spec):
    spec.write(CHANGED)
    spec.run("--update-goldens", "--goldens-results", "out/review").assert_outcomes(passed=1)
    result = spec.run("--goldens-results", "out/review", phase="after")
    assert "all failures: out/review/index.html" in failure(result, "test_sky")
    assert (spec.path / "out/review/test_sky/diff.png").is_file()
    assert (spec.path / "out/review/index.html").is_file()
    assert not spec.results.exists()


def test_goldens_sit_beside_the_test_file_and_results_in_the_rootdir(spec):
    """Run from a subfolder: the goldens go beside the test file, the results to the rootdir
    (the folder of the ini file), not to the current folder."""
    spec.pytester.makeini("[pytest]\n")
    sub = spec.path / "deep" / "er"
    sub.mkdir(parents=True)
    (sub / "test_sub.py").write_text(PRELUDE + textwrap.dedent(CHANGED))
    spec.monkeypatch.chdir(spec.path / "deep")
    spec.run("--update-goldens", "er").assert_outcomes(passed=1)
    assert (sub / "goldens" / "test_sky.png").is_file()
    result = spec.run("er", phase="after")
    assert f"all failures: {spec.results / 'index.html'}" in failure(result, "test_sky")
    assert (spec.results / "test_sky" / "diff.png").is_file()
    assert not (spec.path / "deep" / "golden-results").exists()
    assert not spec.goldens.exists()


def test_update_rewrites_a_changed_golden_and_the_next_run_passes(spec):
    spec.write(CHANGED)
    spec.run("--update-goldens").assert_outcomes(passed=1)
    old_sidecar = json.loads((spec.goldens / "test_sky.json").read_text())

    result = spec.run("--update-goldens", phase="after")
    result.assert_outcomes(passed=1)
    result.stdout.fnmatch_lines(["goldens: 1 updated", "written: goldens/test_sky.png",
                                 "results: golden-results/index.html"])
    new = read_golden(spec.goldens / "test_sky.png")
    assert new[20, 5, 0] == 138
    sidecar = json.loads((spec.goldens / "test_sky.json").read_text())
    assert sidecar["rgba_sha256"] == pixels_sha256(new) != old_sidecar["rgba_sha256"]
    # The update is listed for review, with the old golden beside the new frame.
    assert (spec.results / "test_sky" / "expected.png").is_file()
    assert "1 written" in (spec.results / "index.html").read_text()

    spec.run(phase="after").assert_outcomes(passed=1)


def test_update_keeps_a_golden_the_frame_passes_unless_asked_for_all(spec):
    """Plain --update-goldens rewrites only goldens that fail their policy: one broken golden
    does not drag along every golden that differs within tolerance. --update-goldens=all
    rewrites every golden whose pixels differ at all."""
    spec.write("""
        def test_within(golden):
            golden.check(frame(after=[(np.s_[0, 0], 1), (np.s_[3, 3], 2)]))

        def test_broken(golden):
            golden.check(frame(after=[(np.s_[20, 5], 10)]))
    """)
    spec.run("--update-goldens").assert_outcomes(passed=2)
    within_before = snapshot(spec.goldens)["test_within.png"]

    result = spec.run("--update-goldens", phase="after")
    result.assert_outcomes(passed=2)
    result.stdout.fnmatch_lines(["goldens: 1 passed, 1 updated", "written: goldens/test_broken.png"])
    result.stdout.no_fnmatch_line("written: goldens/test_within.png")
    assert snapshot(spec.goldens)["test_within.png"] == within_before
    assert np.array_equal(read_golden(spec.goldens / "test_within.png"), GREY)

    result = spec.run("--update-goldens=all", phase="after")
    result.assert_outcomes(passed=2)
    result.stdout.fnmatch_lines(["goldens: 1 unchanged, 1 updated", "written: goldens/test_within.png"])
    assert read_golden(spec.goldens / "test_within.png")[3, 3, 0] == 130
    assert snapshot(spec.goldens)["test_within.png"] != within_before


def test_update_all_creates_missing_goldens_too_and_the_path_is_not_its_value(spec):
    spec.write(ONE_GOLDEN)
    spec.run("--update-goldens=all").assert_outcomes(passed=1)
    assert (spec.goldens / "test_sky.png").is_file()
    # A path after plain --update-goldens is a path, not the option's value.
    spec.run("--update-goldens", "test_spec.py").assert_outcomes(passed=1)


def test_only_the_golden_that_changed_fails(spec):
    spec.write("""
        def test_one(golden):
            golden.check(frame())

        def test_two(golden):
            golden.check(frame(after=[(np.s_[10:12, 10:12], 50)]))

        def test_three(golden):
            golden.check(frame(), "third")
            golden.check(frame(), "fourth")
    """)
    spec.run("--update-goldens").assert_outcomes(passed=3)
    result = spec.run(phase="after")
    assert outcomes(result) == {"test_one": "passed", "test_two": "failed", "test_three": "passed"}
    assert "4 pixels differ at all, 4 fail" in failure(result, "test_two")
    result.stdout.fnmatch_lines(["goldens: 1 failed, 3 passed"])
    assert sorted(p.name for p in spec.results.iterdir() if p.is_dir()) == ["test_two"]


# --- 5: policies ----------------------------------------------------------------------------

POLICIES = """
def test_exact_one_level_in_one_pixel(golden):
    golden.check(frame(after=[(np.s_[5, 5], 1)]), policy="exact")

def test_exact_identical(golden):
    golden.check(frame(), policy="exact")

def test_threshold_one_level_everywhere(golden):
    golden.check(frame(after=[(np.s_[:, :], 1)]))

def test_threshold_two_levels_everywhere(golden):
    golden.check(frame(after=[(np.s_[:, :], 2)]))

def test_threshold_three_levels_everywhere(golden):
    golden.check(frame(after=[(np.s_[:, :], 3)]))

def test_max_failing_3_with_3_failing(golden):
    golden.check(frame(after=[(np.s_[2, 2], 10), (np.s_[2, 12], 10), (np.s_[2, 22], 10)]),
                 policy={"name": "threshold", "max_failing_pixels": 3})

def test_max_failing_3_with_4_failing(golden):
    golden.check(frame(after=[(np.s_[2, 2], 10), (np.s_[2, 12], 10), (np.s_[2, 22], 10),
                              (np.s_[22, 22], 10)]),
                 policy={"name": "threshold", "max_failing_pixels": 3})

def test_flip_one_pixel_20_levels(golden):
    golden.check(frame(after=[(np.s_[5, 5], 20)]), policy="flip")

def test_flip_8x8_block_black(golden):
    golden.check(frame(after=[(np.s_[8:16, 8:16], -128)]), policy="flip")
"""


def test_flip_cases_have_margin():
    """The figures the flip cases below rely on, measured: default bound 0.01."""
    tiny, large = GREY.copy(), GREY.copy()
    tiny[5, 5, :3] += 20
    large[8:16, 8:16, :3] = 0
    assert flip_error(GREY, tiny)[0] < 0.002          # measured 0.00077
    assert flip_error(GREY, large)[0] > 0.05          # measured 0.069


def test_each_policy_passes_and_fails_where_it_should(spec):
    spec.write(POLICIES)
    spec.run("--update-goldens").assert_outcomes(passed=9)
    result = spec.run(phase="after")
    assert outcomes(result) == {
        "test_exact_one_level_in_one_pixel": "failed",
        "test_exact_identical": "passed",
        "test_threshold_one_level_everywhere": "passed",
        "test_threshold_two_levels_everywhere": "passed",
        "test_threshold_three_levels_everywhere": "failed",
        "test_max_failing_3_with_3_failing": "passed",
        "test_max_failing_3_with_4_failing": "failed",
        "test_flip_one_pixel_20_levels": "passed",
        "test_flip_8x8_block_black": "failed",
    }
    assert "exact(): 1 pixels differ (none may)" in failure(result, "test_exact_one_level_in_one_pixel")
    assert "1024 pixels fail within ±1 px at 2/255 (at most 0 may)" in \
        failure(result, "test_threshold_three_levels_everywhere")
    assert "4 pixels fail within ±1 px at 2/255 (at most 3 may)" in \
        failure(result, "test_max_failing_3_with_4_failing")
    text = failure(result, "test_flip_8x8_block_black")
    assert "flip(max_mean=0.01): mean ꟻLIP 0.06" in text and "(at most 0.01 may)" in text
    # The sidecar records the policy the golden is held to.
    sidecar = json.loads((spec.goldens / "test_max_failing_3_with_3_failing.json").read_text())
    assert sidecar["policy"] == {"name": "threshold", "threshold": 2, "deviation": 1, "max_failing_pixels": 3}
    assert json.loads((spec.goldens / "test_flip_8x8_block_black.json").read_text())["policy"] == \
        {"name": "flip", "max_mean": 0.01}


def test_bad_policies_fail_with_a_clear_message(spec):
    spec.write("""
        def test_unknown_name(golden):
            golden.check(frame(), policy="fuzzy")

        def test_threshold_out_of_range(golden):
            golden.check(frame(), policy={"name": "threshold", "threshold": 300})

        def test_flip_bound_out_of_range(golden):
            golden.check(frame(), policy={"name": "flip", "max_mean": 2})

        def test_unknown_parameter(golden):
            golden.check(frame(), policy={"name": "exact", "threshold": 1})
    """)
    result = spec.run("--update-goldens")
    result.assert_outcomes(failed=4)
    expected = {
        "test_unknown_name": "policy: unknown policy 'fuzzy'; known policies: exact, threshold, flip",
        "test_threshold_out_of_range": "threshold.threshold: must be a whole number 0 to 255, got 300",
        "test_flip_bound_out_of_range": "flip.max_mean: must be a number from 0 to 1, got 2",
        "test_unknown_parameter": "exact: unknown parameter 'threshold'; exact takes no parameters",
    }
    for test, message in expected.items():
        text = failure(result, test)
        assert_clean_failure(text)
        assert text.strip() == message
    assert not spec.goldens.exists()                 # a bad policy writes nothing, even when updating


def test_ini_option_sets_the_default_policy(spec):
    spec.pytester.makeini("[pytest]\ngoldens_policy = exact\n")
    spec.write("""
        def test_default(golden):
            golden.check(frame(after=[(np.s_[5, 5], 1)]))

        def test_named(golden):
            golden.check(frame(after=[(np.s_[5, 5], 1)]), policy="threshold")
    """)
    spec.run("--update-goldens").assert_outcomes(passed=2)
    assert json.loads((spec.goldens / "test_default.json").read_text())["policy"] == {"name": "exact"}
    result = spec.run(phase="after")
    assert outcomes(result) == {"test_default": "failed", "test_named": "passed"}
    assert "does not match under exact(): 1 pixels differ" in failure(result, "test_default")


def test_unknown_policy_in_the_ini_fails_clearly(spec):
    spec.pytester.makeini("[pytest]\ngoldens_policy = fuzzy\n")
    spec.write(ONE_GOLDEN)
    result = spec.run("--update-goldens")
    assert failure(result, "test_sky").strip() == \
        "policy: unknown policy 'fuzzy'; known policies: exact, threshold, flip"


# --- 6: wrong use ---------------------------------------------------------------------------

def test_golden_of_another_size_fails_giving_both_sizes(spec):
    spec.write("""
        def test_sky(golden):
            golden.check(frame(size=(16, 8) if PHASE == "after" else (32, 32)))
    """)
    spec.run("--update-goldens").assert_outcomes(passed=1)
    result = spec.run(phase="after")
    text = failure(result, "test_sky")
    assert_clean_failure(text)
    assert "goldens/test_sky.png: size: the golden is 32x32 and the frame is 16x8" in text
    assert "render at 32x32, or run pytest --update-goldens" in text


def test_frame_that_is_not_rgba8_fails(spec):
    spec.write("""
        def test_float(golden):
            golden.check(frame().astype(np.float32))

        def test_rgb(golden):
            golden.check(frame()[..., :3])
    """)
    result = spec.run("--update-goldens")
    assert "a golden holds an (H, W, 4) uint8 RGBA image; got float32 (32, 32, 4)" in failure(result, "test_float")
    assert "got uint8 (32, 32, 3)" in failure(result, "test_rgb")
    assert not spec.goldens.exists()


def _noisy_png_bytes() -> bytes:
    """A real PNG that does not compress to almost nothing, so cutting it cuts pixel data."""
    rgba = np.random.default_rng(1).integers(0, 256, (32, 32, 4), dtype=np.uint8)
    buffer = io.BytesIO()
    Image.fromarray(rgba).save(buffer, format="PNG")
    return buffer.getvalue()


# "signature then garbage" is the full run's (--all): past the signature, Pillow's error takes
# the branch of read_golden that "truncated" takes ("cannot be read as a PNG (...)"), which
# the default run holds.
@pytest.mark.parametrize("damage, reason", [
    pytest.param("garbage", "not a PNG file (its first bytes are not PNG's signature)",
                 id="garbage"),
    pytest.param("truncated", "cannot be read as a PNG (image file is truncated)", id="truncated"),
    pytest.param("signature then garbage", "cannot be read as a PNG (", id="signature-then-garbage",
                 marks=pytest.mark.slow),
])
def test_corrupt_golden_png_fails_naming_the_file(spec, damage, reason):
    spec.write(ONE_GOLDEN)
    spec.run("--update-goldens").assert_outcomes(passed=1)
    png = spec.goldens / "test_sky.png"
    real = _noisy_png_bytes()
    png.write_bytes({"garbage": b"this is not an image\n" * 10,
                     "truncated": real[:len(real) // 2],
                     "signature then garbage": real[:8] + b"\x00garbage" * 20}[damage])
    result = spec.run()
    text = failure(result, "test_sky")
    assert_clean_failure(text)
    assert text.startswith(f"{png}: {reason}"), text
    assert "restore it from version control or run pytest --update-goldens" in text

    # --update-goldens replaces an unreadable golden; then it passes.
    spec.run("--update-goldens").assert_outcomes(passed=1)
    assert np.array_equal(read_golden(png), GREY)
    spec.run().assert_outcomes(passed=1)


@pytest.mark.parametrize("content, reason", [
    ("{ not json", "cannot be read as JSON (Expecting property name"),
    ("[1, 2]", "must hold a JSON object"),
    (None, "the golden has no JSON sidecar; run pytest --update-goldens to write it"),
], ids=["bad-json", "not-an-object", "missing"])
def test_corrupt_or_missing_sidecar_fails_naming_the_file(spec, content, reason):
    spec.write(ONE_GOLDEN)
    spec.run("--update-goldens").assert_outcomes(passed=1)
    sidecar = spec.goldens / "test_sky.json"
    if content is None:
        sidecar.unlink()
    else:
        sidecar.write_text(content)
    text = failure(spec.run(), "test_sky")
    assert_clean_failure(text)
    assert text.startswith(f"{sidecar}: {reason}"), text

    spec.run("--update-goldens").assert_outcomes(passed=1)
    assert json.loads(sidecar.read_text())["name"] == "test_sky"
    spec.run().assert_outcomes(passed=1)


def test_invalid_golden_names_fail(spec):
    spec.write("""
        @pytest.mark.parametrize("name", ["../x", "a/b", ".hidden", "x" * 151])
        def test_name(golden, name):
            golden.check(frame(), name)
    """)
    result = spec.run("--update-goldens")
    result.assert_outcomes(failed=4)
    for report in result.reprec.getfailures():
        assert_clean_failure(report.longreprtext)
        assert "is not a golden name: use letters, digits, '.', '_' and '-'" in report.longreprtext
    assert "name: '../x' is not a golden name" in failure(result, "test_name[../x]")
    assert not spec.goldens.exists() and not (spec.path / "x.png").exists()


# --- 7, 8: what the sidecar tells ----------------------------------------------------------

def test_golden_from_another_gl_implementation(spec):
    spec.write("""
        def test_same_pixels(golden):
            golden.check(frame(), gl_info=GL_B if PHASE == "after" else GL_A)

        def test_other_pixels(golden):
            golden.check(frame(after=[(np.s_[3:5, 3:5], 40)]), gl_info=GL_B if PHASE == "after" else GL_A)

        def test_same_implementation(golden):
            golden.check(frame(), gl_info=GL_A)
    """)
    spec.run("--update-goldens").assert_outcomes(passed=3)
    result = spec.run(phase="after")
    assert outcomes(result) == {"test_same_pixels": "passed", "test_other_pixels": "failed",
                                "test_same_implementation": "passed"}
    note = ("the golden was made on another GL implementation: A / 4.5; this frame comes from "
            "B / 4.5, so a difference may be the implementation's, not your change")
    assert note in failure(result, "test_other_pixels")
    result.stdout.fnmatch_lines(["*warnings summary*", "*test_same_pixels*",
                                 f"*GoldenWarning: golden 'test_same_pixels': {note}"])
    assert "test_same_implementation" not in result.stdout.str().split("warnings summary")[1]
    result.assert_outcomes(passed=2, failed=1, warnings=1)


EDITED_NOTE = "test_sky.json does not describe these pixels: the PNG was changed after its sidecar was written"


def test_png_edited_after_its_sidecar_fails_and_says_so(spec):
    spec.write(ONE_GOLDEN)
    spec.run("--update-goldens").assert_outcomes(passed=1)
    edited = GREY.copy()
    edited[9, 9, :3] = 0                       # one pixel, by hand
    write_rgba(spec.goldens / "test_sky.png", edited)

    result = spec.run()
    text = failure(result, "test_sky")
    assert_clean_failure(text)
    assert "1 pixels differ at all, 1 fail" in text
    assert EDITED_NOTE in text


def test_png_edited_within_tolerance_passes_with_a_warning(spec):
    """The sidecar's hash notices the edit, but the frame still matches the PNG under the
    policy: the test passes and the warning says what was seen."""
    spec.write(ONE_GOLDEN)
    spec.run("--update-goldens").assert_outcomes(passed=1)
    edited = GREY.copy()
    edited[9, 9, :3] += 1
    write_rgba(spec.goldens / "test_sky.png", edited)

    result = spec.run()
    result.assert_outcomes(passed=1, warnings=1)
    result.stdout.fnmatch_lines([f"*GoldenWarning: golden 'test_sky': {EDITED_NOTE}*"])
    # --update-goldens puts PNG and sidecar back in step.
    result = spec.run("--update-goldens")
    result.stdout.fnmatch_lines(["goldens: 1 updated"])
    result = spec.run()
    result.assert_outcomes(passed=1)
    assert "GoldenWarning" not in result.stdout.str()


# --- 9: atomic writes -----------------------------------------------------------------------

def _interrupt_after_some_bytes(monkeypatch):
    """Make every PNG save write a few bytes, then raise KeyboardInterrupt (Ctrl-C)."""
    def save(self, fp, *args, **kwargs):
        fp.write(b"\x89PNG\r\n\x1a\n half a PNG")
        raise KeyboardInterrupt
    monkeypatch.setattr(Image.Image, "save", save)


def test_interrupted_update_leaves_the_old_golden_and_no_temporary_file(tmp_path, monkeypatch):
    assert check_golden(tmp_path, "sky", GREY, update=True).status == "created"
    before = snapshot(tmp_path)
    changed = GREY.copy()
    changed[0, 0, :3] = 0

    _interrupt_after_some_bytes(monkeypatch)
    with pytest.raises(KeyboardInterrupt):
        check_golden(tmp_path, "sky", changed, update=True)
    monkeypatch.undo()

    assert snapshot(tmp_path) == before                # both files: same bytes, same mtime
    assert sorted(p.name for p in tmp_path.iterdir()) == ["sky.json", "sky.png"]
    assert not list(tmp_path.glob(".sky.png.*.tmp"))
    assert check_golden(tmp_path, "sky", GREY).status == "passed"


def test_update_interrupted_between_png_and_sidecar_is_noticed(tmp_path, monkeypatch):
    """The PNG is written first; if the sidecar's write is cut short, the old sidecar stays
    and the next check says the two disagree."""
    check_golden(tmp_path, "sky", GREY, update=True)
    sidecar_before = (tmp_path / "sky.json").read_bytes()
    changed = GREY.copy()
    changed[0, 0, :3] = 0

    import renderer.checks.goldens
    def write_text(path, text):
        raise KeyboardInterrupt
    monkeypatch.setattr(renderer.checks.goldens, "write_text", write_text)
    with pytest.raises(KeyboardInterrupt):
        check_golden(tmp_path, "sky", changed, update=True)
    monkeypatch.undo()

    assert np.array_equal(read_golden(tmp_path / "sky.png"), changed)
    assert (tmp_path / "sky.json").read_bytes() == sidecar_before
    outcome = check_golden(tmp_path, "sky", changed)
    assert any("changed after its sidecar was written (by hand, or by an interrupted update)" in note
               for note in outcome.notes)
    assert check_golden(tmp_path, "sky", changed, update=True).status == "refreshed"
    assert check_golden(tmp_path, "sky", changed).notes == []


# --- 10: the results folder -----------------------------------------------------------------

def test_results_folder_not_made_by_the_plugin_is_refused(spec):
    spec.write(ONE_GOLDEN)
    spec.results.mkdir()
    (spec.results / "my-notes.txt").write_text("mine")
    result = spec.run("--update-goldens")
    text = failure(result, "test_sky")
    assert_clean_failure(text)
    assert text.startswith(f"{spec.results}: --goldens-results: exists, is not empty and was not made by "
                           "the golden plugin (it has no .golden-results marker)"), text
    assert sorted(p.name for p in spec.results.iterdir()) == ["my-notes.txt"]   # nothing deleted
    assert not spec.goldens.exists()


def test_results_folder_that_is_a_file_is_refused(spec):
    spec.write(ONE_GOLDEN)
    (spec.path / "review").write_text("a file")
    text = failure(spec.run("--goldens-results", "review"), "test_sky")
    assert text.strip() == f"{spec.path / 'review'}: --goldens-results: is not a folder"
    assert (spec.path / "review").read_text() == "a file"


def test_results_folder_is_emptied_by_the_next_run(spec):
    spec.write(CHANGED)
    spec.run("--update-goldens").assert_outcomes(passed=1)
    spec.run(phase="after").assert_outcomes(failed=1)
    assert (spec.results / "test_sky" / "diff.png").is_file()
    assert (spec.results / ".golden-results").is_file()

    spec.run().assert_outcomes(passed=1)               # run 2: the golden's own frame
    assert sorted(p.name for p in spec.results.iterdir()) == [".golden-results", "index.html"]
    assert "0 failing, 0 written" in (spec.results / "index.html").read_text()


def test_an_empty_folder_is_taken_as_the_results_folder(spec):
    spec.write(CHANGED)
    spec.run("--update-goldens").assert_outcomes(passed=1)
    (spec.path / "review").mkdir()
    spec.run("--goldens-results", "review", phase="after").assert_outcomes(failed=1)
    assert (spec.path / "review" / ".golden-results").is_file()
    assert (spec.path / "review" / "test_sky" / "actual.png").is_file()


# --- 11, 12: names --------------------------------------------------------------------------

TWO_TESTS_ONE_NAME = """
def test_first(golden):
    golden.check(frame(), "shared")

def test_second(golden):
    golden.check(frame(before=[(np.s_[0:8, 0:8], 60)], after=[(np.s_[0:8, 0:8], 60)]), "shared")
"""


def test_two_tests_updating_one_golden_name_the_second_is_compared(spec):
    spec.write(TWO_TESTS_ONE_NAME)
    result = spec.run("--update-goldens")
    assert outcomes(result) == {"test_first": "passed", "test_second": "failed"}
    assert "golden 'shared' (goldens/shared.png) does not match" in failure(result, "test_second")
    result.stdout.fnmatch_lines(["goldens: 1 created, 1 failed"])
    assert np.array_equal(read_golden(spec.goldens / "shared.png"), GREY)   # the first test's frame


def test_two_tests_sharing_an_unchanged_golden_the_second_does_not_overwrite_it(spec):
    """The same rule when the golden already holds the first test's frame ("unchanged"):
    the second test is compared, not written, or the two would rewrite it in turn."""
    spec.write(TWO_TESTS_ONE_NAME)
    spec.run("--update-goldens", "-k", "test_first").assert_outcomes(passed=1, deselected=1)
    before = snapshot(spec.goldens)
    result = spec.run("--update-goldens")
    assert outcomes(result) == {"test_first": "passed", "test_second": "failed"}
    result.stdout.fnmatch_lines(["goldens: 1 failed, 1 unchanged"])
    assert snapshot(spec.goldens) == before


def test_second_check_without_a_name_fails_asking_for_one(spec):
    spec.write("""
        def test_twice(golden):
            golden.check(frame())
            golden.check(frame())

        def test_twice_named(golden):
            golden.check(frame(), "left")
            golden.check(frame(), "right")
    """)
    result = spec.run("--update-goldens")
    assert outcomes(result) == {"test_twice": "failed", "test_twice_named": "passed"}
    text = failure(result, "test_twice")
    assert_clean_failure(text)
    assert text.strip() == ("this test already checked a golden named 'test_twice'; give each check "
                            "its own name=")
    assert sorted(p.name for p in spec.goldens.glob("*.png")) == ["left.png", "right.png", "test_twice.png"]


# --- 12b: under pytest-xdist (CI runs `pytest --all -n auto`) -------------------------------

# Eight checks: six goldens that the "after" phase breaks, two it keeps, one name checked twice.
SPREAD = """
@pytest.mark.parametrize("k", range(6))
def test_broken(golden, k):
    golden.check(frame(after=[(np.s_[k, k], 10)]), f"broken{k}")

def test_kept(golden):
    golden.check(frame(), "kept")

@pytest.mark.parametrize("context", ["egl", "osmesa"])
def test_shared(golden, context):
    golden.check(frame(after=[(np.s_[0, 0], 10)]), "shared")
"""


@pytest.mark.slow          # two worker processes: about 2 s
def test_under_xdist_the_controller_reports_every_worker_s_failures(spec):
    """Workers write their failures' images; the controller, which emptied the folder once
    before they started, lists all of them on one page and prints the summary."""
    spec.write(SPREAD)
    spec.run("--update-goldens").assert_outcomes(passed=9)
    (spec.results / "stale").mkdir()                        # an earlier run's entry

    result = spec.run("-n", "2", phase="after")
    result.assert_outcomes(failed=8, passed=1)
    result.stdout.fnmatch_lines(["goldens: 8 failed, 1 passed", "results: golden-results/index.html"])
    folders = [f"broken{k}" for k in range(6)] + ["shared", "shared-2"]
    assert sorted(p.name for p in spec.results.iterdir() if p.is_dir()) == sorted(folders)
    for folder in folders:
        assert sorted(p.name for p in (spec.results / folder).iterdir()) == [
            "actual.png", "diff.png", "expected.png", "figures.json", "flip.png"]
    page = (spec.results / "index.html").read_text()
    assert "8 failing, 0 written" in page
    for folder in folders:
        assert f'src="{folder}/diff.png"' in page
    shared = {json.loads((spec.results / f / "figures.json").read_text())["test"] for f in ("shared", "shared-2")}
    assert shared == {"test_spec.py::test_shared[egl]", "test_spec.py::test_shared[osmesa]"}


def test_under_xdist_update_goldens_runs_in_one_process(spec):
    """--update-goldens turns -n off: a golden one test writes is what a later test of the
    same name is compared with, whichever worker would have run it."""
    spec.write(TWO_TESTS_ONE_NAME)
    result = spec.run("-n", "2", "--update-goldens")
    result.stdout.fnmatch_lines(["goldens: --update-goldens runs the tests in one process*"])
    assert outcomes(result) == {"test_first": "passed", "test_second": "failed"}
    result.stdout.fnmatch_lines(["goldens: 1 created, 1 failed"])
    assert np.array_equal(read_golden(spec.goldens / "shared.png"), GREY)


# --- 13: inert when unused ------------------------------------------------------------------

def test_plugin_is_inert_when_no_test_uses_golden(spec):
    spec.write("""
        def test_plain():
            assert frame().shape == (32, 32, 4)
    """)
    result = spec.run("--update-goldens")
    result.assert_outcomes(passed=1)
    assert "golden images" not in result.stdout.str()
    assert "goldens:" not in result.stdout.str()
    assert sorted(p.name for p in spec.path.iterdir()) == ["test_spec.py"]


def test_options_are_listed_in_help(spec):
    result = spec.run("--help")
    result.stdout.fnmatch_lines(["*golden images (checked-renderer)*", "*--update-goldens*",
                                 "*--update-goldens=all*",
                                 "*--goldens-results=DIR*", "*goldens_policy*"])


# --- 14: a real GL frame --------------------------------------------------------------------

def test_check_scene_records_the_real_gl_implementation(spec):
    spec.write("""
        def test_sphere(golden):
            frame = golden.check_scene("sphere", size=(64, 64), context="egl")
            assert frame.rgba8.shape == (64, 64, 4)
    """)
    spec.run("--update-goldens").assert_outcomes(passed=1)
    sidecar = json.loads((spec.goldens / "test_sphere.json").read_text())
    assert sidecar["scene"] == "sphere"
    assert sidecar["size"] == [64, 64]
    assert sidecar["context"] == "egl"
    assert isinstance(sidecar["gl_renderer"], str) and sidecar["gl_renderer"]
    assert isinstance(sidecar["gl_version"], str) and sidecar["gl_version"]
    assert (read_golden(spec.goldens / "test_sphere.png")[..., 3] == 255).any()   # something drawn

    result = spec.run()
    result.assert_outcomes(passed=1)
    assert "GoldenWarning" not in result.stdout.str()


def test_check_scene_ray_traces_with_the_tracer_options(spec):
    """method="raytrace": the frame is RayTracer's, with the options given (4 samples here);
    tracer options without it, and an unknown method, fail with one line."""
    spec.write("""
        from renderer.core.scene_file import load_scene
        from renderer.gpu.raytracer import RayTracer

        def test_traced(golden):
            frame = golden.check_scene("classic", size=(32, 24), context="egl", method="raytrace",
                                       samples=4)
            with RayTracer(load_scene("classic"), 32, 24, context_kind="egl", samples=4) as tracer:
                assert np.array_equal(frame.rgba8, tracer.render().rgba8)
            with RayTracer(load_scene("classic"), 32, 24, context_kind="egl") as tracer:
                assert not np.array_equal(frame.rgba8, tracer.render().rgba8)   # 1 sample differs

        def test_raster_with_samples(golden):
            golden.check_scene("sphere", size=(8, 8), samples=4)

        def test_unknown_method(golden):
            golden.check_scene("sphere", size=(8, 8), method="photon_map")
    """)
    result = spec.run("--update-goldens")
    assert outcomes(result) == {"test_traced": "passed", "test_raster_with_samples": "failed",
                                "test_unknown_method": "failed"}
    assert json.loads((spec.goldens / "test_traced.json").read_text())["scene"] == "classic"
    assert failure(result, "test_raster_with_samples").strip() == "samples: is for method raytrace, not raster"
    assert failure(result, "test_unknown_method").strip() == \
        "method: unknown method 'photon_map'; one of raster, raytrace, radiosity, pathtrace"
    assert outcomes(spec.run("-k", "traced")) == {"test_traced": "passed"}
