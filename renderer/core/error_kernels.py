"""Error-diffusion kernels and the order that makes them parallel, written once for both twins
(glsl/output/error_diffusion.comp, reference/output/error_diffusion.py).

A kernel is written as the literature prints it, in "push" form: the share of a pixel's error
each later neighbour (dx columns right, dy rows down) receives. Both twins use it in "pull"
form: a pixel gathers what its earlier neighbours sent, tap by tap in ONE fixed order (the
sources in raster order: top row first, left to right), so that the GPU and the twin add the
same float32 terms in the same order and agree bit for bit. Raster order, not serpentine:
a serpentine scan reverses every other row, so a row's pixels no longer depend on the row
above in one direction and no skewed wavefront orders them.

The wavefronts: pixel (x, y) lies on wavefront t = x + s y. Every pulled neighbour
(x - dx, y - dy) lies on wavefront t - (dx + s dy), an earlier one when dx + s dy > 0 for
every tap: `skew` is the smallest such s (2 for Floyd-Steinberg, 3 for Jarvis-Judice-Ninke).
All the pixels of one wavefront are then independent, and the image takes W + s (H - 1)
wavefronts in order (the GPU: one dispatch each).
"""

from __future__ import annotations

from dataclasses import dataclass
from functools import lru_cache

import numpy as np


@dataclass(frozen=True)
class ErrorKernel:
    """push: {(dx, dy): weight} over `divisor`; the pixel itself is (0, 0)."""
    push: dict
    divisor: int

    @property
    def skew(self) -> int:
        """The smallest s with dx + s dy > 0 for every (dx, dy) of push."""
        s = 0
        while not all(dx + s * dy > 0 for dx, dy in self.push):
            s += 1
        return s

    @property
    def reach(self) -> int:
        """How far (columns or rows) a pixel's error travels: the zero border of the error
        image that lets the pull read every tap without a test."""
        return max(max(abs(dx), abs(dy)) for dx, dy in self.push)


# Floyd & Steinberg (1976):        Jarvis, Judice & Ninke (1976):
#          *  7                              *  7  5
#       3  5  1      / 16             3  5  7  5  3
#                                     1  3  5  3  1      / 48
KERNELS = {
    "floyd-steinberg": ErrorKernel({(1, 0): 7, (-1, 1): 3, (0, 1): 5, (1, 1): 1}, 16),
    "jarvis-judice-ninke": ErrorKernel(
        {(1, 0): 7, (2, 0): 5,
         (-2, 1): 3, (-1, 1): 5, (0, 1): 7, (1, 1): 5, (2, 1): 3,
         (-2, 2): 1, (-1, 2): 3, (0, 2): 5, (1, 2): 3, (2, 2): 1}, 48),
}


@lru_cache(maxsize=None)
def pull_taps(name: str) -> tuple[np.ndarray, np.ndarray]:
    """(offsets (n, 2) int32, weights (n,) float32) of kernel `name` in pull form: the source
    of tap k is (x + offsets[k, 0], y + offsets[k, 1]); weights[k] = float32(w / divisor)
    (exact for Floyd-Steinberg's sixteenths, rounded once for 48ths). Taps in the fixed
    order both twins add them: sources in raster order."""
    kernel = KERNELS[name]
    sources = sorted(((-dy, -dx), w) for (dx, dy), w in kernel.push.items())
    offsets = np.array([(dx, dy) for (dy, dx), _ in sources], dtype=np.int32)
    weights = np.array([w / kernel.divisor for _, w in sources], dtype=np.float64)
    offsets.flags.writeable = False
    weights = weights.astype(np.float32)
    weights.flags.writeable = False
    return offsets, weights


def wavefronts(width: int, height: int, skew: int):
    """(t, first row, last row) of each wavefront t = x + skew y of a width x height image,
    in order: its pixels are (t - skew y, y) for y = first .. last."""
    for t in range(width + skew * (height - 1)):
        first = max(0, -(-(t - width + 1) // skew))        # ceil((t - (W - 1)) / s)
        last = min(height - 1, t // skew)
        yield t, first, last
