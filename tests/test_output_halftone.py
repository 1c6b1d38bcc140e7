"""Half-toning (renderer/core/halftone_screen.py; reference/output/halftone.py and
glsl/output/halftone.glsl): the diamond dot by hand and its area law, the screens' geometry,
the threshold arrays of screens on the pixel grid by hand and their levels, the dots nested
as the ink grows, grey-component replacement, and GPU against twin bit for bit.

The area law on the pixel grid (a flat coverage a inks a fraction ~a of a big area): a screen
turned off the pixel grid samples its cells everywhere, and a 256 x 256 field comes within
AREA_BOUND of a at every level k/64 (measured: 0.0002 at 15 and 75 degrees, 0.005 at 45,
cell 6). A screen on the grid (a multiple of 90 degrees, a whole number of pixels a cell)
samples each cell at the same cell^2 points, many of them on one diamond (|fu| + |fv|
equal): thresholding S there moved the fraction in a few steps (cell 8: 7, 4 12 24 40 52 60
64 of 64, a flat field off by up to 0.125; cell 6 by 0.156). Such a screen is a threshold
array (the samples ranked, T = (rank + 1/2) / cell^2), so a coverage k / cell^2 inks exactly
k samples of every cell, and any coverage a within 1/(2 cell^2). Mean light on rendered
scenes: tests/test_output_mean_light.py.
"""

import numpy as np
import pytest

import reference.output
from renderer.core.halftone_screen import INKS, MAX_GRID_CELL, cell_ranks, grid_turns, screen_basis
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


def one_ink(ink: str, coverage, size: int | None = None) -> np.ndarray:
    """(size, size, 3) float32 linear colour that asks for `coverage` (a number, or an
    (H, W) array when size is None) of `ink` alone: 1 - a in the channel it absorbs (C: R,
    M: G, Y: B), or grey 1 - a for black."""
    coverage = np.broadcast_to(np.float32(coverage), (size, size) if size else np.shape(coverage))
    rgb = np.ones((*coverage.shape, 3), np.float32)
    channels = slice(None) if ink == "k" else [INKS.index(ink)]
    rgb[..., channels] = (np.float32(1) - coverage)[..., None]
    return rgb


def on_the_grid(ink: str, cell: int, turns: int = 0) -> Halftone:
    """The half-tone whose `ink` screen lies on the pixel grid, turned `turns` quarter turns."""
    halftone = Halftone(cell, 90 * turns - INK_ANGLES[ink])
    assert grid_turns(halftone) == tuple(turns if other == ink else None for other in INKS)
    return halftone


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
    # 16 samples, 3 values: on the pixel grid the screen is its threshold array instead (below)


def test_a_screen_on_the_pixel_grid_is_a_threshold_array_by_hand():
    # cell 4, yellow at 0 degrees: samples (a, b) = 8 (fu, fv) in {-3, -1, 1, 3}^2, pixel
    # x = (a + 3)/2, y = (b + 3)/2. Ranked by the diamond |a| + |b|: 2 (the 4 centre pixels),
    # 4 (8 on the edges), 6 (4 corners); ties as _ORBIT: (1, 1), its opposite (-1, -1), a
    # quarter turn on (-1, 1), its opposite (1, -1): ranks 0-3; the edges one orbit of (3, 1):
    # (3, 1) (-3, -1) (-1, 3) (1, -3) (1, 3) (-1, -3) (-3, 1) (3, -1): 4-11; corners 12-15
    ranks = [[13, 9, 7, 15],
             [5, 1, 3, 11],
             [10, 2, 0, 4],
             [14, 6, 8, 12]]
    np.testing.assert_array_equal(cell_ranks(4), ranks)
    # T = (rank + 1/2) / 16: yellow at coverage 0.3 prints ranks 0-4 (0.3 * 16 = 4.8) of
    # every cell: B = 0 there
    codes = reference.output.apply(np.concatenate([one_ink("y", 0.3, 8)[:4], np.ones((4, 8, 1), np.float32)], -1),
                                   OutputSettings(halftone=Halftone(4, 0)))
    np.testing.assert_array_equal(codes[..., 2], np.tile(np.array(ranks) > 4, (1, 2)))
    assert (codes[..., :2] == 1).all() and (codes[..., 3] == 1).all()
    # a quarter turn turns the array: (a, b) = (B, -A) of the pixel's (A, B) at 0 degrees
    np.testing.assert_array_equal(cell_ranks(4, 1), np.rot90(ranks, -1))


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


def test_on_the_pixel_grid_the_diamond_ties_and_the_ranks_do_not():
    # why a threshold array: cell 8's 64 samples of S take 7 values (t = 1/8 .. 7/8), so
    # thresholding S would ink 4, 12, 24, 40, 52, 60 or 64 samples of a cell and nothing between
    one_cell = thresholds(Halftone(8, 0), "y", 8, 8)
    steps = np.float32([1, 4, 9, 16, 23, 28, 31]) / np.float32(32)
    np.testing.assert_array_equal(np.unique(one_cell), steps)
    np.testing.assert_array_equal([(one_cell <= s).sum() for s in steps], [4, 12, 24, 40, 52, 60, 64])
    # every sample of every whole-pixel cell has its own rank, in the diamond's order
    # (centre first), at every quarter turn
    for cell in range(2, 33):
        offset = np.abs(2 * np.arange(cell) + 1 - cell)
        diamond = (offset[None, :] + offset[:, None]).ravel()
        for turns in range(4):
            ranks = cell_ranks(cell, turns).ravel()
            np.testing.assert_array_equal(np.sort(ranks), np.arange(cell * cell))
            assert (np.diff(diamond[np.argsort(ranks)]) >= 0).all(), (cell, turns)


@pytest.mark.parametrize("ink", INKS)
def test_on_the_pixel_grid_a_coverage_of_k_samples_inks_k_samples_of_every_cell(ink):
    # cells 2 to 16 at every quarter turn in turn: side by side a flat field at each
    # k / cell^2 (k = 0 .. cell^2), two cells tall; each cell inks exactly k samples, its
    # ranks 0 .. k - 1
    for cell in range(2, 17):
        turns = cell % 4
        levels = np.arange(cell * cell + 1, dtype=np.float32) / np.float32(cell * cell)
        coverage = np.repeat(np.broadcast_to(levels, (2 * cell, levels.size)), cell, axis=1)
        printed = inks(one_ink(ink, coverage), on_the_grid(ink, cell, turns))[ink]
        per_cell = printed.reshape(2, cell, levels.size, cell).sum(axis=(1, 3))
        np.testing.assert_array_equal(per_cell, np.broadcast_to(np.arange(levels.size), (2, levels.size)),
                                      err_msg=f"cell {cell}")
        first = np.tile(cell_ranks(cell, turns), (2, levels.size)) < np.repeat(np.arange(levels.size), cell)
        np.testing.assert_array_equal(printed, first, err_msg=f"cell {cell}")


@pytest.mark.parametrize("cell", (3, 8))
def test_on_the_pixel_grid_a_flat_field_is_within_half_a_level(cell):
    # any coverage a inks round(a cell^2) samples of each cell: within 1 / (2 cell^2) of a,
    # met exactly at a = 1/2, cell 3: 4 of 9 (S would give up to 0.125 off at cell 8)
    for level in LEVELS:
        printed = inks(one_ink("y", level, 4 * cell), Halftone(cell, 0))["y"]
        assert abs(printed.mean() - level) <= 1 / (2 * cell * cell) + 1e-12, level


def test_beyond_max_grid_cell_a_screen_keeps_the_diamond():
    assert grid_turns(Halftone(MAX_GRID_CELL, 0))[INKS.index("y")] == 0
    assert grid_turns(Halftone(MAX_GRID_CELL + 1, 0)) == (None,) * 4
    assert grid_turns(Halftone(6.5, 0)) == grid_turns(Halftone(6, 0.5)) == (None,) * 4


@pytest.mark.parametrize("ink", INKS)
@pytest.mark.parametrize("grid", (False, True), ids=("off the grid", "on the grid"))
def test_the_dot_grows_with_darkness(ink, grid):
    # nested: every pixel an ink covers at one coverage it covers at every higher one
    halftone = on_the_grid(ink, 6, 1) if grid else Halftone(7.5, 10)
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
    # on the pixel grid: yellow (angle 0), cyan (-15), magenta (15: 90), black (135: 180)
    for halftone in (Halftone(2, 0), Halftone(6, 0), Halftone(8, -15), Halftone(5, 15), Halftone(4, 135),
                     Halftone(7.5, 22.5), Halftone(13.3, -37)):
        settings = OutputSettings(halftone=halftone)
        for linear in (frame, ramp.astype(np.float32)):
            np.testing.assert_array_equal(output_passes[kind].apply(linear, settings),
                                          reference.output.apply(linear, settings),
                                          err_msg=str(halftone))
