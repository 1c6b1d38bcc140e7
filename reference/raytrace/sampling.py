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

The other distributed dimensions (`distributed_2d`, `distributed_1d`; renderer/core/
ray_sampling.py and docs/conventions.md, "Distributed sampling"): the same pattern over a set's
n * per_sample points, shuffled by Kensler's `permute` with a key per pixel, frame, slot and
dimension; integer arithmetic and the same float conversions, so bit for bit the GLSL's.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from reference.raytrace.random import random_stream, random_uint, uint_to_unit_float
from renderer.core.ray_sampling import DIMENSION_STRIDE, PERMUTATION_SALT

_FRACTION = np.uint32(1 << 24)
_U8 = np.uint32(8)
TWO_TO_MINUS_24 = np.float32(2.0 ** -24)
HALF = np.float32(0.5)
CELL_CENTRE = np.uint32(0x80000000)          # stratum_coordinate's h of a cell's centre
BELOW_ONE = np.float32(1.0 - 2.0 ** -24)     # the largest float32 below 1


def stratum_coordinate(h, a, c) -> np.ndarray:
    """The coordinate in cell a of c (arrays broadcast) at the uniform uint32 numbers h:
    n 2^-24 with n = max(floor((a 2^24 + (h >> 8)) / c), ceil(a 2^24 / c)), so n 2^-24 lies in
    [a/c, (a + 1)/c) exactly; a < c <= 256 keeps the numerators below 2^32. float(n) 2^-24 is
    exact in float32 (n < 2^24). h = CELL_CENTRE gives the cell's centre (to 24 bits)."""
    with np.errstate(over="ignore"):
        base = np.asarray(a, np.uint32) * _FRACTION
        c_ = np.asarray(c, np.uint32)
        n = np.maximum((base + (np.asarray(h, np.uint32) >> _U8)) // c_, (base + c_ - np.uint32(1)) // c_)
    return n.astype(np.float32) * TWO_TO_MINUS_24


def stratum_offset(h, a, c) -> np.ndarray:
    """stratum_coordinate minus 0.5: an offset from the pixel's centre (exact in float32)."""
    return stratum_coordinate(h, a, c) - HALF


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


# -- distributed dimensions ---------------------------------------------------------------------
_PERMUTE_MULTIPLIERS = [np.uint32(v) for v in (0xE170893D, 0x0929EB3F, 0x6935FA69, 0x74DCB303,
                                               0x9E501CC3, 0xC860A3DF)]


def _permute_rounds(i, p, w):
    u = np.uint32
    m = _PERMUTE_MULTIPLIERS
    with np.errstate(over="ignore"):
        i = i ^ p
        i = i * m[0]
        i ^= p >> u(16)
        i ^= (i & w) >> u(4)
        i ^= p >> u(8)
        i = i * m[1]
        i ^= p >> u(23)
        i ^= (i & w) >> u(1)
        i = i * (u(1) | (p >> u(27)))
        i = i * m[2]
        i ^= (i & w) >> u(11)
        i = i * m[3]
        i ^= (i & w) >> u(2)
        i = i * m[4]
        i ^= (i & w) >> u(2)
        i = i * m[5]
        i &= w
        i ^= i >> u(5)
    return i


def permute(i, l, p) -> np.ndarray:
    """Kensler's hash permutation of [0, l) (the GLSL's `permute`; arrays broadcast, uint32):
    rounds of invertible steps on l - 1's bit mask, repeated (cycle walking) for the values not
    yet below l, then rotated by (i + p mod l) mod l."""
    i, l, p = (np.array(v, np.uint32) for v in np.broadcast_arrays(i, l, p))
    w = l - np.uint32(1)
    for shift in (1, 2, 4, 8, 16):
        w |= w >> np.uint32(shift)
    todo = np.ones(i.shape, bool)
    while todo.any():                          # a do-while per element; ~1.4 rounds on average
        i[todo] = _permute_rounds(i[todo], p[todo], w[todo])
        todo &= i >= l
    return (i + p % l) % l


def _frame_first_sample(first_sample: int, sampling) -> int:
    """The table patterns repeat every frame, as their pixel offsets do."""
    return 0 if sampling.table is not None else first_sample


def permutation_key(x, y, first_sample: int, sampling, slot, dimension: int, which_set):
    """The key of `dimension` at `slot` for the pixel's samples of set `which_set`."""
    stream = random_stream(x, y, _frame_first_sample(first_sample, sampling), slot,
                           np.uint32(sampling.seed) ^ np.uint32(PERMUTATION_SALT))
    return random_uint(stream, np.uint32(2 * dimension) + np.asarray(which_set, np.uint32))


def _sets(k, sampling):
    """(which set, index in it) of samples k (arrays)."""
    k = np.asarray(k, np.int64)
    which = (k >= sampling.first_set).astype(np.int64)
    return which, k - which * sampling.first_set


def distributed_2d(x, y, k, first_sample: int, sampling, slot, dimension: int, m: int = 0,
                   per_sample: int = 1) -> np.ndarray:
    """(..., 2) float32 points in [0, 1)^2: sample k's m-th point (m < per_sample: 1, or the
    sampling's light_samples) of `dimension` at `slot` (0: the camera's; 1 + r: at ray r's hit)
    for pixels (x, y); x, y, k, slot broadcast. The GLSL's distributed_2d bit for bit."""
    x, y, k, slot = np.broadcast_arrays(*(np.asarray(v) for v in (x, y, k, slot)))
    stream = random_stream(x, y, _frame_first_sample(first_sample, sampling) + k.astype(np.int64), slot,
                           sampling.seed)
    number = 2 * (DIMENSION_STRIDE * dimension + m)
    h0, h1 = random_uint(stream, number), random_uint(stream, number + 1)
    mode = sampling.dimension_mode
    if mode == "random":
        return np.stack([uint_to_unit_float(h0), uint_to_unit_float(h1)], -1)
    which, j = _sets(k, sampling)
    grids = np.array([sampling.dimension_grid(0, per_sample), sampling.dimension_grid(1, per_sample)])
    columns, rows = grids[which, 0], grids[which, 1]
    cell = permute(j * per_sample + m, columns * rows,
                   permutation_key(x, y, first_sample, sampling, slot, dimension, which)).astype(np.int64)
    if mode == "table" and per_sample == 1:
        return np.minimum(sampling.table[cell] + HALF, BELOW_ONE)
    if mode == "centres":
        h0 = h1 = np.broadcast_to(CELL_CENTRE, h0.shape)
    return np.stack([stratum_coordinate(h0, cell % columns, columns),
                     stratum_coordinate(h1, cell // columns, rows)], -1)


def distributed_1d(x, y, k, first_sample: int, sampling, slot, dimension: int) -> np.ndarray:
    """float32 points in [0, 1): sample k's point of a one-dimensional `dimension` at `slot`
    (the set's n samples in n strata, permuted; regular: the centres; poisson: jittered). The
    GLSL's distributed_1d bit for bit."""
    x, y, k, slot = np.broadcast_arrays(*(np.asarray(v) for v in (x, y, k, slot)))
    stream = random_stream(x, y, _frame_first_sample(first_sample, sampling) + k.astype(np.int64), slot,
                           sampling.seed)
    h = random_uint(stream, 2 * DIMENSION_STRIDE * dimension)
    mode = sampling.dimension_mode
    if mode == "random":
        return uint_to_unit_float(h)
    which, j = _sets(k, sampling)
    n = np.array(sampling.set_sizes)[which]
    cell = permute(j, n, permutation_key(x, y, first_sample, sampling, slot, dimension, which))
    if mode == "centres":
        h = np.broadcast_to(CELL_CENTRE, h.shape)
    return stratum_coordinate(h, cell, n)


@dataclass
class RaySamples:
    """Whose numbers each camera ray draws: its pixel (x, y) (GL window coordinates, uint32
    arrays), its sample k in the frame, the frame's first sample index and sampling rule.
    trace.py hands a ray of a camera ray's tree `owner` (the camera ray's index) and `key`
    (the GLSL's g_ray_key) to these methods, so that a hit draws the GLSL's numbers."""
    x: np.ndarray
    y: np.ndarray
    k: np.ndarray
    first_sample: int
    sampling: object

    def point_2d(self, owner, slot, dimension: int, m: int = 0, per_sample: int = 1) -> np.ndarray:
        """distributed_2d for the camera rays `owner` at `slot` (1 + key at a hit)."""
        return distributed_2d(self.x[owner], self.y[owner], self.k[owner], self.first_sample,
                              self.sampling, slot, dimension, m, per_sample)

    def point_1d(self, owner, slot, dimension: int) -> np.ndarray:
        """distributed_1d for the camera rays `owner` at `slot`."""
        return distributed_1d(self.x[owner], self.y[owner], self.k[owner], self.first_sample,
                              self.sampling, slot, dimension)
