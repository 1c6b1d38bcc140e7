"""Each triangle's facet normal, as the shadow lookup reads it (docs/conventions.md, "Shadows",
"The facet normal").

A smooth-shaded mesh lights a point with the normal interpolated from its vertices, but the
surface that casts and receives shadows is its flat facets. The shadow lookup therefore uses
the facet's own normal: a point on a facet turned away from the light is not reached by it
(as a shadow ray from that facet is blocked by the solid behind it), and the bias's normal
offset moves the point along the facet's normal, for which its planar argument is exact.

`face_normals(mesh)`: (F, 3) float32 unit normals in object space, as wound
(normalize((p1 - p0) x (p2 - p0)) in float64, then rounded; 0 for a degenerate triangle).
Both twins read these float32 values: the GPU path as a texture (`face_texture`: face f at
texel (f mod FACE_TEXTURE_WIDTH, f div FACE_TEXTURE_WIDTH), fetched at gl_PrimitiveID, which
is the face's index in an indexed draw) and the reference by index; each turns it into world
space by the normal matrix and renormalises (glsl/fragment.glsl <-> reference/fragment.py).
"""

from __future__ import annotations

import numpy as np

from renderer.core.mesh_cache import per_mesh

FACE_TEXTURE_WIDTH = 1024      # texels on a row of the face-normal texture (GL allows 16384)


@per_mesh
def face_normals(mesh) -> np.ndarray:
    """(F, 3) float32: each face's unit normal in object space, as wound (module docstring)."""
    positions = np.asarray(mesh.positions, dtype=np.float64)
    corners = positions[np.asarray(mesh.faces, dtype=np.int64)]
    n = np.cross(corners[:, 1] - corners[:, 0], corners[:, 2] - corners[:, 0])
    length = np.linalg.norm(n, axis=1, keepdims=True)
    with np.errstate(invalid="ignore", divide="ignore"):
        unit = np.where(length > 0.0, n / np.where(length > 0.0, length, 1.0), 0.0)
    out = unit.astype(np.float32)
    out.setflags(write=False)
    return out


def face_texture(mesh) -> np.ndarray:
    """(rows, FACE_TEXTURE_WIDTH, 4) float32: the face normals laid out as the GPU path's
    RGBA32F texture holds them (row 0 first, as uploaded; alpha 0)."""
    normals = face_normals(mesh)
    rows = max(1, -(-len(normals) // FACE_TEXTURE_WIDTH))
    data = np.zeros((rows * FACE_TEXTURE_WIDTH, 4), np.float32)
    data[:len(normals), :3] = normals
    return data.reshape(rows, FACE_TEXTURE_WIDTH, 4)
