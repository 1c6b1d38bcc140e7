"""# Twin: glsl/raytrace/sampling.glsl

Where sample k of a frame lies in pixel (x, y) (docs/conventions.md, "Sample positions";
the rule's constants: renderer/core/ray_sampling.py), vectorised over pixels: the offset
(dx, dy) from the pixel's centre, float32 in [-0.5, 0.5)^2, bit for bit the GLSL's.

A table pattern (regular, poisson) gives offset k of its table. A stratified one (random,
jittered, adaptive) puts sample k in a cell (a, b) of a columns x rows grid (row by row:
a = j mod columns, b = j div columns, j = k or k - first_set, modulo columns x rows) and in the cell at the uniform
numbers h0, h1 (random_uint of random_stream(x, y, first_sample + k, 0, seed), dimensions 0
and 1), each coordinate by `stratum_offset`: 24-bit fixed point by integer division, exact
in both twins.
"""

from __future__ import annotations

import numpy as np

from reference.raytrace.random import random_stream, random_uint

_FRACTION = np.uint32(1 << 24)
_U8 = np.uint32(8)
TWO_TO_MINUS_24 = np.float32(2.0 ** -24)
HALF = np.float32(0.5)


def stratum_offset(h, a: int, c: int) -> np.ndarray:
    """The coordinate (minus 0.5) in cell a of c at the uniform uint32 numbers h: n 2^-24 - 0.5
    with n = max(floor((a 2^24 + (h >> 8)) / c), ceil(a 2^24 / c)), so n 2^-24 lies in
    [a/c, (a + 1)/c) exactly; a < c <= 256 keeps the numerators below 2^32. float(n) 2^-24
    and the subtraction of 0.5 are exact in float32 (n < 2^24)."""
    base = np.uint32(a) * _FRACTION
    c_ = np.uint32(c)
    n = np.maximum((base + (np.asarray(h, np.uint32) >> _U8)) // c_, (base + c_ - np.uint32(1)) // c_)
    return n.astype(np.float32) * TWO_TO_MINUS_24 - HALF


def sample_offset(x, y, k: int, first_sample: int, sampling) -> np.ndarray:
    """(..., 2) float32 offsets of sample k of the frame at pixels (x, y) (GL window
    coordinates, row 0 at the bottom; uint arrays, broadcast); `sampling` a
    renderer.core.ray_sampling.RaySampling."""
    shape = np.broadcast_shapes(np.shape(x), np.shape(y))
    if sampling.table is not None:
        return np.broadcast_to(sampling.table[k], (*shape, 2)).astype(np.float32)
    j, (columns, rows) = k, sampling.first_strata
    if k >= sampling.first_set:
        j, (columns, rows) = k - sampling.first_set, sampling.rest_strata
    j %= columns * rows                      # random: every sample in the one 1 x 1 cell
    stream = random_stream(x, y, first_sample + k, 0, sampling.seed)
    return np.stack([stratum_offset(random_uint(stream, 0), j % columns, columns),
                     stratum_offset(random_uint(stream, 1), j // columns, rows)], axis=-1)
