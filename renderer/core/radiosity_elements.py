"""Radiosity's elements (notes 2, indirect illumination; issue 33): the scene's surfaces cut into
small flat triangles, each of which is given one radiosity B_i. One definition for the GPU
path and its twin: both draw these triangles into their item buffers and place a hemicube on
each (renderer/core/hemicube.py).

An element is a triangle in world coordinates (float64) with
  - its front: the side the mesh's normals point to (the average of its source triangle's
    vertex normals through the normal matrix). Its corners are ordered counter-clockwise seen
    from the front (swapped where the winding disagrees), so that GL's gl_FrontFacing (and the
    twin's signed area) says which side of it a hemicube sees: only the front reflects and
    emits; a back face seen is an occluder that passes nothing on;
  - its centre (the centroid, where its hemicube sits), unit normal and area;
  - the object it belongs to, its reflectance rho (per channel, <= 1) and its emitted
    radiosity E (exitance, per channel).

Meshing: each source triangle is cut into k x k similar triangles (k = the smallest integer
with longest edge / k <= `size`), the regular split whose pieces keep the triangle's shape.
Pieces of neighbouring triangles need not share vertices (T-junctions); the hemicube does
not mind, and the display interpolates per vertex of each piece.
"""

from __future__ import annotations

from dataclasses import dataclass
from functools import cached_property

import numpy as np

from renderer.core.convexity import convex_body
from renderer.core.transforms import normal_matrix


@dataclass(frozen=True)
class Elements:
    """The elements (module docstring); their centres, areas and normals computed once, from
    `corners` (which stay as made)."""
    corners: np.ndarray          # (E, 3, 3) float64 world, counter-clockwise seen from the front
    obj: np.ndarray              # (E,) int64 index of the scene object
    reflectance: np.ndarray      # (E, 3) float64 rho per channel
    emission: np.ndarray         # (E, 3) float64 emitted radiosity per channel
    # False where no element can see another's front: the scene is one object whose mesh
    # bounds a convex solid, its normals outward (scene_elements; renderer/core/convexity.py)
    see_each_other: bool = True

    def __len__(self) -> int:
        return len(self.corners)

    @cached_property
    def centres(self) -> np.ndarray:
        return self.corners.mean(axis=1)

    @cached_property
    def _cross(self) -> np.ndarray:
        a, b, c = self.corners[:, 0], self.corners[:, 1], self.corners[:, 2]
        return np.cross(b - a, c - a)

    @cached_property
    def areas(self) -> np.ndarray:
        return 0.5 * np.linalg.norm(self._cross, axis=1)

    @cached_property
    def normals(self) -> np.ndarray:
        cross = self._cross
        return cross / np.linalg.norm(cross, axis=1, keepdims=True)

    def frames(self) -> np.ndarray:
        """(E, 3, 3): each element's hemicube frame, rows u, v, n in world coordinates (u along
        its first edge, n its front normal, v = n x u): the element's frame of hemicube.py."""
        n = self.normals
        u = self.corners[:, 1] - self.corners[:, 0]
        u = u / np.linalg.norm(u, axis=1, keepdims=True)
        return np.stack([u, np.cross(n, u), n], axis=1)

    def shortest_edge(self) -> float:
        return float(np.linalg.norm(self.corners - np.roll(self.corners, 1, axis=1), axis=2).min())

    def extent(self) -> tuple[np.ndarray, float]:
        """(centre, diameter) of the elements' bounding box."""
        lo, hi = self.corners.min(axis=(0, 1)), self.corners.max(axis=(0, 1))
        return (lo + hi) / 2, float(np.linalg.norm(hi - lo))


def split_triangle(corners: np.ndarray, k: int) -> np.ndarray:
    """(T, 3, 3) triangles, each split into k x k similar ones: (T * k * k, 3, 3), each piece
    wound as its source, the pieces of one source together."""
    i, j = np.meshgrid(np.arange(k), np.arange(k), indexing="ij")
    up = (i + j) < k                                     # (i, j), (i+1, j), (i, j+1)
    down = (i + j) < k - 1                               # (i+1, j), (i+1, j+1), (i, j+1)
    lattice = [np.stack([i[up], j[up]], -1)[:, None] + np.array([[0, 0], [1, 0], [0, 1]]),
               np.stack([i[down], j[down]], -1)[:, None] + np.array([[1, 0], [1, 1], [0, 1]])]
    steps = np.concatenate(lattice) / k                  # (k*k, 3, 2): (s, t) along b - a, c - a
    a, b, c = corners[:, 0], corners[:, 1], corners[:, 2]
    return (a[:, None, None] + steps[None, ..., :1] * (b - a)[:, None, None]
            + steps[None, ..., 1:] * (c - a)[:, None, None]).reshape(-1, 3, 3)


# Corners closer than this fraction of the elements' extent are one vertex of the refined mesh.
REFINE_WELD_FRACTION = 1e-9


def refined(elements: Elements, split: np.ndarray) -> Elements:
    """The elements with those marked in `split` (E,) bool cut in four at their edges' midpoints,
    and the mesh kept conforming (red-green refinement): an element with two or three of its
    edges cut by its neighbours' splits is cut in four too (repeated until none is left), one
    with one such edge in two, from the opposite corner to that edge's midpoint. So every
    new vertex is a corner of the elements on both sides of its edge, and no T-junction opens
    a crack in the display. Corners are welded (within REFINE_WELD_FRACTION of the extent, each
    vertex one position) and a midpoint is (P_i + P_j) / 2 of the welded ends in index order,
    the same bits from either side. Each element's pieces stand in its place, wound as it was,
    with its object, reflectance and emission."""
    split = np.asarray(split, bool)
    count = len(elements)
    _, diameter = elements.extent()
    step = max(diameter, np.finfo(float).tiny) * REFINE_WELD_FRACTION
    points = elements.corners.reshape(-1, 3)
    _, first, vertex = np.unique(np.round(points / step).astype(np.int64), axis=0,
                                 return_index=True, return_inverse=True)
    position, vertex = points[first], vertex.reshape(count, 3)
    ends = np.stack([vertex, np.roll(vertex, -1, axis=1)], axis=-1)          # edge k: corner k to k + 1
    low, high = ends.min(axis=-1), ends.max(axis=-1)
    key = low * len(position) + high                                         # (E, 3)
    red = split.copy()
    while True:
        cut = np.isin(key, key[red])
        grown = red | (cut.sum(axis=1) >= 2)
        if np.array_equal(grown, red):
            break
        red = grown
    green = ~red & cut.any(axis=1)
    middle = (position[low] + position[high]) * 0.5                          # (E, 3, 3): edge k's
    corner = position[vertex]                                                # (E, 3, 3) welded
    pieces = np.where(red, 4, np.where(green, 2, 1))
    source = np.repeat(np.arange(count), pieces)
    out = np.empty((len(source), 3, 3))
    start = np.cumsum(pieces) - pieces
    keep = ~red & ~green
    out[start[keep]] = corner[keep]
    r = np.flatnonzero(red)
    a, b, c = corner[r, 0], corner[r, 1], corner[r, 2]
    m_ab, m_bc, m_ca = middle[r, 0], middle[r, 1], middle[r, 2]
    for offset, piece in enumerate(([a, m_ab, m_ca], [m_ab, b, m_bc], [m_ca, m_bc, c], [m_ab, m_bc, m_ca])):
        out[start[r] + offset] = np.stack(piece, axis=1)
    g = np.flatnonzero(green)
    k = np.argmax(cut[g], axis=1)                                            # the one cut edge
    here, there, opposite = (corner[g, (k + j) % 3] for j in range(3))
    m = middle[g, k]
    out[start[g]] = np.stack([here, m, opposite], axis=1)
    out[start[g] + 1] = np.stack([m, there, opposite], axis=1)
    return Elements(out, elements.obj[source], elements.reflectance[source], elements.emission[source],
                    see_each_other=elements.see_each_other)


def mesh_triangles(positions, faces, normals, model) -> tuple[np.ndarray, np.ndarray]:
    """(T, 3, 3) world triangles of a mesh through `model`, each counter-clockwise seen from the
    side its vertex normals point to, and (T, 3) that side's unit normal (the winding's)."""
    positions = np.asarray(positions, np.float64)
    faces = np.asarray(faces, np.int64)
    world = positions @ model[:3, :3].T + model[:3, 3]
    corners = world[faces]
    cross = np.cross(corners[:, 1] - corners[:, 0], corners[:, 2] - corners[:, 0])
    front = (np.asarray(normals, np.float64) @ normal_matrix(model).T)[faces].sum(axis=1)
    flip = (cross * front).sum(axis=1) < 0
    corners[flip] = corners[flip][:, [0, 2, 1]]
    cross[flip] = -cross[flip]
    keep = np.linalg.norm(cross, axis=1) > 0
    return corners[keep], cross[keep] / np.linalg.norm(cross[keep], axis=1, keepdims=True)


def mesh_elements(triangles: np.ndarray, obj: np.ndarray, size: float) -> tuple[np.ndarray, np.ndarray]:
    """The triangles (T, 3, 3) cut into elements no longer than `size` on any edge: (corners,
    object index of each)."""
    if len(triangles) == 0:
        return np.zeros((0, 3, 3)), np.zeros(0, np.int64)
    edges = np.linalg.norm(triangles - np.roll(triangles, 1, axis=1), axis=2).max(axis=1)
    splits = np.maximum(1, np.ceil(edges / size - 1e-9)).astype(np.int64)
    pieces, source = [], []
    for k in np.unique(splits):
        these = np.flatnonzero(splits == k)
        pieces.append(split_triangle(triangles[these], int(k)))
        source.append(np.repeat(these, k * k))
    source = np.concatenate(source)
    order = np.argsort(source, kind="stable")            # back into the sources' order
    return np.concatenate(pieces)[order], np.asarray(obj)[source[order]]


def scene_elements(scene, size, reflectance=None, emission=None) -> Elements:
    """The scene's objects (their meshes through their world matrices) cut into elements of at
    most `size` scene units, or of size(d) with d the diagonal of the triangles' bounding box
    where `size` is a function. `reflectance` and `emission`: per object (O, 3), default each
    material's k_d and nothing."""
    triangles, owner = [np.zeros((0, 3, 3))], [np.zeros(0, np.int64)]
    for index, (obj, model) in enumerate(zip(scene.objects, scene.world_matrices())):
        corners, _ = mesh_triangles(obj.mesh.positions, obj.mesh.faces, obj.mesh.normals, model)
        triangles.append(corners)
        owner.append(np.full(len(corners), index, np.int64))
    triangles, owner = np.concatenate(triangles), np.concatenate(owner)
    if callable(size):
        points = triangles.reshape(-1, 3)
        size = size(float(np.linalg.norm(np.ptp(points, axis=0))) if len(points) else 0.0)
    corners, obj = mesh_elements(triangles, owner, size)
    rho = np.array([o.material.kd for o in scene.objects], np.float64).reshape(-1, 3) if reflectance is None \
        else np.asarray(reflectance, np.float64)
    emitted = np.zeros((len(scene.objects), 3)) if emission is None else np.asarray(emission, np.float64)
    return Elements(corners, obj, rho[obj], emitted[obj], see_each_other=not _one_convex_solid(scene))


def _one_convex_solid(scene) -> bool:
    """Whether the scene is one object whose mesh bounds a convex solid with its normals
    outward: its faces' fronts look away from one another (and a scene's transforms are never
    mirrored, so its world matrix keeps that), and no hemicube of it sees anything."""
    if len(scene.objects) != 1:
        return False
    body = convex_body(scene.objects[0].mesh)
    return body is not None and body.normals_outward is True
