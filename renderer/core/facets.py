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

from renderer.core.convexity import WELD_TOLERANCE, weld
from renderer.core.mesh_cache import per_mesh

FACE_TEXTURE_WIDTH = 1024      # texels on a row of the face texture (GL allows 16384)
FACES_PER_ROW = FACE_TEXTURE_WIDTH // 2    # two texels a face
CREASE_CAP = 1.0               # a crease's rise is taken up to 45 degrees (tan 1): steeper is a corner


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


@per_mesh
def face_creases(mesh) -> np.ndarray:
    """(F, 2) float32: how steeply the faces across each face's edges rise off its plane, on
    the side its normal (as wound) points to (column 0) and on the other (column 1): for each
    neighbour (sharing an edge, vertices welded by position), the height of its far vertex over
    the face's plane per unit of its distance from the shared edge along the plane, the
    largest of the three on each side, up to CREASE_CAP (0: flat, open, or falling away). A
    neighbour rising on the lit side (a concave crease) is what a filter reading past the
    edge meets above the face's plane; the shadow lookup lifts its point by it."""
    positions = np.asarray(mesh.positions, dtype=np.float64)
    faces = np.asarray(mesh.faces, dtype=np.int64)
    out = np.zeros((len(faces), 2), np.float32)
    if len(faces) == 0:
        return out
    extent = float(np.ptp(positions, axis=0).max()) or 1.0
    welded = weld(positions, WELD_TOLERANCE * extent)[faces]
    # each face's directed edges (a -> b) with its far vertex c; its neighbour runs b -> a
    corners = [(0, 1, 2), (1, 2, 0), (2, 0, 1)]
    a = np.concatenate([faces[:, i] for i, _, _ in corners])
    b = np.concatenate([faces[:, j] for _, j, _ in corners])
    c = np.concatenate([faces[:, k] for _, _, k in corners])
    wa = np.concatenate([welded[:, i] for i, _, _ in corners])
    wb = np.concatenate([welded[:, j] for _, j, _ in corners])
    owner = np.tile(np.arange(len(faces)), 3)
    count = int(welded.max()) + 1
    key, reverse = wa * count + wb, wb * count + wa
    order = np.argsort(key, kind="stable")
    at = np.minimum(np.searchsorted(key[order], reverse), len(order) - 1)
    found = key[order][at] == reverse
    edge, neighbour = np.flatnonzero(found), order[at[found]]
    n = face_normals(mesh).astype(np.float64)[owner[edge]]
    p, q, far = positions[a[edge]], positions[b[edge]], positions[c[neighbour]]
    height = np.einsum("ij,ij->i", far - p, n)
    along = (far - p) - height[:, None] * n                 # in the face's plane
    e = q - p
    e /= np.maximum(np.linalg.norm(e, axis=1, keepdims=True), np.finfo(float).tiny)
    distance = np.linalg.norm(along - np.einsum("ij,ij->i", along, e)[:, None] * e, axis=1)
    with np.errstate(divide="ignore", invalid="ignore"):
        slope = np.where(distance > 0.0, np.abs(height) / distance, np.where(height != 0.0, np.inf, 0.0))
    slope = np.minimum(slope, CREASE_CAP).astype(np.float32)
    np.maximum.at(out[:, 0], owner[edge], np.where(height > 0.0, slope, np.float32(0.0)))
    np.maximum.at(out[:, 1], owner[edge], np.where(height < 0.0, slope, np.float32(0.0)))
    out.setflags(write=False)
    return out


def face_texture(mesh) -> np.ndarray:
    """(rows, FACE_TEXTURE_WIDTH, 4) float32: the faces as the GPU path's RGBA32F texture
    holds them (row 0 first, as uploaded), two texels a face (FACES_PER_ROW a row): face f's
    first at (2 (f mod FACES_PER_ROW), f div FACES_PER_ROW) holds (its normal, its crease on
    the normal's side), the next (its crease on the other side, 0, 0, 0)."""
    normals, creases = face_normals(mesh), face_creases(mesh)
    rows = max(1, -(-len(normals) // FACES_PER_ROW))
    data = np.zeros((rows * FACES_PER_ROW, 2, 4), np.float32)
    data[:len(normals), 0, :3] = normals
    data[:len(normals), 0, 3] = creases[:, 0]
    data[:len(normals), 1, 0] = creases[:, 1]
    return data.reshape(rows, FACE_TEXTURE_WIDTH, 4)
