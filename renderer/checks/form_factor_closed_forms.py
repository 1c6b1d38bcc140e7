"""Closed-form form factors between rectangles, the references the radiosity method's form
factors are held to (issue 33). The form factor F_ij is the fraction of the energy leaving a
diffuse (Lambertian) surface i that arrives at surface j:

    F_ij = (1 / A_i) ∫_Ai ∫_Aj cos θ_i cos θ_j / (π r²) dA_j dA_i,

with θ_i, θ_j the angles between each surface's normal and the line between the two points, r
its length. Reciprocity: A_i F_ij = A_j F_ji. The two closed forms are configurations C-11 and
C-14 of J. R. Howell, "A Catalog of Radiation Heat Transfer Configuration Factors" (3rd ed.,
the catalogue behind Siegel and Howell's "Thermal Radiation Heat Transfer"):

    element_to_rectangle(a, b, c)        B-3: from a differential element to a parallel a × b
                                         rectangle c away, one corner on the element's normal
                                         (what one hemicube measures)
    parallel_rectangles(a, b, c)         C-11: two directly opposed parallel a × b rectangles
                                         a distance c apart
    perpendicular_rectangles(l, w, h)    C-14: from an l × w rectangle to an l × h one at right
                                         angles to it, the two sharing their edge of length l
    rectangles_by_quadrature(...)        the defining double integral by Gauss–Legendre
                                         quadrature, for any two rectangles: the closed forms'
                                         independent check (tests/test_form_factor_closed_forms.py)

In float64; no GL, no scene: pure geometry, as the radiosity's tests need it.
"""

from __future__ import annotations

import math

import numpy as np


def element_to_rectangle(a: float, b: float, c: float) -> float:
    """B-3: F from a differential element to a parallel a × b rectangle c away whose corner is
    on the element's normal. With A = a / c, B = b / c:
    F = 1 / (2π) [A / √(1 + A²) atan(B / √(1 + A²)) + B / √(1 + B²) atan(A / √(1 + B²))]."""
    if not (a > 0 and b > 0 and c > 0):
        raise ValueError(f"the sides and the distance must be positive, got {a}, {b}, {c}")
    A, B = a / c, b / c
    a1, b1 = math.sqrt(1 + A * A), math.sqrt(1 + B * B)
    return (A / a1 * math.atan(B / a1) + B / b1 * math.atan(A / b1)) / (2 * math.pi)


def parallel_rectangles(a: float, b: float, c: float) -> float:
    """C-11: F from one a × b rectangle to a parallel, directly opposed one c away (the same
    both ways, the areas being equal). With X = a / c, Y = b / c:
    F = 2 / (π X Y) [ln √((1 + X²)(1 + Y²) / (1 + X² + Y²)) + X √(1 + Y²) atan(X / √(1 + Y²))
        + Y √(1 + X²) atan(Y / √(1 + X²)) - X atan X - Y atan Y]."""
    if not (a > 0 and b > 0 and c > 0):
        raise ValueError(f"the sides and the distance must be positive, got {a}, {b}, {c}")
    X, Y = a / c, b / c
    x1, y1 = math.sqrt(1 + X * X), math.sqrt(1 + Y * Y)
    # (1 + X²)(1 + Y²) / (1 + X² + Y²) = 1 + X² Y² / (1 + X² + Y²): log1p, exact where the
    # rectangles are far apart and the ratio is within rounding of 1
    return 2 / (math.pi * X * Y) * (
        0.5 * math.log1p(X * X * Y * Y / (1 + X * X + Y * Y))
        + X * y1 * math.atan(X / y1) + Y * x1 * math.atan(Y / x1)
        - X * math.atan(X) - Y * math.atan(Y))


def perpendicular_rectangles(l: float, w: float, h: float) -> float:
    """C-14: F from an l × w rectangle to an l × h one standing at right angles on it along
    their common edge of length l. With W = w / l, H = h / l:
    F = 1 / (π W) [W atan(1 / W) + H atan(1 / H) - √(H² + W²) atan(1 / √(H² + W²))
        + ¼ ln((1 + W²)(1 + H²) / (1 + W² + H²)
                 · (W² (1 + W² + H²) / ((1 + W²)(W² + H²)))^(W²)
                 · (H² (1 + H² + W²) / ((1 + H²)(H² + W²)))^(H²))].
    The logarithm is taken term by term (its powers overflow for long rectangles)."""
    if not (l > 0 and w > 0 and h > 0):
        raise ValueError(f"the sides must be positive, got {l}, {w}, {h}")
    W, H = w / l, h / l
    W2, H2 = W * W, H * H
    r = math.sqrt(W2 + H2)
    # each ratio as 1 + something, through log1p (they are within rounding of 1 for thin or
    # long rectangles): (1 + W²)(1 + H²) = (1 + W² + H²) + W² H², and
    # W² (1 + W² + H²) = (1 + W²)(W² + H²) - H²
    log = (math.log1p(W2 * H2 / (1 + W2 + H2))
           + W2 * math.log1p(-H2 / ((1 + W2) * (W2 + H2)))
           + H2 * math.log1p(-W2 / ((1 + H2) * (H2 + W2))))
    return (W * math.atan(1 / W) + H * math.atan(1 / H) - r * math.atan(1 / r) + log / 4) / (math.pi * W)


def rectangles_by_quadrature(origin_i, u_i, v_i, origin_j, u_j, v_j, points: int = 32) -> float:
    """F_ij by the defining integral, Gauss–Legendre with `points` nodes along each of the four
    parameters: rectangle i is origin_i + s u_i + t v_i (s, t in [0, 1]), its normal u_i × v_i
    (unit), and so j; each normal must face the other rectangle. Points of the two that touch
    (an edge they share) make the integrand singular there: the sum then converges only as a
    power of `points`, which tests/test_form_factor_closed_forms.py measures."""
    nodes, weights = np.polynomial.legendre.leggauss(points)
    t, w = (nodes + 1) / 2, weights / 2                                  # on [0, 1]

    def samples(origin, u, v):
        origin, u, v = (np.asarray(x, np.float64) for x in (origin, u, v))
        s1, s2 = np.meshgrid(t, t, indexing="ij")
        p = origin + s1[..., None] * u + s2[..., None] * v
        normal = np.cross(u, v)
        area = float(np.linalg.norm(normal))
        return p.reshape(-1, 3), np.outer(w, w).ravel() * area, normal / area, area

    p_i, w_i, n_i, area_i = samples(origin_i, u_i, v_i)
    p_j, w_j, n_j, _ = samples(origin_j, u_j, v_j)
    total = 0.0
    for k in range(0, len(p_i), 256):                                    # bounded temporaries
        d = p_j[None, :, :] - p_i[k:k + 256, None, :]
        r2 = np.einsum("abc,abc->ab", d, d)
        cos_i = np.einsum("abc,c->ab", d, n_i)
        cos_j = -np.einsum("abc,c->ab", d, n_j)
        kernel = np.clip(cos_i, 0, None) * np.clip(cos_j, 0, None) / (np.pi * r2 * r2)
        total += float(w_i[k:k + 256] @ kernel @ w_j)
    return total / area_i
