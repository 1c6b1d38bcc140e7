"""The half-tone screens' geometry, written once for both twins (glsl/output/halftone.glsl,
reference/output/halftone.py): each ink's screen is a grid of square cells `cell` pixels wide
turned by its angle, given to the shaders as two float32 numbers per ink, and, where the
screen lies on the pixel grid, as a threshold array.

A pixel centre (px, py) (x = column + 0.5, y = image row from the top + 0.5) has cell
coordinates u = px cs + py sn, v = py cs - px sn, with cs = cos(a) / cell and sn = sin(a) / cell:
the screen's axes turned by a, in cells. cs and sn are computed here in float64 and rounded to
float32 once, so that both twins multiply by the very same numbers (no trigonometry on the GPU).

A screen ON THE PIXEL GRID (its angle a multiple of 90 degrees, the cell a whole number c of
pixels) samples every cell at the same c^2 points, and the diamond's threshold S ties on
each contour |fu| + |fv| = const (cell 8: 7 distinct values among 64 samples), so a flat
coverage would ink only a few fractions of the cell. Such a screen is a threshold array
instead, as a printer's is built from its spot function (PostScript Language Reference,
3rd ed., 7.4.2 "Spot functions": device pixels are painted in the order of the spot
function's values): the c^2 samples ranked by the diamond (|fu| + |fv|), ties broken as
`cell_ranks` says, and sample r gets T = (r + 1/2) / c^2. A coverage a then inks the
round(a c^2) first samples of every cell (within 1/(2 c^2) of a; exactly k at a = k / c^2),
c^2 + 1 levels, and the dot still grows from the cell's centre, nested.
"""

from __future__ import annotations

import math
from functools import lru_cache

import numpy as np

from renderer.core.output_settings import INK_ANGLES, Halftone

INKS = ("c", "m", "y", "k")        # the order of the rows of `screen_basis` (and of the GLSL's)
MAX_GRID_CELL = 256                # the largest cell given a threshold array (4 MiB at most)
# The quarter turns' (cos, sin), exact.
_QUARTER_TURNS = ((1, 0), (0, 1), (-1, 0), (0, -1))
# The order in which a cell inks the (up to) 8 samples (a, b) that one (p, q), p >= q >= 0,
# stands for (the same |a| + |b| and |a| - |b|): a sample and its opposite, then those a
# quarter turn on, then the mirror images alike, so that the dot keeps its centre after every
# second sample and its four-fold symmetry after every fourth.
_ORBIT = (lambda p, q: (p, q), lambda p, q: (-p, -q), lambda p, q: (-q, p), lambda p, q: (q, -p),
          lambda p, q: (q, p), lambda p, q: (-q, -p), lambda p, q: (-p, q), lambda p, q: (p, -q))


def screen_basis(halftone: Halftone) -> np.ndarray:
    """(4, 2) float32: per ink of INKS, (cs, sn) = (cos(a) / cell, sin(a) / cell) with
    a = halftone.angle + INK_ANGLES[ink] degrees."""
    basis = np.empty((len(INKS), 2), dtype=np.float32)
    for row, ink in enumerate(INKS):
        angle = math.radians(halftone.angle + INK_ANGLES[ink])
        basis[row] = (math.cos(angle) / halftone.cell, math.sin(angle) / halftone.cell)
    return basis


def grid_turns(halftone: Halftone) -> tuple[int | None, ...]:
    """Per ink of INKS: the quarter turns (0 to 3) of its screen when it lies on the pixel
    grid (its angle a multiple of 90 degrees, the cell a whole number of pixels up to
    MAX_GRID_CELL), else None. (INK_ANGLES differ by no multiple of 90: one ink at most.)"""
    if halftone.cell != math.floor(halftone.cell) or halftone.cell > MAX_GRID_CELL:
        return (None,) * len(INKS)
    angles = (halftone.angle + INK_ANGLES[ink] for ink in INKS)
    return tuple(round(angle / 90) % 4 if angle % 90 == 0 else None for angle in angles)


@lru_cache(maxsize=64)
def cell_ranks(cell: int, turns: int = 0) -> np.ndarray:
    """(cell, cell) int64, [row y][column x] of a cell's pixels on a screen turned by `turns`
    quarter turns: the order 0 .. cell^2 - 1 in which a growing coverage inks them.

    In half-pixel units from the cell's centre, the pixel's sample is (a, b) = 2 c (fu, fv),
    integers (odd for an even cell), and the order is, by priority:
    1. |a| + |b|: the diamond's S (monotone in t = |fu| + |fv|), centre first;
    2. on one diamond, (|a| - |b|)^2 rising while the dot grows (t <= 1/2: diagonal samples
       first, a rounder dot), falling after it has met its neighbours (the paper left is a
       diamond about the cell's corner, rounded the same way);
    3. among the up to 8 samples alike in both, _ORBIT's order.
    No two samples of a cell share all three, so every sample has its own rank."""
    offset = 2 * np.arange(cell) + 1 - cell                  # 2 c (x + 1/2) / c - c
    along_x, along_y = offset[None, :], offset[:, None]
    cos, sin = _QUARTER_TURNS[turns]
    a = cos * along_x + sin * along_y                        # u = (px cs + py sn), in 1/(2 c)
    b = cos * along_y - sin * along_x                        # v = (py cs - px sn)
    a, b = np.broadcast_arrays(a, b)
    diamond = np.abs(a) + np.abs(b)
    spread = (np.abs(a) - np.abs(b)) ** 2
    roundness = np.where(diamond <= cell, spread, -spread)
    p, q = np.maximum(np.abs(a), np.abs(b)), np.minimum(np.abs(a), np.abs(b))
    position = np.full(a.shape, len(_ORBIT))
    for index, image in reversed(list(enumerate(_ORBIT))):   # the first that matches wins
        image_a, image_b = image(p, q)
        position = np.where((image_a == a) & (image_b == b), index, position)
    order = np.lexsort((position.ravel(), roundness.ravel(), diamond.ravel()))
    ranks = np.empty(cell * cell, dtype=np.int64)
    ranks[order] = np.arange(cell * cell)
    ranks = ranks.reshape(cell, cell)
    ranks.flags.writeable = False                            # cached: shared by every caller
    return ranks


@lru_cache(maxsize=16)
def grid_thresholds(cell: int, turns: tuple[int | None, ...]) -> np.ndarray:
    """(4 cell, cell) float32: ink i's threshold array T = (rank + 1/2) / cell^2 in rows
    i cell .. (i + 1) cell - 1, [row y mod cell][column x mod cell], for each ink of INKS
    whose `turns` (grid_turns) is not None; zeros for the others."""
    thresholds = np.zeros((len(INKS) * cell, cell), dtype=np.float32)
    for row, ink_turns in enumerate(turns):
        if ink_turns is not None:
            ranks = cell_ranks(cell, ink_turns)
            thresholds[row * cell:(row + 1) * cell] = (ranks + 0.5) / (cell * cell)
    thresholds.flags.writeable = False
    return thresholds


def grid_screens(halftone: Halftone) -> tuple[np.ndarray, np.ndarray | None]:
    """(cells, thresholds): cells (4,) uint32, per ink of INKS its whole-pixel cell where its
    screen lies on the pixel grid, else 0; thresholds grid_thresholds' arrays, None when no
    ink's screen lies on the grid."""
    turns = grid_turns(halftone)
    on_grid = [ink_turns is not None for ink_turns in turns]
    cells = np.where(on_grid, int(halftone.cell) if any(on_grid) else 0, 0).astype(np.uint32)
    return cells, (grid_thresholds(int(halftone.cell), turns) if any(on_grid) else None)
