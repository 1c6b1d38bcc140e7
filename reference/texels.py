"""# Twin: fixed-function GL texel addressing and filtering (OpenGL 4.5 §8.14.2, §8.15) as llvmpipe does it

One mip level's part of a texture lookup (reference/sampler.py chooses the levels and blends
them): texel coordinates, the wrap modes and the nearest and linear filters, on llvmpipe's two
paths (docs/llvmpipe/texture-sampler.md):

- the fixed-point path (repeat and clamp to edge): texel coordinates in 1/256 of a texel,
  bilinear weights of TEXEL_WEIGHT_BITS, the 8-bit `lerp8` per channel, x first, then y;
  results stay unorm8 (int64 arrays) until the sampler converts them;
- the float path (mirrored repeat, and the anisotropic filter's texels): float32 texel
  coordinates and weights, texels converted first (gl_rules.unorm8_to_float), each lerp one
  fused multiply-add (`fma32`).
Texel (i, j), j counted from the bottom, of level l is `texel_levels(texture).fetch(l, i, j)`.
Sizes, levels and indices are int64 arrays that broadcast with the coordinates; the repeat
rule for every level follows the BASE level's power-of-two-ness, as llvmpipe's does.
"""

from __future__ import annotations

import weakref
from dataclasses import dataclass

import numpy as np

from renderer.core.gl_rules import TEXEL_WEIGHT_BITS, unorm8_to_float

f32 = np.float32
INT32_MIN = -(1 << 31)
TEXEL_ONE = 1 << TEXEL_WEIGHT_BITS          # one texel in the fixed-point coordinate
TEXEL_HALF = TEXEL_ONE >> 1
BELOW_ONE = np.nextafter(f32(1), f32(0))    # the largest float32 below 1 (fract_safe's clamp)


# --------------------------------------------------------------------------- float32 rules

def flush_denormals(x):
    """x (float32) with denormals made 0: llvmpipe's shaders run with the CPU's denormals-are-
    zero and flush-to-zero modes, so a denormal coordinate samples as 0 (u = -1e-45 with NPOT
    repeat reads texel 0, not the last texel)."""
    x = np.asarray(x, dtype=f32)
    return np.where(np.abs(x) < np.finfo(f32).tiny, f32(0), x)


def cvt_round(x):
    """float32 -> int32 rounded to nearest, ties to even (cvtps2dq); NaN and |x| >= 2^31 give
    INT32_MIN, as the instruction does. int64 out, for exact arithmetic after."""
    ok = np.abs(x) < 2.0 ** 31
    return np.where(ok, np.rint(np.where(ok, x, 0)), INT32_MIN).astype(np.int64)


def cvt_trunc(x):
    """float32 -> int32 truncated (cvttps2dq); NaN and out of range give INT32_MIN."""
    ok = np.abs(x) < 2.0 ** 31
    return np.where(ok, np.trunc(np.where(ok, x, 0)), INT32_MIN).astype(np.int64)


def _wrap_int32(x):
    """int64 values wrapped to int32 two's complement (llvmpipe's int32 adds)."""
    return ((x + (1 << 31)) & 0xFFFFFFFF) - (1 << 31)


def fma32(a, b, c):
    """fma(a, b, c) in float32 with one rounding, as an FMA instruction (llvmpipe's
    lp_build_mad): a b is exact in float64, the float64 sum's error is recovered exactly
    (two-sum), and a float64 sum that lands on a float32 halfway point is moved off it by
    that error before the rounding to float32."""
    p = np.asarray(a, dtype=np.float64) * np.asarray(b, dtype=np.float64)
    c = np.asarray(c, dtype=np.float64)
    s = p + c
    t = s - p
    error = (p - (s - t)) + (c - t)
    r = s.astype(f32)
    other = np.nextafter(r, np.where(s > r, np.inf, -np.inf).astype(f32))
    halfway = (s != r) & (s == (r.astype(np.float64) + other.astype(np.float64)) / 2) & (error != 0)
    toward = np.where(error > 0, np.maximum(r, other), np.minimum(r, other))
    return np.where(halfway, toward, r).astype(f32)


# --------------------------------------------------------------------------- texel storage

@dataclass(frozen=True)
class _Levels:
    """Every level's texels in one (T, 4) int64 array, each level's rows bottom-up (GL's
    order), so that texel (i, j) of level l is texels[offset[l] + j width[l] + i]."""
    texels: np.ndarray
    offset: np.ndarray
    width: np.ndarray
    height: np.ndarray

    def fetch(self, level, i, j):
        return self.texels[self.offset[level] + j * self.width[level] + i]


_stored: "weakref.WeakKeyDictionary" = weakref.WeakKeyDictionary()


def base_level_pots(texture) -> tuple[bool, bool]:
    """Whether the base level's width and height are powers of two: llvmpipe picks the repeat
    rule by these for every level (a 5 x 3 texture's 2 x 1 level still takes the NPOT rule)."""
    return tuple((size & (size - 1)) == 0 for size in (texture.width, texture.height))


def texel_levels(texture) -> _Levels:
    """`texture`'s levels as one bottom-up texel array (made once per Texture object)."""
    if texture not in _stored:
        flipped = [np.asarray(level)[::-1].reshape(-1, 4) for level in texture.levels]
        sizes = np.array([level.shape[:2] for level in texture.levels], dtype=np.int64)
        offset = np.concatenate([[0], np.cumsum(sizes[:, 0] * sizes[:, 1])[:-1]])
        _stored[texture] = _Levels(np.concatenate(flipped).astype(np.int64), offset,
                                   sizes[:, 1], sizes[:, 0])
    return _stored[texture]


# --------------------------------------------------------------------------- fixed-point path

def fixed_linear_axis(s, size, pot, repeat):
    """(i0, i1, weight in 0..255) along one axis of the fixed-point path (lp_bld_sample_aos.c).
    The coordinate is round(s size 256) - 128 in int32 (wrapping: beyond |s| size >= 2^23 it
    is INT32_MIN - 128, so a repeat axis reads its last and first texels half and half);
    repeat on an NPOT base level takes the fraction of s first, so it never overflows."""
    if repeat and not pot:
        fraction = (s - np.floor(s)).astype(f32)
        x = cvt_round((fraction * size.astype(f32)).astype(f32) * f32(TEXEL_ONE)) - TEXEL_HALF
        weight, i0 = x & (TEXEL_ONE - 1), x >> TEXEL_WEIGHT_BITS
        i0 = np.minimum(np.where(i0 < 0, size - 1, i0), size - 1)
        return i0, np.where(i0 == size - 1, 0, i0 + 1), weight
    x = _wrap_int32(cvt_round((s * (size << TEXEL_WEIGHT_BITS).astype(f32)).astype(f32)) - TEXEL_HALF)
    weight, i0 = x & (TEXEL_ONE - 1), x >> TEXEL_WEIGHT_BITS
    if repeat:
        return i0 & (size - 1), (i0 + 1) & (size - 1), weight
    return np.clip(i0, 0, size - 1), np.clip(i0 + 1, 0, size - 1), weight


def fixed_nearest_axis(s, size, pot, repeat):
    """The texel along one axis of the fixed-point path's nearest filter: floor(s size)
    (INT32_MIN when out of int32's range), clamped, masked (POT) or from the fraction of s
    below 1 (NPOT repeat)."""
    if repeat and not pot:
        fraction = (s - np.floor(s)).astype(f32)
        fraction = np.where(fraction < BELOW_ONE, fraction, BELOW_ONE)      # NaN too
        return cvt_trunc((fraction * size.astype(f32)).astype(f32))
    i = cvt_trunc(np.floor((s * size.astype(f32)).astype(f32)))
    return i & (size - 1) if repeat else np.clip(i, 0, size - 1)


def lerp8(weight, a, b):
    """llvmpipe's 8-bit lerp, weight in 1/256 (pmulhrsw): a + ((w (b - a) + 128) >> 8)."""
    return a + ((weight * (b - a) + TEXEL_HALF) >> TEXEL_WEIGHT_BITS)


def fixed_level(store, level, s, t, image_filter, pots, repeat):
    """One level's unorm8 result (N, 4) int64 on the fixed-point path."""
    width, height = store.width[level], store.height[level]
    if image_filter == "nearest":
        return store.fetch(level, fixed_nearest_axis(s, width, pots[0], repeat),
                           fixed_nearest_axis(t, height, pots[1], repeat))
    x0, x1, wx = fixed_linear_axis(s, width, pots[0], repeat)
    y0, y1, wy = fixed_linear_axis(t, height, pots[1], repeat)
    wx, wy = wx[:, None], wy[:, None]
    bottom = lerp8(wx, store.fetch(level, x0, y0), store.fetch(level, x1, y0))
    top = lerp8(wx, store.fetch(level, x0, y1), store.fetch(level, x1, y1))
    return lerp8(wy, bottom, top)


# --------------------------------------------------------------------------- float path

def _mirror(s):
    """GL_MIRRORED_REPEAT's fold into [0, 1] (lp_build_coord_mirror): |2 (s/2 - rint(s/2))|,
    float32, NaN -> 0."""
    half = (s * f32(0.5)).astype(f32)
    folded = (half - np.rint(half)).astype(f32)
    folded = np.abs(folded + folded)
    return np.where(np.isnan(folded), f32(0), folded)


def _scaled(s, size):
    return (s * size.astype(f32)).astype(f32)


def float_nearest_axis(s, size, pot, wrap):
    """The texel along one axis of the float path's nearest filter (lp_bld_sample_soa.c
    lp_build_sample_wrap_nearest): mirror: trunc(fold(s) size) below size; repeat, POT:
    floor(s size) masked; repeat, NPOT: trunc(fract(s) size), fract below 1; clamp:
    trunc(s size) clamped."""
    if wrap == "mirror":
        return np.minimum(cvt_trunc(_scaled(_mirror(s), size)), size - 1)
    if wrap == "repeat" and pot:
        return cvt_trunc(np.floor(_scaled(s, size))) & (size - 1)
    if wrap == "repeat":
        fraction = (s - np.floor(s)).astype(f32)
        fraction = np.where(fraction < BELOW_ONE, fraction, BELOW_ONE)      # NaN too
        return cvt_trunc(_scaled(fraction, size))
    return np.clip(cvt_trunc(_scaled(s, size)), 0, size - 1)


def float_linear_axis(s, size, pot, wrap):
    """(i0, i1, weight (N, 1) float32) along one axis of the float path's linear filter
    (lp_build_sample_wrap_linear): x = s size - 1/2 (s folded for mirror, its fraction for
    NPOT repeat, s size clamped to [1/2, size - 1/2] for clamp), i0 = floor(x), weight the
    float32 fraction, then the wrap's edge rules."""
    if wrap == "mirror":
        x = (_scaled(_mirror(s), size) - f32(0.5)).astype(f32)
    elif wrap == "repeat" and not pot:
        x = (_scaled((s - np.floor(s)).astype(f32), size) - f32(0.5)).astype(f32)
    elif wrap == "repeat":
        x = (_scaled(s, size) - f32(0.5)).astype(f32)
    else:
        scaled = _scaled(s, size)
        x = np.where(scaled < size, scaled, size.astype(f32))            # NaN -> size
        x = np.maximum((x - f32(0.5)).astype(f32), f32(0))
    whole = np.floor(x)
    i, weight = cvt_trunc(whole), (x - whole).astype(f32)[:, None]
    if wrap == "mirror":
        return np.maximum(i, 0), np.minimum(i + 1, size - 1), weight
    if wrap == "repeat" and pot:
        return i & (size - 1), (i + 1) & (size - 1), weight
    if wrap == "repeat":
        i0 = np.where(x < 0, size - 1, i)
        return i0, np.where(i0 != size - 1, i0 + 1, 0), weight
    return i, np.minimum(i + 1, size - 1), weight


def float_lerp(weight, a, b):
    """The float path's lerp: one fused multiply-add, a + w (b - a) (lp_build_mad)."""
    return fma32(weight, (b - a).astype(f32), a)


def float_level(store, level, s, t, image_filter, pots, wrap):
    """One level's float32 result (N, 4) on the float path: texels converted first, then
    blended in float32, x first on both rows, then y."""
    width, height = store.width[level], store.height[level]

    def texel(i, j):
        return unorm8_to_float(store.fetch(level, i, j))

    if image_filter == "nearest":
        return texel(float_nearest_axis(s, width, pots[0], wrap), float_nearest_axis(t, height, pots[1], wrap))
    x0, x1, wx = float_linear_axis(s, width, pots[0], wrap)
    y0, y1, wy = float_linear_axis(t, height, pots[1], wrap)
    return float_lerp(wy, float_lerp(wx, texel(x0, y0), texel(x1, y0)),
                      float_lerp(wx, texel(x0, y1), texel(x1, y1)))
