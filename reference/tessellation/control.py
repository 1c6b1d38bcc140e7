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

Inputs: patches' corners (P, 3, 3) object space, the uniforms as a ControlUniforms.
Output: (P, 4) float32 levels: outer[0..2], inner[0] (gl_TessLevelOuter / gl_TessLevelInner).
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from reference.glsl_builtins import dot, matrix_times


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


def edge_levels(a: np.ndarray, b: np.ndarray, u: ControlUniforms) -> np.ndarray:
    """(...,) float32: the level of each edge from world points a to b (..., 3) float32."""
    f = np.float32
    radius, high = f(u.surface_radius), f(u.max_level)
    shape = a.shape[:-1]
    if f(u.fixed_level) > 0:
        return np.full(shape, f(u.fixed_level), f)
    if not radius > 0:
        return np.ones(shape, f)
    mid = matrix_times(u.projection, matrix_times(u.view, _homogeneous((a + b) * f(0.5))))
    w = mid[..., 3]
    with np.errstate(divide="ignore", invalid="ignore", over="ignore"):
        pixels_per_unit = f(u.viewport_height) * f(u.projection[1, 1]) / (f(2) * w)
        s = f(u.target_error) / pixels_per_unit / radius
        chord = a - b
        c2 = dot(chord, chord)
        c = np.sqrt(c2)
        d = np.sqrt(np.maximum(radius * radius - c2 * f(0.25), f(0)))
        level = c * (f(1) - s) / (f(2) * d * np.sqrt(s * (f(2) - s)))
    level = np.minimum(np.maximum(level, f(1)), high)
    level = np.where(d > 0, level, high)
    level = np.where(s < 1, level, f(1))
    return np.where(w > 0, level, high).astype(f)


def patch_levels(corners: np.ndarray, u: ControlUniforms) -> np.ndarray:
    """(P, 4) float32: outer[0..2], inner[0] of each patch's corners (P, 3, 3) object space."""
    world = matrix_times(u.model, _homogeneous(np.asarray(corners, np.float32)))[..., :3]
    p0, p1, p2 = world[:, 0], world[:, 1], world[:, 2]
    outer = np.stack([edge_levels(p1, p2, u), edge_levels(p2, p0, u), edge_levels(p0, p1, u)], axis=1)
    return np.concatenate([outer, np.maximum(np.maximum(outer[:, 0:1], outer[:, 1:2]), outer[:, 2:3])], axis=1)
