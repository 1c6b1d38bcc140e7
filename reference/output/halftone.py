"""# Twin: glsl/output/halftone.glsl

Half-toning (clustered dots, as a printer screens its inks), vectorised over the image: linear
R, G, B (clamped to [0, 1], NaN -> 0) become ink coverages c = 1 - R, m = 1 - G, y = 1 - B,
k = min(c, m, y) (grey-component replacement: black ink prints the grey the three share), and
each ink is printed or not at a pixel by comparing its coverage with its own screen's spot
threshold there. Every step is float32 in the order the GLSL writes it (no fused multiply-add:
llvmpipe lowers it), so the twins agree bit for bit.

The screen (renderer/core/halftone_screen.py): cell coordinates u = px cs + py sn,
v = py cs - px sn of the pixel centre (px, py) = (x + 0.5, y + 0.5), x the column and y the
image row from the top. The spot threshold (the DIAMOND dot) of the cell's point
(fu, fv) = (frac(u) - 1/2, frac(v) - 1/2), t = |fu| + |fv| in [0, 1]:
    S = 2 t^2            for t <= 1/2
    S = 1 - 2 (1 - t)^2  above
{S < a} is the diamond |fu| + |fv| < sqrt(a / 2) for a <= 1/2 and the cell less four corner
triangles above, of area exactly a in either case: a flat coverage a inks a fraction a of the
paper (up to the pixel grid's sampling), the spot grows from the cell's centre as a rises, and
neighbouring spots meet at a = 1/2. (A round dot's threshold needs acos, which llvmpipe does
not round exactly; the diamond's needs only products and sums.)

A screen on the pixel grid (an angle that is a multiple of 90 degrees, a whole-pixel cell:
renderer/core/halftone_screen.py, grid_turns) samples every cell at the same points, where S
ties on each diamond: it uses its threshold array T (grid_thresholds: the cell's samples
ranked by S, ties broken, T = (rank + 1/2) / cell^2) in place of S, so a flat coverage a inks
round(a cell^2) samples of each cell: cell^2 + 1 levels. Other screens sample their cells
everywhere and keep S.

An ink is printed where its coverage exceeds the threshold: K where k > S_K; C where
c' = (c - k) / (1 - k) > S_C, written without the division as c - k > S_C (1 - k). Were the
screens independent, a pixel's expected reflectance would be (1 - c')(1 - k) = 1 - c: the mean
light is kept. The screens' angles differ (C 15, M 75, Y 0, K 45 degrees), so their dots overlap
nearly, not exactly, at random: the bias that leaves is measured (tests/test_output_halftone.py,
tests/test_output_mean_light.py).
"""

from __future__ import annotations

import numpy as np

from renderer.core.halftone_screen import INKS, grid_screens, screen_basis
from renderer.core.output_settings import Halftone, OutputSettings
from reference.output.quantise import clamp_light

_F = np.float32


def spot_threshold(px: np.ndarray, py: np.ndarray, cs: np.float32, sn: np.float32) -> np.ndarray:
    """S (float32, in [0, 1]) of the diamond dot at the pixel centres (px, py) (float32) on the
    screen whose basis is (cs, sn)."""
    u = px * cs + py * sn
    v = py * cs - px * sn
    fu = (u - np.floor(u)) - _F(0.5)
    fv = (v - np.floor(v)) - _F(0.5)
    t = np.abs(fu) + np.abs(fv)
    inside = _F(2.0) * (t * t)                       # the diamond around the cell's centre
    rest = _F(1.0) - _F(2.0) * ((_F(1.0) - t) * (_F(1.0) - t))
    return np.where(t <= _F(0.5), inside, rest)


def inks(rgb: np.ndarray, halftone: Halftone) -> dict[str, np.ndarray]:
    """{ink: (H, W) bool, where it is printed} for the linear colour `rgb` (H, W, 3) float32,
    row 0 at the top (clamped to [0, 1], NaN -> 0: clamp_light)."""
    height, width = rgb.shape[:2]
    c, m, y = (_F(1.0) - clamp_light(rgb[..., i]) for i in range(3))
    k = np.minimum(np.minimum(c, m), y)
    px = np.arange(width, dtype=np.float32)[None, :] + _F(0.5)
    py = np.arange(height, dtype=np.float32)[:, None] + _F(0.5)
    cells, arrays = grid_screens(halftone)
    spots = {}
    for row, (ink, (cs, sn), cell) in enumerate(zip(INKS, screen_basis(halftone), cells)):
        if cell:                                 # on the pixel grid: its threshold array
            array = arrays[row * cell:(row + 1) * cell]
            spots[ink] = array[np.arange(height)[:, None] % cell, np.arange(width)[None, :] % cell]
        else:
            spots[ink] = spot_threshold(px, py, cs, sn)
    paper = _F(1.0) - k                          # what the black ink leaves for the colours
    printed = {ink: (coverage - k) > spots[ink] * paper
               for ink, coverage in (("c", c), ("m", m), ("y", y))}
    printed["k"] = k > spots["k"]
    return printed


def halftoned(rgb: np.ndarray, settings: OutputSettings) -> np.ndarray:
    """(H, W, 3) uint16 1-bit codes of R, G, B of the linear colour `rgb` (H, W, 3) under
    settings.halftone: 0 where the channel's ink (C for R, M for G, Y for B) or black is
    printed, else 1 (the paper)."""
    printed = inks(rgb, settings.halftone)
    paper = [~(printed[ink] | printed["k"]) for ink in ("c", "m", "y")]
    return np.stack(paper, axis=-1).astype(np.uint16)
