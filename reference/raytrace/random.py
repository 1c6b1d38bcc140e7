"""# Twin: glsl/raytrace/random.glsl

The ray tracer's random numbers (docs/conventions.md, "Rays"), vectorised: every function takes
arrays (or scalars) of unsigned integers, broadcasts them and returns np.uint32 arrays (the
float conversion: float32), bit for bit what the GLSL returns.

pcg_hash is the PCG hash of Jarzynski & Olano, "Hash Functions for GPU Rendering", JCGT 9(3),
2020. All arithmetic is np.uint32, wrapping modulo 2^32 like GLSL's uint.
"""

from __future__ import annotations

import numpy as np

_MULTIPLIER = np.uint32(747796405)
_INCREMENT = np.uint32(2891336453)
_WORD_MULTIPLIER = np.uint32(277803737)
_U4 = np.uint32(4)
_U22 = np.uint32(22)
_U28 = np.uint32(28)
_U8 = np.uint32(8)
TWO_TO_MINUS_24 = np.float32(2.0 ** -24)


def _u32(values) -> np.ndarray:
    """`values` as an np.uint32 array of at least one dimension (0-d arrays turn into numpy
    scalars in arithmetic, whose wrap-around warns; arrays wrap silently)."""
    array = np.asarray(values)
    if array.dtype != np.uint32:
        if array.dtype.kind not in "iu" or (array.size and (array.min() < 0 or array.max() > 0xFFFFFFFF)):
            raise ValueError("random numbers are drawn from unsigned 32-bit integers")
        array = array.astype(np.uint32)
    return np.atleast_1d(array)


def _shaped(result: np.ndarray, *inputs) -> np.ndarray:
    shape = np.broadcast_shapes(*(np.shape(v) for v in inputs))
    return result.reshape(shape)


def _pcg(v: np.ndarray) -> np.ndarray:
    with np.errstate(over="ignore"):
        state = v * _MULTIPLIER + _INCREMENT
        word = ((state >> ((state >> _U28) + _U4)) ^ state) * _WORD_MULTIPLIER
        return (word >> _U22) ^ word


def pcg_hash(v) -> np.ndarray:
    """PCG hash of each uint32 in `v`."""
    return _shaped(_pcg(_u32(v)), v)


def random_stream(x, y, sample_index, bounce, seed) -> np.ndarray:
    """One stream value per (pixel x, pixel y, sample index, bounce, seed), broadcast: chained
    hashing, seed first and x last, as glsl/raytrace/random.glsl."""
    x_, y_, i_, b_, s_ = np.broadcast_arrays(*(_u32(v) for v in (x, y, sample_index, bounce, seed)))
    with np.errstate(over="ignore"):
        h = _pcg(s_)
        h = _pcg(h + b_)
        h = _pcg(h + i_)
        h = _pcg(h + y_)
        h = _pcg(h + x_)
    return _shaped(h, x, y, sample_index, bounce, seed)


def random_uint(stream, dimension) -> np.ndarray:
    """The dimension-th uint32 of each stream."""
    s_, d_ = np.broadcast_arrays(_u32(stream), _u32(dimension))
    with np.errstate(over="ignore"):
        return _shaped(_pcg(s_ + d_), stream, dimension)


def uint_to_unit_float(h) -> np.ndarray:
    """uint32 -> float32 in [0, 1): (h >> 8) * 2^-24, exact (an integer below 2^24 times a power
    of two), so equal to the GLSL's float bit for bit."""
    return _shaped((_u32(h) >> _U8).astype(np.float32) * TWO_TO_MINUS_24, h)


def random_float(stream, dimension) -> np.ndarray:
    """The dimension-th float32 in [0, 1) of each stream."""
    return uint_to_unit_float(random_uint(stream, dimension))
