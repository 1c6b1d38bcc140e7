"""The report's output section (renderer/study/output_report.py): its measures by hand, the
eye's low-pass, the ranking, and a tiny sweep through `run_report`."""

import math
from dataclasses import replace

import numpy as np
import pytest

from renderer.core.output_settings import OutputSettings, Transfer
from renderer.study.output_report import (EYE_SIGMA, gaussian_blur, output_errors, output_variants,
                                          ranking)

SRGB = Transfer("srgb")


def flat(value: float, height: int = 16, width: int = 16) -> np.ndarray:
    linear = np.full((height, width, 4), value, np.float32)
    linear[..., 3] = 1.0
    return linear


def test_a_flat_field_shown_one_level_up_is_off_by_the_level_everywhere():
    """Grey 0.5 shown at 1 bit as white: every block 0.5 too light, PSNR 10 log10(1 / 0.25)."""
    codes = np.ones((16, 16, 4), np.uint16)
    errors = output_errors(flat(0.5), codes, OutputSettings(SRGB, 1))
    assert errors["block_bias"] == errors["block_mean_abs"] == errors["block_max_abs"] == pytest.approx(0.5)
    assert errors["lowpass_psnr"] == pytest.approx(10 * math.log10(4))
    assert errors["flip_mean"] > 0.1


def test_a_fine_checker_at_its_mean_is_what_the_eye_averages():
    """Black and white pixels, half each, against grey 0.5 of light: every block keeps its
    mean (bias 0); the eye's low-pass leaves a small ripple, so the PSNR is high but finite."""
    codes = np.zeros((16, 16, 4), np.uint16)
    codes[::2, ::2, :3] = codes[1::2, 1::2, :3] = 1
    errors = output_errors(flat(0.5), codes, OutputSettings(SRGB, 1))
    assert errors["block_bias"] == errors["block_max_abs"] == 0
    assert 25 < errors["lowpass_psnr"] < math.inf


def test_the_eye_is_flips_achromatic_filter_at_67_pixels_per_degree():
    assert EYE_SIGMA == pytest.approx(math.sqrt(0.0047 / (2 * math.pi ** 2)) * 67.0206, rel=1e-5)
    assert EYE_SIGMA == pytest.approx(1.034, abs=1e-3)


def test_the_low_pass_is_a_normalised_gaussian_with_mirrored_edges():
    ndimage = pytest.importorskip("scipy.ndimage")
    image = np.random.default_rng(3).random((20, 24))
    radius = math.ceil(3 * EYE_SIGMA)
    expected = ndimage.gaussian_filter(image, EYE_SIGMA, mode="reflect", radius=radius)
    np.testing.assert_allclose(gaussian_blur(image, EYE_SIGMA), expected, atol=1e-12)
    np.testing.assert_allclose(gaussian_blur(np.full((9, 9), 0.3), EYE_SIGMA), 0.3, atol=1e-15)


def test_settings_run_on_both_backends_but_code_value_dithering_on_the_reference():
    found = {name: backends for name, _, backends in output_variants(
        ("none", "bayer8"), (1, 8), True, ("blue-noise",))}
    assert found == {"none 1-bit": ("gpu", "reference"), "none 8-bit": ("gpu", "reference"),
                     "bayer8 1-bit": ("gpu", "reference"), "bayer8 8-bit": ("gpu", "reference"),
                     "halftone 1-bit": ("gpu", "reference"),
                     "code-value blue-noise 1-bit": ("reference",),
                     "code-value blue-noise 8-bit": ("reference",)}


def test_the_ranking_is_by_low_pass_psnr_averaged_over_scenes_with_flips_order_beside():
    def row(scene, method, psnr, flip, backend="gpu"):
        return {"scene": scene, "knob": "output", "method": method, "bits": 1, "backend": backend,
                "median_ms": 1.0, "lowpass_psnr": psnr, "flip_mean": flip, "block_mean_abs": 0.0,
                "block_p95_abs": 0.0, "block_max_abs": 0.0, "block_bias": 0.0}
    rows = [row("a", "none", 10, 0.5), row("b", "none", 20, 0.5),
            row("a", "bayer4", 30, 0.3), row("b", "bayer4", 20, 0.3),
            row("a", "code-value blue-noise", 18, 0.2, "reference")]
    order = [(method, f["lowpass_psnr"], f["flip_rank"]) for method, f in ranking(rows)]
    assert order == [("bayer4", 25, 2), ("code-value blue-noise", 18, 1), ("none", 15, 3)]


@pytest.mark.slow                       # about 3 s: a context, a frame, plots
def test_a_tiny_output_sweep_writes_its_rows_section_and_plot(tmp_path):
    from renderer.core.scene_file import load_scene
    from renderer.study.report import QUICK, run_report
    sweep = replace(QUICK, output_methods=("none", "blue-noise"), output_bits=(1,),
                    output_halftone=True, output_code_value=("blue-noise",), runs=1)
    result = run_report([load_scene("sphere")], tmp_path, sweep_name="quick", size=(32, 24),
                        knobs=("output",), sweep=sweep, context_kind="osmesa")
    assert [(r["setting"], r["backend"]) for r in result.rows] == [
        ("none 1-bit", "gpu"), ("none 1-bit", "reference"), ("blue-noise 1-bit", "gpu"),
        ("blue-noise 1-bit", "reference"), ("halftone 1-bit", "gpu"),
        ("halftone 1-bit", "reference"), ("code-value blue-noise 1-bit", "reference")]
    assert result.truth_hits == 0 and not any("rmse" in r for r in result.rows)   # no truth
    by = {(r["method"], r["backend"]): r for r in result.rows}
    for method in ("none", "blue-noise", "halftone"):     # the same codes on both backends
        assert by[(method, "gpu")]["lowpass_psnr"] == by[(method, "reference")]["lowpass_psnr"]
    # linear-light dithering keeps the light; dithering code values brightens
    assert abs(by[("blue-noise", "gpu")]["block_bias"]) < by[("code-value blue-noise", "reference")]["block_bias"]
    report = (tmp_path / "report.md").read_text()
    assert "### Ranking at 1 bit per channel" in report and "Ground truth" not in report
    assert (tmp_path / "plots" / "sphere-output.png").read_bytes().startswith(b"\x89PNG")
