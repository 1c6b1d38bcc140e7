"""reference/sampler.py (and texels.py, anisotropic.py): llvmpipe's texture sampling, a
hand-checked case per rule. That llvmpipe does exactly this is tests/test_sampler_gl.py's job.

Texel values in these cases are chosen so that the answer can be worked out on paper: a
texture whose texel (i, j) (j from the bottom) holds a value naming it, and a weight read
straight off a black-to-white pair.
"""

import numpy as np
import pytest

from reference.anisotropic import anisotropic_level
from reference.sampler import QuadDerivatives, quad_reference, sample, select_levels
from reference.texels import fma32, lerp8
from renderer.core.gl_rules import (anisotropic_weight_table, fast_log2, round_log2_sqrt,
                                    unorm8_to_float)
from renderer.core.textures import Sampler, Texture, level_sizes

f32 = np.float32


def indexed(width, height):
    """A one-level texture whose texel (i, j), j from the bottom, has red = i and green = j."""
    rows = np.zeros((height, width, 4), np.uint8)
    rows[..., 0] = np.arange(width)[None, :]
    rows[..., 1] = np.arange(height)[::-1, None]              # row 0 of the array is the top
    return Texture((rows,), f"indexed {width}x{height}", "linear")


def texel_of(texture, sampler, u, v=0.5):
    """(i, j) of the texel the nearest filter reads at each u (and v)."""
    u = np.atleast_1d(np.asarray(u, dtype=f32))
    rgba = sample(texture, sampler, u, np.full(u.shape, v, dtype=f32))
    ij = np.rint(rgba[:, :2] * 255).astype(int)
    return [tuple(p) for p in ij]


def columns(texture, sampler, u):
    return [i for i, _ in texel_of(texture, sampler, u)]


def two_texels(left, right):
    """A 2 x 1 texture: left and right grey levels (RGB), alpha 255."""
    row = np.array([[[left] * 3 + [255], [right] * 3 + [255]]], np.uint8)
    return Texture((row, row[:, :1]), f"{left}|{right}", "linear")


ULP_BELOW_ONE = float(np.nextafter(f32(1), f32(0)))


# --- wrap modes at and past the edges (nearest: which texel) -------------------------------

def test_repeat_wraps_a_power_of_two_width_by_masking_floor_u_w():
    tex = indexed(4, 1)
    nearest = Sampler("repeat", "nearest")
    # u W = 0, 3.99999976, 4, -4e-7 -> floor 0, 3, 4, -1 -> & 3
    assert columns(tex, nearest, [0.0, ULP_BELOW_ONE, 1.0, -1e-7, 2.3]) == [0, 3, 0, 3, 1]


def test_repeat_of_an_npot_width_takes_the_fraction_below_one_first():
    """-1e-9 - floor(-1e-9) rounds to 1.0 in float32; the fraction is held below 1, so the
    last texel, not texel 5 (out of range) or texel 0."""
    tex = indexed(5, 1)
    assert columns(tex, Sampler("repeat", "nearest"), [-1e-9, 0.2, 1.99, -0.1]) == [4, 1, 4, 4]


def test_clamp_to_edge_holds_the_edge_texels_past_the_edges():
    tex = indexed(4, 1)
    assert columns(tex, Sampler("clamp", "nearest"), [-5.0, -1e-7, 0.0, 0.9999, 1.0, 7.0]) == [0, 0, 0, 3, 3, 3]


def test_mirrored_repeat_folds_every_other_period_backwards():
    """u in [1, 2) reads the texture right to left: 1.1 -> 0.9 -> texel 3; -0.1 -> 0.1 ->
    texel 0; 2.1 -> 0.1; 1.0 itself folds to 1.0 (s/2 = 0.5 rounds to even 0), the last texel."""
    tex = indexed(4, 1)
    assert columns(tex, Sampler("mirror", "nearest"), [0.1, 1.1, -0.1, 2.1, 1.0, -1.0]) == [0, 3, 0, 0, 3, 3]


def test_the_row_counts_from_the_bottom_of_the_image():
    tex = indexed(1, 4)
    got = texel_of(tex, Sampler("clamp", "nearest"), [0.5, 0.5], v=0.1)
    assert got == [(0, 0), (0, 0)]                              # v = 0.1: the bottom row, j = 0
    assert texel_of(tex, Sampler("clamp", "nearest"), [0.5], v=0.9) == [(0, 3)]


# --- bilinear: 8-bit weights, x then y ------------------------------------------------------

def test_lerp8_is_a_rounded_shift_that_never_reaches_the_far_end():
    a, b = np.array([0, 0, 0, 0, 200]), np.array([255, 255, 255, 255, 100])
    assert lerp8(np.array([0, 1, 128, 255, 128]), a, b).tolist() == [0, 1, 128, 254, 150]


def test_bilinear_weights_on_a_2x2_texture():
    """Texels (grey) 0 and 255 on the bottom row, 100 and 200 on the top, clamp. At
    u = v = 1/2 both weights are 128/256: bottom lerp8(128, 0, 255) = 128, top 150, then
    lerp8(128, 128, 150) = 139. At the texel centres (1/4, 3/4) a texel itself. At
    u = 1/4 + 1/512 the x weight is 1/256... of 255: 1."""
    image = np.zeros((2, 2, 4), np.uint8)
    image[1, :, :3] = np.array([0, 255])[:, None]                # bottom row (array row 1)
    image[0, :, :3] = np.array([100, 200])[:, None]              # top row
    image[..., 3] = 255
    tex = Texture((image, image[:1, :1]), "2x2", "linear")
    bilinear = Sampler("clamp", "bilinear")
    u = np.array([0.5, 0.25, 0.75, 0.25, 0.75, 0.25 + 1 / 512], f32)
    v = np.array([0.5, 0.25, 0.25, 0.75, 0.75, 0.25], f32)
    grey = np.rint(sample(tex, bilinear, u, v)[:, 0] * 255).astype(int)
    assert grey.tolist() == [139, 0, 255, 100, 200, 1]


def test_bilinear_coordinates_round_to_the_nearest_256th_of_a_texel_ties_to_even():
    """Texels 0 and 255: u W 256 - 128 is the weight. u = 1/4 + 2.5/512 (W = 2: 2.5 /256
    past texel 0's centre) rounds to 2 (ties to even); + 3.5/512 to 4."""
    tex = two_texels(0, 255)
    u = np.array([0.25 + 2.5 / 512, 0.25 + 3.5 / 512], f32)
    got = sample(tex, Sampler("clamp", "bilinear"), u, np.full(2, 0.5, f32))[:, 0]
    assert (got == unorm8_to_float(lerp8(np.array([2, 4]), 0, 255))).all()


def test_repeat_beyond_int32_reads_the_last_and_first_texels_half_and_half():
    """u W 256 >= 2^31 gives llvmpipe's rounding INT32_MIN, and INT32_MIN - 128 wraps to
    0x7FFFFF80: i0 = W - 1, i1 = 0, weight 128, whatever u is. W = 16, u = +-1e6:
    1e6 16 256 = 4.1e9. Texels 0..15 hold 0, 17, ..., 255: lerp8(128, 255, 0) =
    255 + floor(-32512 / 256) = 128."""
    row = np.zeros((1, 16, 4), np.uint8)
    row[0, :, 0] = np.arange(16) * 17
    tex = Texture((row,), "ramp", "linear")
    got = sample(tex, Sampler("repeat", "bilinear"), np.array([1e6, -1e6, 1000.0], f32),
                 np.full(3, 0.5, f32))[:, 0]
    # 1000.0: 1000 16 256 = 4096000, in range: u = 1000 is texel 0's left edge, between 15 and 0
    assert np.rint(got * 255).astype(int).tolist() == [128, 128, 128]
    got = sample(tex, Sampler("repeat", "bilinear"), np.array([1000.0 + 1 / 32], f32), np.full(1, 0.5, f32))
    assert np.rint(got[0, 0] * 255) == 0                          # texel 0's centre: exact


def test_the_float_path_mirror_weights_are_float32_not_256ths():
    """Mirrored repeat takes llvmpipe's float path: weight = float32(u W - 1/2), blended by
    one fma. Texels 0 and 255 (as 0.0 and 1.0), u = 0.4: weight 0.3 as float32 exactly."""
    tex = two_texels(0, 255)
    got = sample(tex, Sampler("mirror", "bilinear"), np.array([0.4], f32), np.array([0.5], f32))
    assert got[0, 0] == f32(f32(f32(0.4) * f32(2)) - f32(0.5))
    fixed = sample(tex, Sampler("repeat", "bilinear"), np.array([0.4], f32), np.array([0.5], f32))
    assert fixed[0, 0] == unorm8_to_float(77)                      # round(0.3 256) = 77: 77/255


def test_fma32_rounds_once():
    """c = 1 + 2^-23 and a b = 2^-24 - 2^-70: the exact sum lies just below the midpoint
    between c and the next float32; float64 rounds it onto the midpoint, which a second
    rounding would send up (to even). One rounding keeps c."""
    a, b, c = f32(1 + 2.0 ** -23), f32(2.0 ** -24 - 2.0 ** -47), f32(1 + 2.0 ** -23)
    assert (a.astype(np.float64) * b + c).astype(f32) == np.nextafter(c, f32(2))   # twice rounded
    assert fma32(a, b, c) == c


def test_texels_become_floats_by_one_float32_product_with_1_over_255():
    """3 x float32(1/255) = 0.011764707..., one ulp above the float32 nearest 3/255; 126 of
    the 256 values are so off. 0 and 255 are exact."""
    c = np.arange(256)
    assert unorm8_to_float(3) == f32(0.011764707) != f32(3 / 255) == f32(0.011764706)
    assert (unorm8_to_float(c) != (c / 255).astype(f32)).sum() == 126
    assert unorm8_to_float(np.array([0, 255])).tolist() == [0.0, 1.0]


# --- the level of detail -------------------------------------------------------------------

def test_the_lod_differences_each_quad_from_its_bottom_left_pixel():
    (x0, y0), (x1, y_), (x_, y1) = quad_reference(np.array([5, 4, 0]), np.array([2, 3, 7]))
    assert x0.tolist() == [4.5, 4.5, 0.5] and y0.tolist() == [2.5, 2.5, 6.5]
    assert x1.tolist() == [5.5, 5.5, 1.5] and y1.tolist() == [3.5, 3.5, 7.5]
    assert (y_ == y0).all() and (x_ == x0).all()
    d = QuadDerivatives.from_reference([[0.25], [0.375], [0.5]], [[1.0], [1.5], [0.0]])
    assert (d.dudx[0], d.dudy[0], d.dvdx[0], d.dvdy[0]) == (0.125, 0.25, 0.5, -1.0)


def test_fast_log2_is_piecewise_linear_between_powers_of_two():
    x = np.array([1, 2, 3, 0.75, 9, 1024], f32)
    assert fast_log2(x).tolist() == [0.0, 1.0, 1.5, -0.5, 3.125, 10.0]
    assert round_log2_sqrt(np.array([1, 1.99, 2, 7.9, 8, 0, np.inf], f32)).tolist() == [0, 0, 1, 1, 2, -63, 64]


def mipmapped(size=64, values=None):
    """A square texture whose level k is filled with grey values[k] (default 40 k)."""
    levels = tuple(np.full((h, w, 4), (values or [40 * k for k in range(8)])[k], np.uint8)
                   for k, (w, h) in enumerate(level_sizes(size, size)))
    return Texture(levels, "levels", "linear")


def derivatives(dudx=0.0, dudy=0.0, dvdx=0.0, dvdy=0.0, n=1):
    return QuadDerivatives(*(np.full(n, d, f32) for d in (dudx, dudy, dvdx, dvdy)))


def test_lod_of_three_texels_per_pixel():
    """64 x 64, du/dx = 3/64: rho^2 = 9 = 1.125 2^3. Trilinear: 0.5 fast_log2(9) = 1.5625
    (log2 3 = 1.585), levels 1 and 2, weight trunc(0.5625 256) = 144; between level 1 (0)
    and level 2 (255): lerp8(144, 0, 255) = 143. Mip-nearest: round(log2 3) = 2."""
    tex = mipmapped(values=[9, 0, 255, 9, 9, 9, 9])
    d = derivatives(dudx=3 / 64)
    level0, level1, fraction = select_levels(tex, Sampler("repeat", "trilinear"), derivatives=d)
    assert (level0[0], level1[0], fraction[0]) == (1, 2, 0.5625)
    got = sample(tex, Sampler("repeat", "trilinear"), [0.3], [0.6], derivatives=d)
    assert got[0, 0] == unorm8_to_float(143)
    level, _, _ = select_levels(tex, Sampler("repeat", "mip-nearest"), derivatives=d)
    assert level[0] == 2


def test_lod_takes_the_larger_of_the_two_directions_and_rounds_half_up_for_mip_nearest():
    """dv/dy = sqrt(2)/64-ish is not exact; rho^2 = 2 exactly comes from du/dx = dv/dx =
    1/64: log2 rho = 1/2, rounded up to level 1 (a ties-to-even rounding would give 0)."""
    tex = mipmapped()
    mip_nearest = Sampler("clamp", "mip-nearest")
    d = derivatives(dudx=1 / 64, dvdx=1 / 64, dvdy=0.5 / 64)
    assert select_levels(tex, mip_nearest, derivatives=d)[0][0] == 1
    d = derivatives(dudx=0.5 / 64, dvdy=4 / 64)                   # y is the larger: level 2
    assert select_levels(tex, mip_nearest, derivatives=d)[0][0] == 2


def test_lod_clamps_to_the_base_and_last_levels():
    tex = mipmapped(64)                                          # levels 0..6
    trilinear = Sampler("repeat", "trilinear")
    small, huge = derivatives(dudx=0.1 / 64), derivatives(dudx=1000 / 64)
    assert [int(a[0]) for a in select_levels(tex, trilinear, derivatives=small)] == [0, 0, 0]
    assert [int(a[0]) for a in select_levels(tex, trilinear, derivatives=huge)] == [6, 6, 0]


def test_an_explicit_lod_rounds_to_even_or_splits_into_floor_and_fraction():
    tex = mipmapped(64)
    lod = np.array([0.5, 1.5, 2.25, -1.0, 9.0], f32)
    level, _, _ = select_levels(tex, Sampler("repeat", "mip-nearest"), lod=lod)
    assert level.tolist() == [0, 2, 2, 0, 6]
    level0, level1, fraction = select_levels(tex, Sampler("repeat", "trilinear"), lod=lod)
    assert level0.tolist() == [0, 1, 2, 0, 6] and level1.tolist() == [1, 2, 3, 0, 6]
    assert fraction.tolist() == [0.5, 0.5, 0.25, 0.0, 0.0]


def test_non_mipmapped_filters_read_the_base_level_whatever_the_lod():
    tex = mipmapped(64)
    got = sample(tex, Sampler("repeat", "bilinear"), [0.5], [0.5], lod=3.0)
    assert got[0, 0] == 0.0                                      # level 0 is grey 0


def test_a_mipmapped_sampler_needs_exactly_one_of_derivatives_and_lod():
    tex = mipmapped(64)
    with pytest.raises(ValueError, match="exactly one"):
        sample(tex, Sampler("repeat", "trilinear"), [0.5], [0.5])
    with pytest.raises(ValueError, match="exactly one"):
        sample(tex, Sampler("repeat", "trilinear"), [0.5], [0.5], lod=0.0, derivatives=derivatives())


# --- anisotropic -----------------------------------------------------------------------------

def test_anisotropic_level_comes_from_the_minor_axis_truncated():
    """16 texels per pixel along x, 3 along y: trilinear reads level 4; llvmpipe's EWA reads
    level trunc(0.5 fast_log2(3^2)) = trunc(1.5625) = 1 (log2 3 = 1.58 would round to 2),
    whatever the anisotropy."""
    tex = mipmapped(64)
    d = derivatives(dudx=16 / 64, dvdy=3 / 64)
    assert anisotropic_level(tex, d)[0] == 1
    assert select_levels(tex, Sampler("repeat", "trilinear"), derivatives=d)[0][0] == 4


def test_the_ewa_weight_table_is_mesas():
    table = anisotropic_weight_table()
    assert len(table) == 1024 and table.dtype == f32
    # entries of Mesa's aniso_filter_table (lp_bld_sample.c), as written there
    assert table[[0, 1, 2, 512, 1021, 1023]].tolist() == [f32(x) for x in
                                                         (1.0, 0.998047, 0.996098, 0.367520, 0.135865, 0.135335)]


def test_the_ewa_of_one_colour_is_that_colour():
    """A constant texture: every texel in the ellipse is 0.6 (153/255) and the weights
    cancel, up to float32 roundings of the weighted sum (a few ulps)."""
    levels = tuple(np.full((h, w, 4), 153, np.uint8) for w, h in level_sizes(16, 16))
    tex = Texture(levels, "grey", "linear")
    d = derivatives(dudx=6 / 16, dvdy=1 / 16, dudy=0.5 / 16, n=3)
    got = sample(tex, Sampler("repeat", "anisotropic", 16), [0.1, 0.5, 0.9], [0.2, 0.7, 0.4], derivatives=d)
    assert np.allclose(got, unorm8_to_float(153), rtol=1e-6, atol=0)


def test_anisotropic_textureLod_takes_one_lod_for_all_fragments():
    tex = mipmapped(16)
    aniso = Sampler("repeat", "anisotropic", 4)
    d = derivatives(dudx=2 / 16, n=2)
    assert sample(tex, aniso, [0.3, 0.6], [0.5, 0.5], derivatives=d, lod=2.0).shape == (2, 4)
    with pytest.raises(ValueError, match="one lod"):
        sample(tex, aniso, [0.3, 0.6], [0.5, 0.5], derivatives=d, lod=[1.0, 2.0])
