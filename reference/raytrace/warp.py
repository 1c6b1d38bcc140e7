"""# Twin: glsl/raytrace/warp.glsl

Warps of uniform points u in [0, 1)^2 (distributed_2d's, sampling.py) onto the domains the
distributed effects sample (docs/conventions.md, "Distributed sampling"), vectorised over
(..., 2) points, in the dtype of u (float32 as the GLSL, in its order of operations; float64
for the ground truth): the unit disc, the unit sphere, a Phong lobe; an orthonormal basis
about a direction; and each warp's density, for the chi-square tests. sin, cos and pow differ
from the GPU's by a few ulps, so warped points agree within that, not bit for bit.
"""

from __future__ import annotations

import numpy as np

PI = np.pi


def _t(u):
    u = np.asarray(u)
    return u.dtype.type if u.dtype.kind == "f" else np.float64


def square_to_disc(u) -> np.ndarray:
    """Shirley and Chiu's concentric map of the square onto the unit disc (density 1/pi);
    u = (0.5, 0.5) is the centre exactly."""
    t = _t(u)
    u = np.asarray(u, t)
    o = t(2) * u - t(1)
    x, y = o[..., 0], o[..., 1]
    wide = np.abs(x) > np.abs(y)
    quarter = t(PI / 4)
    with np.errstate(divide="ignore", invalid="ignore"):
        r = np.where(wide, x, y)
        theta = np.where(wide, quarter * (y / x), t(2) * quarter - quarter * (x / y))
    centre = (x == 0) & (y == 0)
    r = np.where(centre, t(0), r)
    theta = np.where(centre, t(0), theta)
    return np.stack([r * np.cos(theta), r * np.sin(theta)], -1).astype(t)


def square_to_cosine_hemisphere(u) -> np.ndarray:
    """Cosine-weighted on the hemisphere about +z (Malley's method; density cos alpha / pi):
    square_to_disc's point lifted, z = sqrt(max(0, 1 - x^2 - y^2)), as the GLSL."""
    p = square_to_disc(u)
    t = p.dtype.type
    z = np.sqrt(np.maximum(t(0), t(1) - (p[..., 0] * p[..., 0] + p[..., 1] * p[..., 1])))
    return np.concatenate([p, z[..., None]], -1)


def cosine_hemisphere_density(d) -> np.ndarray:
    """square_to_cosine_hemisphere's density (per steradian) at unit directions d (..., 3)."""
    return np.maximum(np.asarray(d, np.float64)[..., 2], 0.0) / PI


def square_to_sphere(u) -> np.ndarray:
    """Uniform on the unit sphere (density 1/(4 pi)): z = 1 - 2 u0, phi = 2 pi u1."""
    t = _t(u)
    u = np.asarray(u, t)
    z = t(1) - t(2) * u[..., 0]
    r = np.sqrt(np.maximum(t(0), t(1) - z * z))
    phi = t(2 * PI) * u[..., 1]
    return np.stack([r * np.cos(phi), r * np.sin(phi), z], -1).astype(t)


def minus_log_1m(u) -> np.ndarray:
    """-log(1 - u) for u in [0, 1) in u's dtype: float32 as the GLSL's warp_minus_log_1m (below
    1/16 the Taylor series u (1 + u/2 + ... + u^5/6), above it -log(1 - u)); float64 (the
    ground truth) -log1p(-u)."""
    t = _t(u)
    u = np.asarray(u, t)
    if t is np.float64:
        return -np.log1p(-u)
    series = u * (t(1) + u * (t(1 / 2) + u * (t(1 / 3) + u * (t(1 / 4) + u * (t(1 / 5) + u / t(6))))))
    with np.errstate(divide="ignore"):
        return np.where(u >= t(0.0625), -np.log(t(1) - u), series)


def one_minus_exp(x) -> np.ndarray:
    """1 - exp(-x) for x >= 0 in x's dtype: float32 as the GLSL's warp_one_minus_exp (below
    ln 2 the series x (1 - x/2 (1 - x/3 (... (1 - x/9)))), above it 1 - exp(-x)); float64 (the
    ground truth) -expm1(-x)."""
    t = _t(x)
    x = np.asarray(x, t)
    if t is np.float64:
        return -np.expm1(-x)
    s = t(1) - x / t(9)
    for n in range(8, 1, -1):
        s = t(1) - x / t(n) * s
    return np.where(x >= t(np.log(2.0)), t(1) - np.exp(-x), x * s)


def square_to_phong_lobe(u, exponent) -> np.ndarray:
    """Directions about +z with density (e + 1)/(2 pi) cos^e(alpha): cos alpha =
    (1 - u0)^(1/(e + 1)), phi = 2 pi u1, computed as the GLSL: 1 - cos alpha = one_minus_exp(
    minus_log_1m(u0) / (e + 1)), sin alpha = sqrt((1 - cos)(1 + cos)), which keeps a narrow
    lobe's angles precise; `exponent` broadcasts against u's points."""
    t = _t(u)
    u = np.asarray(u, t)
    e = np.asarray(exponent, t)
    one_minus_cos = one_minus_exp(minus_log_1m(u[..., 0]) / (e + t(1)))
    cos_alpha = t(1) - one_minus_cos
    sin_alpha = np.sqrt(one_minus_cos * (t(2) - one_minus_cos))
    phi = t(2 * PI) * u[..., 1]
    return np.stack([sin_alpha * np.cos(phi), sin_alpha * np.sin(phi), cos_alpha], -1).astype(t)


def orthonormal_basis(n):
    """(b1, b2) with (b1, b2, n) a right-handed orthonormal basis for unit n (..., 3): Duff et
    al., JCGT 6(1) 2017, as the GLSL (n.z = 0 counts as positive)."""
    n = np.asarray(n)
    t = _t(n)
    x, y, z = n[..., 0], n[..., 1], n[..., 2]
    s = np.where(z >= 0, t(1), t(-1))
    a = t(-1) / (s + z)
    b = x * y * a
    b1 = np.stack([t(1) + s * x * x * a, s * b, -s * x], -1)
    b2 = np.stack([b, s + y * y * a, -y], -1)
    return b1.astype(t), b2.astype(t)


def disc_density(p) -> np.ndarray:
    """square_to_disc's density at points p (..., 2): 1/pi inside the unit disc, else 0."""
    p = np.asarray(p, np.float64)
    return np.where((p ** 2).sum(-1) <= 1.0, 1.0 / PI, 0.0)


def sphere_density(d) -> np.ndarray:
    """square_to_sphere's density (per steradian) at unit directions d (..., 3)."""
    return np.full(np.shape(d)[:-1], 1.0 / (4.0 * PI))


def phong_lobe_density(d, exponent) -> np.ndarray:
    """square_to_phong_lobe's density (per steradian) at unit directions d (..., 3)."""
    cos_alpha = np.asarray(d, np.float64)[..., 2]
    return np.where(cos_alpha > 0, (exponent + 1.0) / (2.0 * PI) * np.maximum(cos_alpha, 0.0) ** exponent, 0.0)
