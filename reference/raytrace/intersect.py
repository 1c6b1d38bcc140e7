"""# Twin: glsl/raytrace/intersect.glsl

Ray intersections (docs/conventions.md, "Rays"), vectorised over rays: the ray P = O + s D
(D need not be unit length) against a plane P.N + d = 0, a sphere (P - C).(P - C) - r^2 = 0
and a triangle ABC, with the GLSL's formulas in the GLSL's order of operations.

Inputs:  O, D (..., 3) ray origins and directions; the surface's parameters (broadcast against
         the rays); s_min, s_max (scalars or broadcast). Everything is computed in the float dtype
         of O and D (float64 for integer input).
Output:  (hit, s): bool (...) whether the nearest hit with s_min < s < s_max exists, and its s,
         or s_max where it misses (as the GLSL's `out float s`).
"""

from __future__ import annotations

import numpy as np

from reference.glsl_builtins import cross as _cross, dot as _dot, normalize as _normalize

# The kinds of surface a ray hits (trace.py's scene_hit; the GLSL's TRACE_MISS ... in trace.glsl).
MISS, SPHERE, PLANE, TRIANGLE = 0, 1, 2, 3


def _float_dtype(*arrays) -> np.dtype:
    dtype = np.result_type(*arrays)
    return dtype if dtype.kind == "f" else np.dtype(np.float64)


def _as(dtype, *values):
    return [np.asarray(v, dtype=dtype) for v in values]


def _select(hit, s, s_max):
    return hit, np.where(hit, s, np.broadcast_to(s_max, s.shape)).astype(s.dtype)


def ray_plane(O, D, N, d, s_min, s_max):
    """Plane P.N + d = 0 (N need not be unit): s = -(O.N + d) / (D.N); a ray parallel to the
    plane (D.N == 0, also one inside it) misses."""
    dtype = _float_dtype(O, D)
    O, D, N, d, s_min, s_max = _as(dtype, O, D, N, d, s_min, s_max)
    with np.errstate(divide="ignore", invalid="ignore"):
        denominator = _dot(D, np.broadcast_to(N, D.shape))
        s = -(_dot(O, np.broadcast_to(N, O.shape)) + d) / denominator
        hit = (denominator != 0) & (s > s_min) & (s < s_max)
    return _select(hit, s, s_max)


def plane_normal(N):
    return _normalize(np.asarray(N))


def _sphere_terms(O, D, C, r):
    """(f, a, delta, q) of Ray Tracing Gems ch. 7 (Haines, Guenther, Akenine-Moeller 2019) for
    rays O, D and a sphere C, r of one float dtype: f = O - C, a = D.D, b = f.D,
    delta = r^2 - |f - (b/a) D|^2 (eq. 7.6: the discriminant b^2 - a c over a, without its
    cancellation), q = -(b + sign(b) sqrt(a delta)) with sign(0) = +1 (eq. 7.7)."""
    dtype = O.dtype
    with np.errstate(divide="ignore", invalid="ignore", over="ignore"):
        f = O - C
        a = _dot(D, D)
        b = _dot(f, D)
        l = f - (b / a)[..., None] * D
        delta = r * r - _dot(l, l)
        sign = np.where(b >= 0, dtype.type(1), dtype.type(-1))
        q = -(b + sign * np.sqrt(np.maximum(a * delta, 0)))
    return f, a, delta, q


def sphere_discriminant(O, D, C, r):
    """r^2 - |f - (b/a) D|^2 with f = O - C, a = D.D, b = f.D: the discriminant b^2 - a c over a,
    in the robust form of Ray Tracing Gems ch. 7 (eq. 7.6)."""
    dtype = _float_dtype(O, D)
    return _sphere_terms(*_as(dtype, O, D, C, r))[2]


def ray_sphere_from(O, D, C, r, on_surface, s_min, s_max):
    """The nearest root in (s_min, s_max) of |O + s D - C|^2 = r^2, by Ray Tracing Gems ch. 7:
    delta = r^2 - |f - (b/a) D|^2 (eq. 7.6), q = -(b + sign(b) sqrt(a delta)), s0 = c / q,
    s1 = q / a (eq. 7.7, 7.8), sign(0) = +1. A tangent ray (delta == 0) hits; from inside, the
    far root. A ray that starts on the sphere (on_surface, per ray or for all; no offset): its
    origin is the root c / q, so the one other point it can meet is s1 = q / a (ahead when it
    goes inwards, b < 0; behind when it leaves outwards: a sphere is convex); c / q, which
    cancels there, is not used. One test for both kinds of ray, as the GLSL's."""
    dtype = _float_dtype(O, D)
    O, D, C, r, s_min, s_max = _as(dtype, O, D, C, r, s_min, s_max)
    f, a, delta, q = _sphere_terms(O, D, C, r)
    with np.errstate(divide="ignore", invalid="ignore", over="ignore"):
        c = _dot(f, f) - r * r
        s0 = c / q
        s1 = q / a
        near = np.where(on_surface, s1, np.minimum(s0, s1))
        far = np.where(on_surface, s1, np.maximum(s0, s1))
        near_hit = (near > s_min) & (near < s_max)
        far_hit = (far > s_min) & (far < s_max)
        hit = (delta >= 0) & (near_hit | far_hit)
        s = np.where(near_hit, near, far)
    return _select(hit, s, s_max)


def ray_sphere(O, D, C, r, s_min, s_max):
    """ray_sphere_from for rays that do not start on the sphere."""
    return ray_sphere_from(O, D, C, r, False, s_min, s_max)


def ray_sphere_from_surface(O, D, C, r, s_min, s_max):
    """ray_sphere_from for rays that start on the sphere."""
    return ray_sphere_from(O, D, C, r, True, s_min, s_max)


def sphere_normal(P, C, r):
    """The outward unit normal at points P on the sphere."""
    return (np.asarray(P) - C) / r


def ray_triangle(O, D, A, B, C, s_min, s_max):
    """Moeller-Trumbore (JGT 1997): (hit, s, uv) with uv (..., 2) the barycentric (u, v) of the
    hit point (1 - u - v) A + u B + v C ((0, 0) on a miss). Closed triangle (edges and vertices
    hit), both faces; det == 0 (parallel ray, degenerate triangle) misses."""
    dtype = _float_dtype(O, D)
    O, D, A, B, C, s_min, s_max = _as(dtype, O, D, A, B, C, s_min, s_max)
    shape = np.broadcast_shapes(O.shape, D.shape)
    O, D = np.broadcast_to(O, shape), np.broadcast_to(D, shape)
    with np.errstate(divide="ignore", invalid="ignore"):
        e1 = np.broadcast_to(B - A, shape)
        e2 = np.broadcast_to(C - A, shape)
        p = _cross(D, e2)
        det = _dot(e1, p)
        t = O - A
        u = _dot(t, p) / det
        q = _cross(t, e1)
        v = _dot(D, q) / det
        s = _dot(e2, q) / det
        hit = ((det != 0) & (u >= 0) & (v >= 0) & (u + v <= 1) & (s > s_min) & (s < s_max))
    uv = np.where(hit[..., None], np.stack([u, v], axis=-1), dtype.type(0))
    hit, s = _select(hit, s, s_max)
    return hit, s, uv


def triangle_normal(A, B, C):
    """The unit geometric normal of ABC, on the side from which A, B, C run counter-clockwise."""
    A, B, C = (np.asarray(v) for v in (A, B, C))
    return _normalize(_cross(B - A, C - A))
