"""Whether a triangle mesh bounds a convex solid, and which side its normals face.

The shadow planning (renderer/core/shadow_casting.py) leaves out what cannot shadow anything:
a convex solid cannot shadow its own outside where the outside faces the light, and with the
light inside it, it shadows neither its inside nor anything else inside it. This module finds
such meshes: `convex_body(mesh)` is the solid's face planes (object space) when

- the mesh is **closed**: after welding vertices that lie at one position (a UV seam, a pole's
  fan, a cube's per-face corners), every edge of a non-degenerate face is shared by exactly
  two faces that run it in opposite directions (a consistently wound, watertight surface), and
- it is **convex**: every vertex lies on the inner side of every face's plane, within
  CONVEX_TOLERANCE of the mesh's extent (a cube's two coplanar triangles per side count).

A mesh of more than MAX_FACE_VERTEX_CHECKS face-vertex pairs is not tested (None: treated as
not convex, which costs a pass, never a wrong shadow). Results are cached per Mesh object, so a
frame pays for a mesh once (renderer/core/mesh_cache.py), and by content, so that a scene of
thousands of objects made from one primitive pays for it once too.
"""

from __future__ import annotations

import hashlib
from dataclasses import dataclass

import numpy as np

from renderer.core.mesh_cache import per_mesh

CONVEX_TOLERANCE = 1e-9          # of the mesh's largest extent: a vertex this far out is "on" a plane
WELD_TOLERANCE = 1e-9            # of the extent: vertices this close are one (seams, poles)
MAX_FACE_VERTEX_CHECKS = 50_000_000
MAX_CACHED_CONTENTS = 1024       # mesh contents whose bodies are kept
CHUNK_VALUES = 1 << 22            # heights computed at once (32 MiB of float64)


@dataclass(frozen=True)
class ConvexBody:
    """A closed convex mesh's solid in its object space: the points p with
    normals @ p + offsets <= tolerance for every face (normals (F, 3) unit, pointing out of the
    solid; offsets (F,)); `normals_outward`: True where every vertex normal points out of the
    solid, False where every one points in, None where they are mixed."""
    normals: np.ndarray
    offsets: np.ndarray
    tolerance: float
    normals_outward: bool | None

    def contains(self, points: np.ndarray, model: np.ndarray | None = None) -> np.ndarray:
        """(N,) bool: the points (N, 3) lie in the solid (on its boundary counts). `model`
        (4, 4): the solid is the mesh through this affine matrix and the points are in its
        space (world); convexity and containment survive any invertible affine map."""
        p = np.asarray(points, dtype=np.float64).reshape(-1, 3)
        if model is not None:
            inverse = np.linalg.inv(np.asarray(model, dtype=np.float64))
            p = p @ inverse[:3, :3].T + inverse[:3, 3]
        return (p @ self.normals.T + self.offsets <= self.tolerance).all(axis=1)


@per_mesh
def convex_body(mesh) -> ConvexBody | None:
    """The mesh's convex solid (module docstring), or None when the mesh is open, not
    consistently wound, not convex, flat, or too large to test. Cached per Mesh object."""
    arrays = (np.ascontiguousarray(mesh.positions, dtype=np.float64),
              np.ascontiguousarray(mesh.normals, dtype=np.float64),
              np.ascontiguousarray(mesh.faces, dtype=np.int64))
    digest = hashlib.blake2b(b"".join(a.tobytes() + repr(a.shape).encode() for a in arrays)).digest()
    if digest not in _BY_CONTENT:
        if len(_BY_CONTENT) >= MAX_CACHED_CONTENTS:
            _BY_CONTENT.pop(next(iter(_BY_CONTENT)))          # the oldest
        _BY_CONTENT[digest] = _find_body(*arrays)
    return _BY_CONTENT[digest]


_BY_CONTENT: dict[bytes, ConvexBody | None] = {}     # content digest -> body (bounded)


def _find_body(positions: np.ndarray, normals: np.ndarray, faces: np.ndarray) -> ConvexBody | None:
    if len(faces) < 4 or len(faces) * len(positions) > MAX_FACE_VERTEX_CHECKS:
        return None
    extent = float(np.ptp(positions, axis=0).max()) if len(positions) else 0.0
    if not extent > 0.0 or not np.isfinite(extent):
        return None
    welded = weld(positions, WELD_TOLERANCE * extent)[faces]
    keep = (welded[:, 0] != welded[:, 1]) & (welded[:, 1] != welded[:, 2]) & (welded[:, 0] != welded[:, 2])
    corners = positions[faces[keep]]
    face_normals = np.cross(corners[:, 1] - corners[:, 0], corners[:, 2] - corners[:, 0])
    length = np.linalg.norm(face_normals, axis=1)
    solid = length > 0.0
    if not solid.any() or not _closed(welded[keep][solid]):
        return None
    n = face_normals[solid] / length[solid, None]
    d = -np.einsum("ij,ij->i", n, corners[solid, 0])
    tolerance = CONVEX_TOLERANCE * extent
    lowest, highest = _height_range(positions, n, d)            # > 0: outside a face's plane
    if highest <= tolerance:                                    # wound outward
        outward_normals, offsets = n, d
    elif lowest >= -tolerance:                                  # wound inward: the solid's
        outward_normals, offsets = -n, -d                       # outside is the other side
    else:
        return None
    centre = positions.mean(axis=0)                             # inside a convex solid
    facing = np.einsum("ij,ij->i", normals, positions - centre)
    side = True if (facing > 0.0).all() else False if (facing < 0.0).all() else None
    return ConvexBody(outward_normals, offsets, tolerance, side)


def _height_range(positions: np.ndarray, n: np.ndarray, d: np.ndarray) -> tuple[float, float]:
    """The least and greatest height n_f . p + d_f of any vertex p over any face plane f, in
    chunks of faces so that memory stays within CHUNK_VALUES floats."""
    step = max(1, CHUNK_VALUES // max(len(positions), 1))
    lowest, highest = np.inf, -np.inf
    for start in range(0, len(n), step):
        heights = positions @ n[start:start + step].T + d[start:start + step]
        lowest, highest = min(lowest, float(heights.min())), max(highest, float(heights.max()))
    return lowest, highest


def weld(positions: np.ndarray, tolerance: float) -> np.ndarray:
    """(V,) index of each vertex's position among the distinct positions, positions within
    about `tolerance` of each other (on a grid of that step) counting as one (also
    renderer/core/facets.py's, to find a face's neighbours)."""
    grid = np.round(positions / tolerance).astype(np.int64)
    _, index = np.unique(grid, axis=0, return_inverse=True)
    return index.reshape(-1)


def _closed(faces: np.ndarray) -> bool:
    """Every directed edge of `faces` (F, 3) occurs once and its reverse once: a watertight,
    consistently wound surface."""
    a = faces.reshape(-1)
    b = np.roll(faces, -1, axis=1).reshape(-1)
    count = int(max(a.max(), b.max())) + 1
    directed = a * count + b
    reverse = b * count + a
    if len(np.unique(directed)) != len(directed):
        return False                                            # an edge run twice one way
    return bool(np.isin(reverse, directed).all())
