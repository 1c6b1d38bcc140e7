"""Error-diffusion kernels and the order that makes them parallel, written once for both twins
(glsl/output/error_diffusion.comp, reference/output/error_diffusion.py).

A kernel is written as the literature prints it, in "push" form: the share of a pixel's error
each later neighbour (dx columns right, dy rows down) receives. Both twins use it in "pull"
form: a pixel gathers what its earlier neighbours sent, tap by tap in ONE fixed order (the
sources in raster order: top row first, left to right), so that the GPU and the twin add the
same float32 terms in the same order and agree bit for bit. Raster order, not serpentine:
a serpentine scan reverses every other row, so a row's pixels no longer depend on the row
above in one direction and no skewed wavefront orders them.

At the image's edges a kernel's receivers outside the image get nothing and the shares of
those inside are renormalised (`sender_weights`): error that left the image would be light
lost, a deficit proportional to the perimeter over the area (1 bit, 320 x 240, built-in
scenes: about -0.3/255 of mean luminance with Floyd-Steinberg and -0.6/255 with
Jarvis-Judice-Ninke when dropped), while renormalised, the codes' total light equals the
image's but for the last (bottom-right) pixel's error (about half a code step) and float32
rounding.

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
        """How far (columns or rows) a pixel's error travels: the width of the zero border of
        the error image that lets the pull read every tap without a test."""
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
def pull_taps(name: str) -> np.ndarray:
    """(n, 2) int32, read-only: the taps of kernel `name` in pull form, in the fixed order
    both twins add them (the sources in raster order): the source of tap k of pixel (x, y) is
    (x + taps[k, 0], y + taps[k, 1])."""
    sources = sorted((-dy, -dx) for dx, dy in KERNELS[name].push)
    taps = np.array([(dx, dy) for dy, dx in sources], dtype=np.int32)
    taps.flags.writeable = False
    return taps


@lru_cache(maxsize=None)
def sender_weights(name: str) -> np.ndarray:
    """(r + 1, r + 1, r + 1, n) float32, read-only (r = reach, n taps): [left, right, below, k]
    is the share of its error a source pixel sends along tap k, when it lies `left` columns
    from the image's left edge, `right` from its right edge and `below` rows above its bottom
    edge (each counted up to r: further makes no difference). The shares are the kernel's
    weights over the sum of the weights whose receivers lie inside the image,
    float32(w / that sum), rounded once: inside the image the printed w / divisor, at an edge
    renormalised, so that no error leaves the image and the frame keeps its light but for the
    last pixel's error. A source with no receiver inside (the bottom-right pixel) sends 0."""
    kernel = KERNELS[name]
    r = kernel.reach
    weights = np.zeros((r + 1, r + 1, r + 1, len(kernel.push)), dtype=np.float32)
    for left in range(r + 1):
        for right in range(r + 1):
            for below in range(r + 1):
                inside = {(dx, dy): w for (dx, dy), w in kernel.push.items()
                          if -left <= dx <= right and dy <= below}
                total = sum(inside.values())
                for k, (dx, dy) in enumerate(pull_taps(name)):
                    if total and (-dx, -dy) in inside:
                        weights[left, right, below, k] = inside[-dx, -dy] / total
    weights.flags.writeable = False
    return weights


def sender_sides(x, y, width: int, height: int, reach: int):
    """(left, right, below) of source pixels (x, y), each clamped to [0, reach]: the indices of
    `sender_weights`. A source outside the image (its error is the border's 0) gets some
    valid index."""
    def side(d):
        return np.clip(d, 0, reach)
    return side(x), side(width - 1 - x), side(height - 1 - y)


def wavefronts(width: int, height: int, skew: int):
    """(t, first row, last row) of each wavefront t = x + skew y of a width x height image,
    in order: its pixels are (t - skew y, y) for y = first .. last."""
    for t in range(width + skew * (height - 1)):
        first = max(0, -(-(t - width + 1) // skew))        # ceil((t - (W - 1)) / s)
        last = min(height - 1, t // skew)
        yield t, first, last
