"""# Twin: glsl/raytrace/optics.glsl

Reflection, refraction, Schlick's Fresnel approximation and the self-intersection offset
(docs/conventions.md, "Rays"), vectorised over rays, with the GLSL's formulas in the GLSL's order.
D is the incoming direction (towards the surface), N the unit normal on the incoming side
(D.N <= 0), eta = n1 / n2. Computed in the float dtype of D (float64 for integer input). The
offset works on the bits of float32 (the GLSL's) or float64 points (the float64 twin, the
ground truth): the same rule in units of the last place of either, its constants below.
"""

from __future__ import annotations

import numpy as np

from reference.glsl_builtins import dot as _dot

RAY_OFFSET_ORIGIN = np.float32(1.0 / 32.0)
RAY_OFFSET_FLOAT_SCALE = np.float32(1.0 / 65536.0)
RAY_OFFSET_INT_SCALE = np.float32(256.0)
# float64: the same number of ulps (int_scale) and origin; near 0 the additive step shrinks
# with the epsilon, 2^-16 eps64 / eps32 = 2^-45, so that it stays the same multiple of the
# ulps of the points near 1/32 (float64 points need not move as far as float32 ones).
_EPS_RATIO = np.finfo(np.float64).eps / np.finfo(np.float32).eps          # 2^-29
_OFFSET = {  # dtype: (its integer view, origin, float_scale, int_scale)
    np.dtype(np.float32): (np.int32, RAY_OFFSET_ORIGIN, RAY_OFFSET_FLOAT_SCALE, RAY_OFFSET_INT_SCALE),
    np.dtype(np.float64): (np.int64, np.float64(RAY_OFFSET_ORIGIN),
                           np.float64(RAY_OFFSET_FLOAT_SCALE) * _EPS_RATIO, np.float64(RAY_OFFSET_INT_SCALE)),
}


def _float_dtype(*arrays) -> np.dtype:
    dtype = np.result_type(*arrays)
    return dtype if dtype.kind == "f" else np.dtype(np.float64)


def _as(dtype, *values):
    return [np.asarray(v, dtype=dtype) for v in values]


def ray_reflect(D, N):
    """R = D - 2 (D.N) N (D any length, N unit)."""
    dtype = _float_dtype(D, N)
    D, N = _as(dtype, D, N)
    return D - (dtype.type(2) * _dot(D, N))[..., None] * N


def ray_refract(D, N, eta):
    """Snell's law for unit D, N with D.N <= 0: (refracted, T). cos_i = -D.N,
    k = 1 - eta^2 (1 - cos_i^2); where k < 0 (total internal reflection) refracted is False and T
    the reflection of D, else T = eta D + (eta cos_i - sqrt(k)) N."""
    dtype = _float_dtype(D, N)
    D, N, eta = _as(dtype, D, N, eta)
    one = dtype.type(1)
    cos_i = -_dot(D, N)
    k = one - eta * eta * (one - cos_i * cos_i)
    refracted = k >= 0
    root = np.sqrt(np.where(refracted, k, 0)).astype(dtype)
    T = eta[..., None] * D + (eta * cos_i - root)[..., None] * N
    return refracted, np.where(refracted[..., None], T, ray_reflect(D, N))


def fresnel_schlick(D, N, eta):
    """Schlick: R0 + (1 - R0) (1 - cos)^5, R0 = ((1 - eta) / (1 + eta))^2, cos on the less dense
    side (cos_i for eta <= 1, cos_t for eta > 1), 1 under total internal reflection."""
    dtype = _float_dtype(D, N)
    D, N, eta = _as(dtype, D, N, eta)
    one = dtype.type(1)
    r0 = (one - eta) / (one + eta)
    r0 = r0 * r0
    c = -_dot(D, N)
    eta = np.broadcast_to(eta, c.shape)
    k = one - eta * eta * (one - c * c)
    tir = (eta > 1) & (k < 0)
    c = np.where(eta > 1, np.sqrt(np.where(k < 0, 0, k)).astype(dtype), c)
    m = one - c
    m2 = m * m
    return np.where(tir, one, r0 + (one - r0) * (m2 * m2 * m)).astype(dtype)


def fresnel_exact(D, N, eta):
    """The Fresnel equations, unpolarised, eta = n1 / n2: (r_s^2 + r_p^2) / 2 with
    r_s = (eta cos_i - cos_t) / (eta cos_i + cos_t), r_p = (cos_i - eta cos_t) / (cos_i + eta cos_t),
    1 under total internal reflection."""
    dtype = _float_dtype(D, N)
    D, N, eta = _as(dtype, D, N, eta)
    one, half = dtype.type(1), dtype.type(0.5)
    c = -_dot(D, N)
    eta = np.broadcast_to(eta, c.shape)
    k = one - eta * eta * (one - c * c)
    t = np.sqrt(np.where(k < 0, 0, k)).astype(dtype)
    with np.errstate(invalid="ignore", divide="ignore"):
        rs = (eta * c - t) / (eta * c + t)
        rp = (c - eta * t) / (c + eta * t)
    return np.where(k < 0, one, half * (rs * rs + rp * rp)).astype(dtype)


def offset_ray_origin(p, n):
    """Waechter and Binder, Ray Tracing Gems ch. 6: p moved along the unit geometric normal n (on
    the side the new ray leaves to) by int(256 n) ulps per coordinate (the float bits as
    integers), or by n / 65536 where |p| < 1/32 (n 2^-45 in float64). float32 in and out, bit
    for bit the GLSL; float64 points stay float64."""
    dtype = np.dtype(np.float64) if np.asarray(p).dtype == np.float64 else np.dtype(np.float32)
    integer, origin, float_scale, int_scale = _OFFSET[dtype]
    p = np.asarray(p, dtype=dtype)
    n = np.asarray(n, dtype=dtype)
    of_i = (int_scale * n).astype(integer)                      # truncation towards zero
    with np.errstate(over="ignore"):
        bits = p.view(integer) + np.where(p < 0, -of_i, of_i)
    p_i = bits.astype(integer).view(dtype)
    p_f = p + float_scale * n
    return np.where(np.abs(p) < origin, p_f, p_i)
