"""The texture-coordinate rules of the analytic shapes, written once (docs/conventions.md,
"Texture coordinates"): the primitives apply them to their vertices, the ray tracer and its
twin to their hits, so that a sphere or plane gets the same UVs both ways.

- Sphere, for the unit direction d from the centre (object space): longitude
  lambda = atan2(d.x, d.z), u = 1/2 + lambda / (2 pi) (u = 1/2 faces +z and grows to the
  right seen from +z), v = 1/2 + asin(d.y) / pi (1 at the north pole +y). The seam is
  lambda = +-pi, the -z side.
- Plane with normal n: T = the object x axis projected into the plane, normalised (the
  -z axis where |n.x| > PLANE_AXIS_SWITCH), B = n x T for unit n; u = p.T, v = p.B for the
  object-space point p (one unit, one repeat before uv_scale). For n = +y: T = +x, B = -z.

`weld_corners` is the seam rule for meshes: a vertex whose faces give it different UVs
becomes one vertex per UV (primitives, mesh files).
"""

from __future__ import annotations

import numpy as np

# Where the normal is this close to the x axis, T comes from the -z axis instead.
PLANE_AXIS_SWITCH = 0.999


def longitude_u(x, z) -> np.ndarray:
    """u of the longitude rule around the y axis: 1/2 + atan2(x, z) / (2 pi), in [0, 1]."""
    return 0.5 + np.arctan2(x, z) / (2.0 * np.pi)


def sphere_uv(directions) -> np.ndarray:
    """(N, 2) UVs of unit directions (N, 3) from a sphere's centre (the module's rule)."""
    d = np.asarray(directions, dtype=np.float64).reshape(-1, 3)
    u = longitude_u(d[:, 0], d[:, 2])
    v = 0.5 + np.arcsin(np.clip(d[:, 1], -1.0, 1.0)) / np.pi
    return np.stack([u, v], axis=1)


def plane_uv_axes(normal) -> tuple[np.ndarray, np.ndarray]:
    """(T, B), unit, of a plane with `normal` (any length but zero): u = p.T, v = p.B."""
    n = np.asarray(normal, dtype=np.float64)
    n = n / np.linalg.norm(n)
    axis = np.array([0.0, 0.0, -1.0]) if abs(n[0]) > PLANE_AXIS_SWITCH else np.array([1.0, 0.0, 0.0])
    t = axis - (axis @ n) * n
    t /= np.linalg.norm(t)
    return t, np.cross(n, t)


def plane_uv(points, normal) -> np.ndarray:
    """(N, 2) UVs of object-space points (N, 3) on a plane with `normal`."""
    t, b = plane_uv_axes(normal)
    p = np.asarray(points, dtype=np.float64).reshape(-1, 3)
    return np.stack([p @ t, p @ b], axis=1)


def weld_corners(faces: np.ndarray, corner_uvs: np.ndarray):
    """Vertices from per-corner UVs (F, 3, 2): one vertex per distinct (vertex, UV) among the
    faces' corners, so that a vertex splits where its corners' UVs differ (a seam). Returns
    (the source vertex of each new vertex, new faces, new UVs). Vertices keep their order
    (those no face uses are left out); a vertex's copies follow it, in the order faces first
    use them."""
    corner_vertex = faces.reshape(-1)
    uv = corner_uvs.reshape(-1, 2)
    count = len(corner_vertex)
    order = np.lexsort((np.arange(count), uv[:, 1], uv[:, 0], corner_vertex))
    vertex_sorted, uv_sorted = corner_vertex[order], uv[order]
    starts = np.ones(count, dtype=bool)
    starts[1:] = (vertex_sorted[1:] != vertex_sorted[:-1]) | (uv_sorted[1:] != uv_sorted[:-1]).any(axis=1)
    group = np.empty(count, dtype=np.int64)
    group[order] = np.cumsum(starts) - 1
    first = order[starts]                           # each group's first corner in face order
    by_vertex = np.lexsort((first, corner_vertex[first]))
    rank = np.empty_like(by_vertex)
    rank[by_vertex] = np.arange(len(by_vertex))
    return corner_vertex[first][by_vertex], rank[group].reshape(faces.shape), uv[first][by_vertex]
