"""# Twin: glsl/tess_evaluation.glsl

Tessellation evaluation (notes 4.1; issue 34), as the evaluation stage runs on each point the
tessellator makes (reference/tessellation/tessellator.py: gl_TessCoord (u, v, w)): the
patch's barycentric point p = (u c0 + v c1) + w c2 in float32, no fused multiply-add, placed on
the exact surface: on a sphere of centre C and radius r, n = normalize(p - C) (glsl_builtins:
v times the reciprocal of its length) and the point C + r n, the normal n; elsewhere p itself
with the corners' normals interpolated alike and normalised.

Inputs: gl_TessCoord (N, 3) float32, the patch corners (N, 3, 3) and normals (N, 3, 3) object
space for each point, the sphere (centre, radius) or None.
Output: (positions (N, 3), normals (N, 3)) float32, object space.
"""

from __future__ import annotations

import numpy as np

from reference.glsl_builtins import normalize


def barycentric(tess_coord: np.ndarray, corners: np.ndarray) -> np.ndarray:
    """(u c0 + v c1) + w c2 over (N, 3) tess coords and (N, 3, 3) corners, float32."""
    t = np.asarray(tess_coord, np.float32)
    c = np.asarray(corners, np.float32)
    return (t[:, 0:1] * c[:, 0] + t[:, 1:2] * c[:, 1]) + t[:, 2:3] * c[:, 2]


def evaluate(tess_coord: np.ndarray, corners: np.ndarray, normals: np.ndarray, sphere=None):
    """The points on the surface and their normals (module docstring)."""
    p = barycentric(tess_coord, corners)
    if sphere is None:
        return p, normalize(barycentric(tess_coord, normals))
    centre = np.asarray(sphere[0], np.float32)
    radius = np.float32(sphere[1])
    n = normalize(p - centre)
    return centre + radius * n, n
