"""The quantisation rule (renderer/core/quantise.py) and the output settings that choose it
(renderer/core/output_settings.py): hand-checked cases first, then the tables against the rule."""

import numpy as np
import pytest

from renderer.core.gl_rules import to_unorm8
from renderer.core.output_settings import (OutputSettings, Halftone, Transfer, parse_bits,
                                           parse_halftone, parse_transfer)
from renderer.core.quantise import code_of, code_values, decision_points, decode, encode
from renderer.gpu.defines import output_defines

LINEAR, SRGB, GAMMA = Transfer("linear"), Transfer("srgb"), Transfer("gamma", 2.2)


def test_srgb_curve_by_hand():
    # IEC 61966-2-1: the linear segment below 0.0031308, 1.055 L^(1/2.4) - 0.055 above
    assert encode(0.0, SRGB) == 0.0
    assert encode(0.001, SRGB) == pytest.approx(0.01292, abs=1e-15)
    assert encode(1.0, SRGB) == pytest.approx(1.0, abs=1e-15)
    assert encode(0.5, SRGB) == pytest.approx(1.055 * 0.5 ** (1 / 2.4) - 0.055, abs=1e-15)
    assert encode(0.25, GAMMA) == pytest.approx(0.25 ** (1 / 2.2), abs=1e-15)


def test_negative_and_nan_count_as_zero():
    assert encode(np.array([-1.0, np.nan]), SRGB).tolist() == [0.0, 0.0]
    assert code_of(np.array([-1.0, np.nan, 2.0], np.float32), SRGB, 8).tolist() == [0, 0, 255]


@pytest.mark.parametrize("transfer", [LINEAR, SRGB, GAMMA], ids=str)
def test_decode_inverts_encode(transfer):
    light = np.linspace(0, 1, 1001)
    assert np.allclose(decode(encode(light, transfer), transfer), light, atol=1e-12)


def test_one_bit_splits_at_the_encoded_midpoint():
    # 1 bit: code 1 from the L whose encoded value is 1/2: sRGB's 0.214041..., linear 0.5 less one
    # ulp, because GL's conversion adds 0.5 in float32 and 0.49999997 + 0.5 rounds to 1
    assert decision_points(LINEAR, 1)[0] == np.nextafter(np.float32(0.5), np.float32(0))
    assert decision_points(SRGB, 1)[0] == pytest.approx(decode(0.5, SRGB), rel=1e-7)


def test_srgb_8_bit_decision_points_by_hand():
    # the first and last levels of the exact encode (docs/llvmpipe/output.md lists them)
    points = decision_points(SRGB, 8)
    assert points.shape == (255,) and points.dtype == np.float32
    assert points[0] == pytest.approx(0.5 / 255 / 12.92, rel=1e-6)       # on the linear segment
    assert points[-1] == pytest.approx(decode(254.5 / 255, SRGB), rel=1e-6)


def test_linear_8_bit_is_gl_unorm_conversion():
    # the framebuffer's rgba8 (gl_rules.to_unorm8) and the stage's linear 8-bit codes agree
    light = np.random.default_rng(3).random(200_000, dtype=np.float32)
    ties = (np.arange(256, dtype=np.float32) + np.float32(0.5)) / np.float32(255)
    light = np.concatenate([light, ties, np.nextafter(ties, np.float32(0))])
    codes = np.searchsorted(decision_points(LINEAR, 8), light, side="right")
    assert (codes == to_unorm8(light)).all()


@pytest.mark.parametrize("bits", [1, 3, 8, 12, 16])
@pytest.mark.parametrize("transfer", [LINEAR, SRGB, GAMMA], ids=str)
def test_decision_points_count_the_rule(transfer, bits):
    points = decision_points(transfer, bits)
    assert points.size == (1 << bits) - 1 and (np.diff(points) > 0).all()
    below = np.nextafter(points, np.float32(0))
    light = np.concatenate([points, below, np.random.default_rng(bits).random(20_000, dtype=np.float32)])
    assert (np.searchsorted(points, light, side="right") == code_of(light, transfer, bits)).all()
    assert (code_of(points, transfer, bits) == np.arange(1, points.size + 1)).all()   # smallest...
    assert (code_of(below, transfer, bits) == np.arange(points.size)).all()           # ...of each code


@pytest.mark.parametrize("transfer", [LINEAR, SRGB, GAMMA], ids=str)
def test_code_values_are_the_codes_light(transfer):
    values = code_values(transfer, 4)
    assert values[0] == 0 and values[-1] == 1 and (np.diff(values) > 0).all()
    assert np.allclose(encode(values, transfer) * 15, np.arange(16), atol=1e-5)
    assert not values.flags.writeable and not decision_points(transfer, 4).flags.writeable


def test_parse_options():
    assert parse_transfer("gamma:2.2") == GAMMA and parse_transfer("srgb") == SRGB
    assert parse_bits("16") == 16 and parse_halftone("6:15") == Halftone(6.0, 15.0)
    for parse, text in ((parse_transfer, "gamma:0"), (parse_transfer, "gamma:x"), (parse_transfer, "log"),
                        (parse_bits, "0"), (parse_bits, "17"), (parse_bits, "1.5"),
                        (parse_halftone, "1.5"), (parse_halftone, "6:nan"), (parse_halftone, "inf")):
        with pytest.raises(ValueError):
            parse(text)


@pytest.mark.parametrize("settings, reason", [
    (dict(bits=12, format="png8"), "at most 8 bits"),
    (dict(bits=8, format="exr"), "float colour"),
    (dict(dither="bayer4", format="npy"), "float colour"),
    (dict(halftone=Halftone(4.0), dither="bayer8"), "choose one"),
    (dict(halftone=Halftone(4.0), bits=4), "binary inks"),
    (dict(dither="bayer3"), "unknown"),
    (dict(format="tiff"), "unknown"),
])
def test_settings_that_cannot_go_together(settings, reason):
    with pytest.raises(ValueError, match=reason):
        OutputSettings(**settings)


def test_code_bits_and_defines():
    assert OutputSettings(format="png16").code_bits == 16
    assert OutputSettings(bits=3).code_bits == 3
    assert OutputSettings(halftone=Halftone(4.0)).code_bits == 1
    assert output_defines(OutputSettings(dither="bayer8")) == {"TRANSFER_LINEAR": "1", "DITHER_ORDERED": "8"}
    assert "FLOAT_OUTPUT" in output_defines(OutputSettings(transfer=SRGB, format="exr"))
