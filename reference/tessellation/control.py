"""# Twin: glsl/tess_control.glsl

Tessellation control (notes 4.1; issue 34), as the control stage runs on each triangle patch of
a curved surface: the patch's corners to world space (u_model), and for each edge the level
that keeps the surface's deviation from its chords under the target error on the screen, the
rule of renderer/core/tessellation.py, in float32 and in the shader's order of operations
(glsl_builtins: dot z first, a matrix times a vector column by column, no fused multiply-add):

    mid = P (V ((a + b) 0.5, 1));  k = H P11 / (2 w_mid);  s = (target / k) / R
    c = sqrt(dot(a - b, a - b));  d = sqrt(max(R^2 - c^2 0.25, 0))
    level = clamp(c (1 - s) / ((2 d) sqrt(s (2 - s))), 1, max)

A fixed level (u_fixed_level > 0) is every edge's. Else 1 for a flat surface (R = 0) or s >= 1, the largest level for a midpoint at or behind the eye or
a chord across the sphere; outer[i] is the edge opposite corner i, inner the largest outer.

PN triangles (SURFACE_PN; `pn_net`, `pn_patch_levels`): each edge's offsets o_ab = N_a ((-w) / 3)
(w = dot(P_b - P_a, N_a); 1/3 multiplied as float32 0.33333334), zero on a straight edge; the
centre's ((((o0 + o1) + o2) + o3) + o4) + o5) 0.25; each edge's mid normal
normalize((N_a + N_b) - v e), e = P_b - P_a, v = (2 dot(e, N_a + N_b)) / dot(e, e) (0 for a
point edge). An edge's level: m = max(|M (o_ba - 2 o_ab, 0)|, |M (o_ab - 2 o_ba, 0)|), then
sqrt((0.75 m) / e) with e = target / k at the edge's midpoint, clamped (max and min as GLSL's
on NaN: the number); the inner level also the interior's, at the centroid ((p0 + p1) + p2) / 3.

Inputs: patches' corners (P, 3, 3) object space, the uniforms as a ControlUniforms.
Output: (P, 4) float32 levels: outer[0..2], inner[0] (gl_TessLevelOuter / gl_TessLevelInner).
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from reference.glsl_builtins import dot, length, matrix_times, normalize


@dataclass(frozen=True)
class ControlUniforms:
    model: np.ndarray                  # (4, 4) u_model
    view: np.ndarray                   # (4, 4) u_view
    projection: np.ndarray             # (4, 4) u_projection
    viewport_height: float             # u_viewport_height, pixels
    target_error: float                # u_target_error, pixels
    surface_radius: float              # u_surface_radius, world units (0: flat)
    max_level: float                   # u_max_level
    fixed_level: float = 0.0           # u_fixed_level: > 0, every level (not by need)


def _homogeneous(points32: np.ndarray) -> np.ndarray:
    return np.concatenate([points32, np.ones(points32.shape[:-1] + (1,), np.float32)], axis=-1)


def _clip_w(world: np.ndarray, u: ControlUniforms) -> np.ndarray:
    """clip_w: P (V (world, 1)), its w."""
    return matrix_times(u.projection, matrix_times(u.view, _homogeneous(world)))[..., 3]


def _world_error(w: np.ndarray, u: ControlUniforms) -> np.ndarray:
    """world_error: the target over the pixels a world unit spans at clip w, H P11 / (2 w)."""
    f = np.float32
    with np.errstate(divide="ignore", invalid="ignore", over="ignore"):
        pixels_per_unit = f(u.viewport_height) * f(u.projection[1, 1]) / (f(2) * w)
        return f(u.target_error) / pixels_per_unit


def edge_levels(a: np.ndarray, b: np.ndarray, u: ControlUniforms) -> np.ndarray:
    """(...,) float32: the level of each edge from world points a to b (..., 3) float32."""
    f = np.float32
    radius, high = f(u.surface_radius), f(u.max_level)
    shape = a.shape[:-1]
    if f(u.fixed_level) > 0:
        return np.full(shape, f(u.fixed_level), f)
    if not radius > 0:
        return np.ones(shape, f)
    w = _clip_w((a + b) * f(0.5), u)
    with np.errstate(divide="ignore", invalid="ignore", over="ignore"):
        s = _world_error(w, u) / radius
        chord = a - b
        c2 = dot(chord, chord)
        c = np.sqrt(c2)
        d = np.sqrt(np.maximum(radius * radius - c2 * f(0.25), f(0)))
        level = c * (f(1) - s) / (f(2) * d * np.sqrt(s * (f(2) - s)))
    level = np.minimum(np.maximum(level, f(1)), high)
    level = np.where(d > 0, level, high)
    level = np.where(s < 1, level, f(1))
    return np.where(w > 0, level, high).astype(f)


ONE_THIRD = np.float32(1.0 / 3.0)      # glsl/tess_control.glsl's
PN_CURVE_BOUND = np.float32(0.75)


def _pn_offset(pa, na, pb):
    return na * ((-dot(pb - pa, na)) * ONE_THIRD)[..., None]


def _pn_mid_normal(pa, na, pb, nb):
    f = np.float32
    e = pb - pa
    e2 = dot(e, e)
    with np.errstate(divide="ignore", invalid="ignore"):
        v = np.where(e2 > 0, f(2) * dot(e, na + nb) / e2, f(0)).astype(f)
    return normalize((na + nb) - v[..., None] * e)


def pn_net(corners: np.ndarray, normals: np.ndarray, straight: np.ndarray):
    """A PN patch's net as the control stage makes it: offsets (P, 6, 3) (edge k's o_ij, o_ji,
    i = k + 1, j = k + 2 mod 3), the centre's (P, 3), the edges' mid normals (P, 3, 3); from
    corners and normals (P, 3, 3) and straight (P, 3) (renderer/core/tessellation.py PatchNet)."""
    c, n = np.asarray(corners, np.float32), np.asarray(normals, np.float32)
    offsets, mids = [], []
    for k in range(3):
        i, j = (k + 1) % 3, (k + 2) % 3
        curved = ~(np.asarray(straight)[:, k] > 0.5)[:, None]
        offsets.append(np.where(curved, _pn_offset(c[:, i], n[:, i], c[:, j]), np.float32(0)))
        offsets.append(np.where(curved, _pn_offset(c[:, j], n[:, j], c[:, i]), np.float32(0)))
        mids.append(_pn_mid_normal(c[:, i], n[:, i], c[:, j], n[:, j]))
    centre = offsets[0]
    for o in offsets[1:]:
        centre = centre + o
    return (np.stack(offsets, axis=1).astype(np.float32), (centre * np.float32(0.25)).astype(np.float32),
            np.stack(mids, axis=1).astype(np.float32))


def _world_length(model, d):
    return length(matrix_times(model, np.concatenate([d, np.zeros(d.shape[:-1] + (1,), np.float32)], axis=-1))[..., :3])


def _pn_level(m, world, u: ControlUniforms):
    f = np.float32
    w = _clip_w(world, u)
    with np.errstate(divide="ignore", invalid="ignore", over="ignore"):
        level = np.sqrt(PN_CURVE_BOUND * m / _world_error(w, u))
    level = np.fmin(np.fmax(level, f(1)), f(u.max_level))
    return np.where(w > 0, level, f(u.max_level)).astype(f)


def pn_patch_levels(corners: np.ndarray, offsets: np.ndarray, centre: np.ndarray,
                    u: ControlUniforms) -> np.ndarray:
    """(P, 4) float32 levels of PN patches: corners (P, 3, 3) object space, their net
    (`pn_net`'s offsets and centre)."""
    f = np.float32
    world = matrix_times(u.model, _homogeneous(np.asarray(corners, f)))[..., :3]
    p0, p1, p2 = world[:, 0], world[:, 1], world[:, 2]
    o = [offsets[:, k] for k in range(6)]
    if f(u.fixed_level) > 0:
        return np.full((len(corners), 4), f(u.fixed_level), f)
    outer = []
    for k, (a, b) in enumerate(((p1, p2), (p2, p0), (p0, p1))):
        o_ab, o_ba = o[2 * k], o[2 * k + 1]
        m = np.fmax(_world_length(u.model, o_ba - f(2) * o_ab), _world_length(u.model, o_ab - f(2) * o_ba))
        outer.append(_pn_level(m, (a + b) * f(0.5), u))
    inner = np.fmax(np.fmax(outer[0], outer[1]), outer[2])
    m = np.fmax(np.fmax(_world_length(u.model, (o[3] + o[0]) - f(2) * centre),
                        _world_length(u.model, (o[5] + o[2]) - f(2) * centre)),
                _world_length(u.model, (o[1] + o[4]) - f(2) * centre))
    inner = np.fmax(inner, _pn_level(m, ((p0 + p1) + p2) * ONE_THIRD, u))
    return np.stack([*outer, inner], axis=1).astype(f)


def displaced_tangents(corners: np.ndarray, uvs: np.ndarray):
    """A displaced patch's dP/ds and dP/dt (P, 3) each, from its corners (P, 3, 3) and UVs
    (P, 3, 2): e1 = c1 - c0, e2 = c2 - c0, d1, d2 alike; det = d1.x d2.y - d2.x d1.y,
    r = 1 / det (0 where det is 0); (e1 d2.y - e2 d1.y) r and (e2 d1.x - e1 d2.x) r."""
    f = np.float32
    c, w = np.asarray(corners, f), np.asarray(uvs, f)
    e1, e2 = c[:, 1] - c[:, 0], c[:, 2] - c[:, 0]
    d1, d2 = w[:, 1] - w[:, 0], w[:, 2] - w[:, 0]
    det = d1[:, 0] * d2[:, 1] - d2[:, 0] * d1[:, 1]
    with np.errstate(divide="ignore"):
        r = np.where(det != 0, f(1) / det, f(0)).astype(f)[:, None]
    return ((e1 * d2[:, 1:2] - e2 * d1[:, 1:2]) * r).astype(f), ((e2 * d1[:, 0:1] - e1 * d2[:, 0:1]) * r).astype(f)


def displaced_patch_levels(corners: np.ndarray, normals: np.ndarray, uvs: np.ndarray, u: ControlUniforms,
                           height_size, slope: float, scale: float) -> np.ndarray:
    """(P, 4) float32 levels of displaced patches (renderer/core/tessellation.py's rule, the
    control stage's order): per edge, texels = max(|ub - ua| (W, H)); where the midpoint's w > 0
    min((texels (g s)) / (2 e), texels), s = S max(|M n_a|, |M n_b|); clamped."""
    f = np.float32
    if f(u.fixed_level) > 0:
        return np.full((len(corners), 4), f(u.fixed_level), f)
    world = matrix_times(u.model, _homogeneous(np.asarray(corners, f)))[..., :3]
    n, w = np.asarray(normals, f), np.asarray(uvs, f)
    size = np.asarray(height_size, f)
    outer = []
    for i, j in ((1, 2), (2, 0), (0, 1)):
        span = np.abs(w[:, j] - w[:, i]) * size
        texels = np.maximum(span[:, 0], span[:, 1])
        mid_w = _clip_w((world[:, i] + world[:, j]) * f(0.5), u)
        with np.errstate(divide="ignore", invalid="ignore", over="ignore"):
            e = _world_error(mid_w, u)
            s = f(scale) * np.fmax(_world_length(u.model, n[:, i]), _world_length(u.model, n[:, j]))
            need = np.fmin(texels * (f(slope) * s) / (f(2) * e), texels)
        level = np.where(mid_w > 0, need, texels)
        outer.append(np.fmin(np.fmax(level, f(1)), f(u.max_level)).astype(f))
    inner = np.fmax(np.fmax(outer[0], outer[1]), outer[2])
    return np.stack([*outer, inner], axis=1).astype(f)


def patch_levels(corners: np.ndarray, u: ControlUniforms) -> np.ndarray:
    """(P, 4) float32: outer[0..2], inner[0] of each patch's corners (P, 3, 3) object space."""
    world = matrix_times(u.model, _homogeneous(np.asarray(corners, np.float32)))[..., :3]
    p0, p1, p2 = world[:, 0], world[:, 1], world[:, 2]
    outer = np.stack([edge_levels(p1, p2, u), edge_levels(p2, p0, u), edge_levels(p0, p1, u)], axis=1)
    return np.concatenate([outer, np.maximum(np.maximum(outer[:, 0:1], outer[:, 1:2]), outer[:, 2:3])], axis=1)
