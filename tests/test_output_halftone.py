"""Half-toning (renderer/core/halftone_screen.py; reference/output/halftone.py and
glsl/output/halftone.glsl): the diamond dot by hand and its area law, the screens' geometry,
the dots nested as the ink grows, grey-component replacement, and GPU against twin bit for bit.

The area law on the pixel grid (a flat coverage a inks a fraction ~a of a big area): a screen
turned off the pixel grid samples its cells everywhere, and a 256 x 256 field comes within
AREA_BOUND of a at every level k/64 (measured: 0.0002 at 15 and 75 degrees, 0.005 at 45,
cell 6). A screen on the grid (0 or 90 degrees, a whole number of pixels a cell) samples
each cell at the same cell^2 points, many of them on one diamond (|fu| + |fv| equal), so the
fraction moves in steps: exactly the share of one cell's samples with S < a (cell 8: 7 steps,
4, 12, 24, 40, 52, 60, 64 of 64, so a flat field can be off by 0.125; cell 6: 5 steps, off by
up to 0.156, the ties split only by float32's rounding of 1/6). Mean light on rendered
scenes: tests/test_output_mean_light.py.
"""

import numpy as np
import pytest

import reference.output
from renderer.core.halftone_screen import INKS, screen_basis
from renderer.core.output_settings import INK_ANGLES, Halftone, OutputSettings
from reference.output.halftone import inks, spot_threshold
from output_cases import linear_frame

LEVELS = np.arange(1, 64, dtype=np.float32) / np.float32(64)
AREA_BOUND = {"off the grid": 0.001, "45 degrees": 0.01}


def thresholds(halftone: Halftone, ink: str, width: int, height: int) -> np.ndarray:
    """(height, width) float32: the spot threshold of `ink`'s screen at every pixel."""
    cs, sn = screen_basis(halftone)[INKS.index(ink)]
    px = np.arange(width, dtype=np.float32)[None, :] + np.float32(0.5)
    py = np.arange(height, dtype=np.float32)[:, None] + np.float32(0.5)
    return spot_threshold(px, py, cs, sn)


def one_ink(ink: str, coverage, size: int) -> np.ndarray:
    """(size, size, 3) float32 linear colour that asks for `coverage` of `ink` alone: 1 - a in
    the channel it absorbs (C: R, M: G, Y: B), or grey 1 - a for black."""
    rgb = np.ones((size, size, 3), np.float32)
    channels = slice(None) if ink == "k" else INKS.index(ink)
    rgb[..., channels] = np.float32(1) - np.float32(coverage)
    return rgb


def test_the_diamond_dot_by_hand():
    # cell 4 at angle 0 (yellow's screen: INK_ANGLES["y"] = 0): cs = 1/4, sn = 0, so pixel
    # (x, y) sits at u = (x + 1/2)/4, v = (y + 1/2)/4 in its cell; fu, fv in {-3/8, -1/8,
    # 1/8, 3/8}; t = |fu| + |fv| is 1/4 at the 4 centre pixels (S = 2 t^2 = 1/8), 1/2 along the
    # edges' middles (S = 1/2), 3/4 at the corners (S = 1 - 2 (1/4)^2 = 7/8)
    assert INK_ANGLES["y"] == 0
    np.testing.assert_array_equal(screen_basis(Halftone(4, 0))[INKS.index("y")], [0.25, 0.0])
    cell = [[0.875, 0.5, 0.5, 0.875],
            [0.5, 0.125, 0.125, 0.5],
            [0.5, 0.125, 0.125, 0.5],
            [0.875, 0.5, 0.5, 0.875]]
    np.testing.assert_array_equal(thresholds(Halftone(4, 0), "y", 8, 4), np.tile(cell, (1, 2)))
    # so yellow at coverage 0.3 prints the 4 centre pixels of each cell: B = 0 there
    codes = reference.output.apply(np.concatenate([one_ink("y", 0.3, 8)[:4], np.ones((4, 8, 1), np.float32)], -1),
                                   OutputSettings(halftone=Halftone(4, 0)))
    np.testing.assert_array_equal(codes[..., 2], np.tile(np.array(cell) >= 0.3, (1, 2)))
    assert (codes[..., :2] == 1).all() and (codes[..., 3] == 1).all()


def test_the_diamond_covers_its_coverage_of_the_cell():
    # the closed-form area law, on a fine grid over one cell (1000 x 1000 points): {S < a}
    # has area a, the dot grows from the cell's centre and meets its neighbours at a = 1/2
    points = (np.arange(1000, dtype=np.float32) + np.float32(0.5)) / np.float32(1000)
    spot = spot_threshold(points[None, :], points[:, None], np.float32(1), np.float32(0))
    covered = (spot[None] < LEVELS[:, None, None]).mean(axis=(1, 2))
    np.testing.assert_allclose(covered, LEVELS, atol=0.004)    # the grid's points on the edge
    assert spot[500, 500] < 1e-5 and spot[0, 0] > 0.99        # centre first, corners last
    # at coverage 1/2 the dot reaches the middle of each edge: it meets its neighbours
    assert spot[500].max() <= 0.5 and spot[:, 500].max() <= 0.5


@pytest.mark.parametrize("cell", (8, 6))
@pytest.mark.parametrize("angle, ink", ((0, "y"), (-45, "k"), (-15, "c"), (15, "m")))
def test_a_screen_of_angle_0_is_axis_aligned_cells_of_the_given_size(angle, ink, cell):
    # ink angle 0 (m: 75 + 15 = 90, the same grid turned a quarter): S repeats every `cell`
    # pixels along x and along y, lowest at each cell's centre, and is symmetric in it;
    # exactly for cell 8 (1/8 is exact), within float32's rounding of 1/6 for cell 6
    spot = thresholds(Halftone(cell, angle), ink, 4 * cell, 3 * cell)
    same = np.testing.assert_array_equal if cell == 8 else \
        lambda a, b: np.testing.assert_allclose(a, b, rtol=0, atol=1e-6)
    same(spot[:, cell:], spot[:, :-cell])
    same(spot[cell:], spot[:-cell])
    one = spot[:cell, :cell]
    same(one, one[::-1])
    same(one, one[:, ::-1])
    middle = slice(cell // 2 - 1, cell // 2 + 1)
    assert one[middle, middle].max() - one.min() <= 1e-6 < one.max() - one[middle, middle].max()
    # and a turned screen does not repeat along the pixel grid
    turned = thresholds(Halftone(cell, angle + 15), ink, 4 * cell, 3 * cell)
    assert not np.array_equal(turned[:, cell:], turned[:, :-cell])


@pytest.mark.parametrize("ink, law", (("c", "off the grid"), ("m", "off the grid"),
                                      ("k", "45 degrees")))
def test_a_flat_field_inks_its_coverage_of_a_big_area(ink, law):
    size = 256
    for level in LEVELS[::4]:
        printed = inks(one_ink(ink, level, size), Halftone(6, 0))[ink]
        assert abs(printed.mean() - level) <= AREA_BOUND[law], level


def test_on_the_pixel_grid_the_fraction_is_a_cells_samples_below_the_level():
    cell, size = 8, 128                               # 16 whole cells a side
    one_cell = thresholds(Halftone(cell, 0), "y", cell, cell)
    steps = np.float32([1, 4, 9, 16, 23, 28, 31]) / np.float32(32)      # t = 1/8 .. 7/8
    np.testing.assert_array_equal(np.unique(one_cell), steps)
    np.testing.assert_array_equal([(one_cell <= s).sum() for s in steps], [4, 12, 24, 40, 52, 60, 64])
    for level in LEVELS:
        printed = inks(one_ink("y", level, size), Halftone(cell, 0))["y"]
        assert printed.mean() == (one_cell < level).mean(), level


@pytest.mark.parametrize("ink", INKS)
def test_the_dot_grows_with_darkness(ink):
    # nested: every pixel an ink covers at one coverage it covers at every higher one
    halftone = Halftone(7.5, 10)
    before = np.zeros((48, 48), bool)
    for level in np.linspace(0, 1, 101, dtype=np.float32):
        printed = inks(one_ink(ink, level, 48), halftone)[ink]
        assert (printed >= before).all(), level
        before = printed
    assert before.all()


def test_grey_is_printed_in_black_alone():
    # grey-component replacement: c = m = y = k, so c - k = 0 prints no colour ink
    rng = np.random.default_rng(1)
    grey = np.repeat(rng.random((32, 32, 1), dtype=np.float32), 3, axis=-1)
    printed = inks(grey, Halftone(5, 20))
    assert not (printed["c"] | printed["m"] | printed["y"]).any() and printed["k"].any()
    # and a colour with one channel at 1 has no black: k = min(c, m, y) = 0
    colour = np.concatenate([np.ones((32, 32, 1), np.float32), grey[..., :2] * np.float32(0.5)], -1)
    printed = inks(colour, Halftone(5, 20))
    assert not (printed["k"] | printed["c"]).any() and printed["m"].any() and printed["y"].any()


def test_an_ink_where_the_screens_overlap_keeps_the_light_on_average():
    # (1 - c')(1 - k) = 1 - c where the screens of C and K are independent: they nearly are
    # (15 and 45 degrees), so a flat field's red shows nearly the light asked for
    rgb = np.broadcast_to(np.float32([0.3, 0.6, 0.8]), (256, 256, 3))
    printed = inks(np.ascontiguousarray(rgb), Halftone(6, 0))
    red = (~(printed["c"] | printed["k"])).mean()
    assert abs(red - 0.3) < 0.01


@pytest.mark.parametrize("kind", ("egl", "osmesa"))
def test_the_gpu_screens_are_the_twins(output_passes, kind):
    frame = linear_frame(width=41, height=29)
    rows, columns = np.mgrid[0:29, 0:41].astype(np.float32)
    ramp = np.stack([columns / 41, rows / 29, (columns + rows) / 70, np.ones_like(rows)], -1)
    for halftone in (Halftone(2, 0), Halftone(6, 0), Halftone(7.5, 22.5), Halftone(13.3, -37)):
        settings = OutputSettings(halftone=halftone)
        for linear in (frame, ramp.astype(np.float32)):
            np.testing.assert_array_equal(output_passes[kind].apply(linear, settings),
                                          reference.output.apply(linear, settings),
                                          err_msg=str(halftone))
