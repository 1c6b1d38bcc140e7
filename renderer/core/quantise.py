"""The quantisation rule, written once (notes 1.3 "Storing images", 5.2 "Outputs"): how linear
light L becomes an N-bit code under a transfer curve, as exact tables that both twins of the
output stage read (glsl/output/, reference/output/).

The curves (float64): linear V = L; sRGB (IEC 61966-2-1) V = 12.92 L for L <= 0.0031308, else
1.055 L^(1/2.4) - 0.055; gamma V = L^(1/gamma). Negative L and NaN count as 0.

The code of L at N bits (the undithered baseline, the nearest code in the encoded domain):
    linear:      floor(f32(f32(clamp(L, 0, 1) (2^N - 1)) + 0.5))   GL's unorm conversion at N
                 bits in float32 (gl_rules.to_unorm8 at N = 8: the framebuffer's rgba8)
    srgb, gamma: floor(V(clamp(L, 0, 1)) (2^N - 1) + 0.5), V in float64 of the float32 L
Neither twin evaluates a curve per pixel: `decision_points` lists, for k = 1 .. 2^N - 1, the
smallest float32 L whose code is at least k, so that code(L) = #{k : L >= t_k}, a count of
exact comparisons (in GLSL a walk from the curve's float32 estimate to the exact count;
np.searchsorted in NumPy). GPU, twin and the
float64 curve then agree on every input, on any GL implementation: llvmpipe's own sRGB
encoding is off by one level on 5 % of inputs (docs/llvmpipe/output.md), which GL allows.

Dithering and error diffusion work in linear light (so that a block's mean light is kept):
they choose between the two codes whose linear values `code_values` bracket L.
"""

from __future__ import annotations

from functools import lru_cache

import numpy as np

from renderer.core.output_settings import MAX_BITS, MIN_BITS, Transfer

SRGB_LINEAR_LIMIT = 0.0031308      # IEC 61966-2-1: below it the curve is linear
SRGB_SLOPE = 12.92
SRGB_A = 0.055                     # V = (1 + a) L^(1/2.4) - a
SRGB_EXPONENT = 2.4


def encode(light, transfer: Transfer) -> np.ndarray:
    """V(L) in float64: linear light to the encoded value (any L >= 0; negative and NaN -> 0)."""
    light = np.nan_to_num(np.asarray(light, dtype=np.float64), nan=0.0, posinf=np.inf, neginf=0.0)
    light = np.maximum(light, 0.0)
    if transfer.kind == "linear":
        return light
    if transfer.kind == "gamma":
        return np.power(light, 1.0 / transfer.gamma)
    if transfer.kind == "srgb":
        with np.errstate(invalid="ignore"):
            curve = (1.0 + SRGB_A) * np.power(light, 1.0 / SRGB_EXPONENT) - SRGB_A
        return np.where(light <= SRGB_LINEAR_LIMIT, SRGB_SLOPE * light, curve)
    raise ValueError(f"unknown transfer {transfer.kind!r}")


def decode(value, transfer: Transfer) -> np.ndarray:
    """L(V) in float64, the inverse of `encode` on [0, 1]."""
    value = np.maximum(np.asarray(value, dtype=np.float64), 0.0)
    if transfer.kind == "linear":
        return value
    if transfer.kind == "gamma":
        return np.power(value, transfer.gamma)
    if transfer.kind == "srgb":
        curve = np.power((value + SRGB_A) / (1.0 + SRGB_A), SRGB_EXPONENT)
        return np.where(value <= SRGB_SLOPE * SRGB_LINEAR_LIMIT, value / SRGB_SLOPE, curve)
    raise ValueError(f"unknown transfer {transfer.kind!r}")


def _check_bits(bits: int) -> int:
    if not MIN_BITS <= int(bits) <= MAX_BITS:
        raise ValueError(f"bits must be between {MIN_BITS} and {MAX_BITS}, got {bits}")
    return int(bits)


def code_of(light, transfer: Transfer, bits: int) -> np.ndarray:
    """The code (int64) of each float32 L: the rule of the module docstring, evaluated
    directly (slow, exact; `decision_points` is made from it, tests hold both to it)."""
    top = (1 << _check_bits(bits)) - 1
    light = np.asarray(light, dtype=np.float32)
    clamped = np.clip(np.nan_to_num(light, nan=0.0), np.float32(0), np.float32(1))
    if transfer.kind == "linear":                     # float32 arithmetic, as GL's conversion
        scaled = (clamped * np.float32(top)).astype(np.float32) + np.float32(0.5)
        return np.floor(scaled.astype(np.float32)).astype(np.int64)
    return np.floor(encode(clamped, transfer) * top + 0.5).astype(np.int64)


_ONE_BITS = int(np.float32(1.0).view(np.uint32))


@lru_cache(maxsize=32)
def decision_points(transfer: Transfer, bits: int) -> np.ndarray:
    """(2^N - 1,) float32, read-only: t_k (k = 1 .. 2^N - 1) is the smallest float32 L >= 0
    with code_of(L) >= k, found by bisection on the bit patterns of [0, 1] (ordered like the
    floats they stand for). code(L) = #{k : L >= t_k} = np.searchsorted(t, L, 'right')."""
    top = (1 << _check_bits(bits)) - 1
    k = np.arange(1, top + 1, dtype=np.int64)
    low = np.zeros(top, dtype=np.int64)                    # code(low) < k (low = 0: code 0)
    high = np.full(top, _ONE_BITS, dtype=np.int64)         # code(high) >= k (1.0: the top)
    while np.any(high - low > 1):
        middle = (low + high) // 2
        reached = code_of(middle.astype(np.uint32).view(np.float32), transfer, bits) >= k
        high = np.where(reached, middle, high)
        low = np.where(reached, low, middle)
    points = high.astype(np.uint32).view(np.float32)
    points.flags.writeable = False
    return points


@lru_cache(maxsize=32)
def code_values(transfer: Transfer, bits: int) -> np.ndarray:
    """(2^N,) float32, read-only: the linear light each code stands for, L(k / (2^N - 1))
    rounded to float32; 0 and 1 at the ends. Dithering chooses between the neighbours that
    bracket L: c0 = the largest k with code_values[k] <= L, and c0 + 1."""
    top = (1 << _check_bits(bits)) - 1
    values = decode(np.arange(top + 1, dtype=np.float64) / top, transfer).astype(np.float32)
    values.flags.writeable = False
    return values
