"""CIE colour (renderer/core/colour.py, reference/output/colour.py, glsl/output/colour.glsl):
hand-checked cases, then colour-science as the check on our conversions (to 1e-7 in float64),
then the GPU pass against both within float32 precision.

The float32 bound, for non-negative RGB (every term of M @ rgb is then >= 0, so a relative
bound on each product and sum is one on the result; u = 2^-24, the unit roundoff):
- XYZ: M rounded to float32 (u) and a three-term dot product (gamma_3 = 3u): 4u relative;
- x, y, z = X / (X + Y + Z): the sum of three values each within 4u, two additions (2u),
  then the division (u; 2u if a GL divides by a reciprocal and a multiply): 12u relative.
The twin's own float64 error (a few 2^-53) is far below either.
"""

import numpy as np
import pytest

from reference.output.colour import (chromaticity, colour_planes, luminance, rgb_to_xyz,
                                     xyz_to_rgb)
from renderer.core import quantise
from renderer.core.colour import (D65_CHROMATICITY, D65_XY, LUMINANCE_WEIGHTS, RGB_TO_XYZ,
                                  SRGB_PRIMARIES_XY, XYZ_TO_RGB)
from renderer.core.output_settings import Transfer

colour = pytest.importorskip("colour")

U = 2.0 ** -24                                   # float32's unit roundoff
XYZ_RELATIVE_BOUND = 4 * U
CHROMATICITY_RELATIVE_BOUND = 12 * U
FLOAT64_AGREEMENT = 1e-7                         # the bar for the float64 twin


def sample_colours():
    """4096 colours: random ones (also above 1: HDR light), the primaries, white, a dim grey
    and black."""
    rng = np.random.default_rng(18)
    special = np.array([[1, 0, 0], [0, 1, 0], [0, 0, 1], [1, 1, 1], [1e-6] * 3, [0, 0, 0]])
    return np.concatenate([rng.random((4096 - len(special), 3)) * 2.0, special]).astype(np.float32)


def derived_srgb():
    """colour-science's sRGB with the matrix derived from the primaries and D65 (its default
    is IEC's printed, rounded one)."""
    return colour.RGB_Colourspace("sRGB, derived matrix", np.array(SRGB_PRIMARIES_XY),
                                  np.array(D65_XY), use_derived_matrix_RGB_to_XYZ=True,
                                  use_derived_matrix_XYZ_to_RGB=True)


# -- hand-checked ------------------------------------------------------------------------------

def test_white_is_d65_at_unit_luminance_and_the_primaries_keep_their_chromaticity():
    white = rgb_to_xyz([1.0, 1.0, 1.0])
    np.testing.assert_allclose(white, [0.3127 / 0.3290, 1.0, 0.3583 / 0.3290], rtol=1e-15)
    for primary, xy in zip(np.eye(3), SRGB_PRIMARIES_XY):
        np.testing.assert_allclose(chromaticity(rgb_to_xyz(primary))[:2], xy, rtol=1e-14)
    np.testing.assert_allclose(xyz_to_rgb(rgb_to_xyz([0.2, 0.5, 0.9])), [0.2, 0.5, 0.9], atol=1e-15)


def test_luminance_weights_are_the_middle_row_rec709_to_four_places():
    assert LUMINANCE_WEIGHTS.tolist() == RGB_TO_XYZ[1].tolist()
    assert np.round(LUMINANCE_WEIGHTS, 4).tolist() == [0.2126, 0.7152, 0.0722]
    assert luminance([1.0, 1.0, 1.0]) == pytest.approx(1.0, abs=1e-15)
    assert luminance([0.0, 1.0, 0.0]) == LUMINANCE_WEIGHTS[1]


def test_black_has_the_white_points_chromaticity_and_x_y_z_add_to_one():
    assert chromaticity([0.0, 0.0, 0.0]).tolist() == D65_CHROMATICITY.tolist()
    xyz = chromaticity(rgb_to_xyz(sample_colours()))
    np.testing.assert_allclose(xyz.sum(axis=-1), 1.0, atol=1e-15)


def test_matrices_are_read_only():
    for matrix in (RGB_TO_XYZ, XYZ_TO_RGB, LUMINANCE_WEIGHTS, D65_CHROMATICITY):
        assert not matrix.flags.writeable


# -- colour-science ----------------------------------------------------------------------------

def test_our_matrix_is_colour_sciences_derived_one_and_iecs_printed_one_rounded():
    derived = colour.normalised_primary_matrix(np.array(SRGB_PRIMARIES_XY), np.array(D65_XY))
    np.testing.assert_allclose(RGB_TO_XYZ, derived, rtol=0, atol=FLOAT64_AGREEMENT)
    printed = colour.RGB_COLOURSPACES["sRGB"].matrix_RGB_to_XYZ     # IEC 61966-2-1's, 4 places
    assert np.round(RGB_TO_XYZ, 4).tolist() == printed.tolist()
    assert 1e-5 < np.abs(RGB_TO_XYZ - printed).max() < 5e-5         # so compare with the derived


def test_xyz_and_xy_match_colour_science():
    rgb = sample_colours().astype(np.float64)
    space = derived_srgb()
    expected_xyz = colour.RGB_to_XYZ(rgb, space)
    np.testing.assert_allclose(rgb_to_xyz(rgb), expected_xyz, rtol=0, atol=FLOAT64_AGREEMENT)
    np.testing.assert_allclose(xyz_to_rgb(expected_xyz), colour.XYZ_to_RGB(expected_xyz, space),
                               rtol=0, atol=FLOAT64_AGREEMENT)
    np.testing.assert_allclose(luminance(rgb), expected_xyz[:, 1], rtol=0, atol=FLOAT64_AGREEMENT)
    lit = rgb.sum(axis=1) > 0                          # colour-science gives black (0, 0)
    np.testing.assert_allclose(chromaticity(expected_xyz)[lit, :2],
                               colour.XYZ_to_xy(expected_xyz[lit]), rtol=0, atol=FLOAT64_AGREEMENT)


def test_srgb_transfer_matches_colour_science():
    light = np.concatenate([np.linspace(0, 1, 100_001), np.linspace(0, 0.0031308 * 2, 1001)])
    srgb = Transfer("srgb")
    np.testing.assert_allclose(quantise.encode(light, srgb),
                               colour.models.eotf_inverse_sRGB(light), rtol=0, atol=FLOAT64_AGREEMENT)
    value = np.linspace(0, 1, 100_001)
    np.testing.assert_allclose(quantise.decode(value, srgb), colour.models.eotf_sRGB(value),
                               rtol=0, atol=FLOAT64_AGREEMENT)


# -- the GPU pass (glsl/output/colour.comp) ----------------------------------------------------

@pytest.fixture(scope="module")
def colour_passes(gl_contexts):
    from renderer.gpu.colour import ColourPass
    passes = {kind: ColourPass(ctx) for kind, ctx in gl_contexts.items()}
    yield passes
    for colour_pass in passes.values():
        colour_pass.release()


def within(gpu, exact, relative):
    """The largest error of `gpu` over `exact`, in units of `relative` times |exact|."""
    error = np.abs(gpu.astype(np.float64) - exact)
    return float(np.max(error / (relative * np.maximum(np.abs(exact), np.finfo(np.float32).tiny))))


@pytest.mark.parametrize("kind", ("egl", "osmesa"))
def test_gpu_pass_is_within_float32_precision_of_the_twin_and_colour_science(colour_passes, kind):
    rgb = sample_colours()
    lit = rgb.sum(axis=1) > 0
    linear = np.concatenate([rgb, np.full((len(rgb), 1), 0.5, np.float32)], axis=1)
    linear = linear.reshape(-1, 64, 4)                        # the cases as an image, 64 wide
    xyz, xy = colour_passes[kind].apply(linear)
    twin_xyz, twin_xy = colour_planes(linear)
    assert xyz.dtype == xy.dtype == np.float32
    assert (xyz[..., 3] == 0.5).all()                         # alpha kept
    assert within(xyz[..., :3], twin_xyz[..., :3], XYZ_RELATIVE_BOUND) <= 1
    assert within(xy, twin_xy, CHROMATICITY_RELATIVE_BOUND) <= 1
    expected = colour.RGB_to_XYZ(rgb.astype(np.float64), derived_srgb())
    assert within(xyz[..., :3].reshape(-1, 3), expected, XYZ_RELATIVE_BOUND) <= 1
    assert within(xy.reshape(-1, 3)[lit, :2], colour.XYZ_to_xy(expected[lit]),
                  CHROMATICITY_RELATIVE_BOUND) <= 1
    assert xy.reshape(-1, 3)[~lit].tolist() == [D65_CHROMATICITY.astype(np.float32).tolist()]


def test_gpu_pass_keeps_rows_as_given_and_any_size(colour_passes):
    linear = np.zeros((5, 9, 4), np.float32)                  # not a multiple of the 8x8 groups
    linear[0, 8] = (1.0, 0.0, 0.0, 1.0)                       # top row, last column: red
    xyz, xy = colour_passes["egl"].apply(linear)
    np.testing.assert_allclose(xy[0, 8, :2], SRGB_PRIMARIES_XY[0], rtol=CHROMATICITY_RELATIVE_BOUND)
    assert (xyz[1:, :, :3] == 0).all() and (xyz[0, :8, :3] == 0).all()
