"""An infinite plane as the rasteriser draws it: the convex polygon where it meets a view volume.

The ray tracer intersects an analytic plane (renderer.core.scene.Plane) itself; the rasteriser
draws, for each view, the part of it inside that view's volume, computed here on the CPU in
float64 and fanned into triangles. Any view volume can use it: the camera's (each update(),
renderer/core/drawn.py) and a light's for its shadow map (an orthographic box, a cube face's
frustum). So nothing of a plane's surface outside the view is handed to the GPU, whose float32
would round a far-away vertex by more than the depth precision the plane is drawn to.

The view volume is given as a clip-space matrix, clip_from_world (4, 4) float64, camera-relative
world (the frame's P V, or a light's), and a depth mapping (renderer/core/gl_rules.py): it keeps
-w <= x, y <= w and z between the near and far planes' z_ndc (GL's clip volume, docs/conventions.md
"Camera"; -1 <= z_ndc <= 1, or 0 <= z_ndc <= 1 under reversed-Z), perspective and parallel
projections alike. Its 8 corners are taken to the world (float64 solve of the matrix)
and the plane cuts those of the box's 12 edges whose ends lie on opposite sides of it (corners
on it count as they are). The points, sorted by angle about their centroid, form the convex
polygon (at most 6 vertices: a plane crosses at most 6 faces of a hexahedron); vertices within
MERGE_TOLERANCE in NDC of their neighbours' line are dropped, so that rounding near a corner
of the volume makes no sliver. Each vertex is projected onto the
plane in float64 last. A volume that is not finite in float64 (a singular matrix, a near plane
at 1e-300 whose far corners overflow) or a plane that meets it in less than a polygon gives
None: nothing to draw.

    plane_polygon(WorldPlane(N, d), P @ V)               Mesh | None, camera-relative world
    object_plane_polygon(Plane(...), model, P @ V)       the same for an object, with its UVs
"""

from __future__ import annotations

import numpy as np

from renderer.core.gl_rules import STANDARD_DEPTH, DepthMapping
from renderer.core.scene import Mesh, Plane, WorldPlane, world_shape
from renderer.core.uv_rules import plane_uv

MAX_POLYGON_VERTICES = 6
MAX_POLYGON_TRIANGLES = MAX_POLYGON_VERTICES - 2
# A vertex this close in NDC (the volume is 2 across) to the line through its neighbours adds
# nothing float32 could show, on screen or in depth: it is dropped.
MERGE_TOLERANCE = 2.0 ** -32

# Corner k of the clip volume takes the high end of x, y, z where bits 0, 1, 2 of k are set;
# the box's edges join corners that differ in one bit.
_BITS = (np.arange(8)[:, None] >> np.arange(3)) & 1
EDGES = np.array([(k, k | 1 << axis) for axis in range(3) for k in range(8) if not k >> axis & 1])


def _corners(clip_from_world: np.ndarray, z_ndc: tuple[float, float]) -> np.ndarray | None:
    """(8, 3) world corners of -1 <= x_ndc, y_ndc <= 1 between the two z_ndc, or None."""
    clip = np.concatenate([np.where(_BITS[:, :2], 1.0, -1.0),
                           np.where(_BITS[:, 2:], z_ndc[1], z_ndc[0]), np.ones((8, 1))], axis=1)
    with np.errstate(all="ignore"):
        try:
            world = np.linalg.solve(np.asarray(clip_from_world, np.float64), clip.T).T
        except np.linalg.LinAlgError:
            return None
        corners = world[:, :3] / world[:, 3:]
    return corners if np.isfinite(corners).all() else None


def view_volume_corners(clip_from_world: np.ndarray, mapping: DepthMapping = STANDARD_DEPTH) -> np.ndarray | None:
    """(8, 3) the world corners of the clip volume of `clip_from_world` under the depth
    `mapping` (near face z_ndc = ndc_near, far face ndc_far), float64; None where they are not
    finite. Where only the far face is at infinity (far / near beyond about 1e16 leaves
    float64 a projection with an infinite far plane), it is taken at the last window depth a
    float32 depth buffer tells from its clear value (GL's default: 1 - 2^-24; reversed-Z: the
    smallest normal float32): a surface beyond it cannot pass the depth test."""
    corners = _corners(clip_from_world, (mapping.ndc_near, mapping.ndc_far))
    if corners is None:
        clear = np.float32(mapping.clear_depth)
        last = np.nextafter(clear, np.float32(0.5)) if clear > 0 else np.finfo(np.float32).tiny
        far = float(last) * (1.0 - mapping.ndc_min) + mapping.ndc_min     # z_ndc of z_w `last`
        corners = _corners(clip_from_world, (mapping.ndc_near, far))
    return corners


def _simplified(points: np.ndarray, ndc: np.ndarray) -> np.ndarray:
    """The convex polygon `points` (K, 3), in order, without the vertices whose NDC point
    (`ndc`, (K, 3)) lies within MERGE_TOLERANCE of the line through its neighbours'
    (duplicates among them), the least significant first; at most MAX_POLYGON_VERTICES."""
    while len(points) >= 3:
        prev, nxt = np.roll(ndc, 1, axis=0), np.roll(ndc, -1, axis=0)
        chord = np.linalg.norm(nxt - prev, axis=1)
        twice_area = np.linalg.norm(np.cross(ndc - prev, nxt - prev), axis=1)
        # the distance from the neighbours' line (from a neighbour where they coincide)
        distance = np.where(chord > 0, twice_area / np.maximum(chord, np.finfo(float).tiny),
                            np.linalg.norm(ndc - prev, axis=1))
        k = int(np.argmin(distance))
        if distance[k] > MERGE_TOLERANCE and len(points) <= MAX_POLYGON_VERTICES:
            break
        points, ndc = np.delete(points, k, axis=0), np.delete(ndc, k, axis=0)
    return points


def plane_polygon(plane: WorldPlane, clip_from_world: np.ndarray,
                  mapping: DepthMapping = STANDARD_DEPTH) -> Mesh | None:
    """The convex polygon where `plane` (camera-relative world, unit N) meets the clip volume of
    `clip_from_world` (module docstring), as a Mesh in the same coordinates: 3 to
    MAX_POLYGON_VERTICES vertices with the plane's normal, fanned (0, k, k + 1) into triangles
    counter-clockwise seen from the side N points to; no UVs. None when they do not meet in a
    polygon."""
    corners = view_volume_corners(clip_from_world, mapping)
    if corners is None:
        return None
    n, d = np.asarray(plane.normal, np.float64), float(plane.offset)
    with np.errstate(all="ignore"):
        side = corners @ n + d
        a, b = side[EDGES[:, 0]], side[EDGES[:, 1]]
        crossing = (a < 0) & (b > 0) | (a > 0) & (b < 0)
        t = (a / (a - b))[crossing, None]
        start, end = corners[EDGES[crossing, 0]], corners[EDGES[crossing, 1]]
        points = np.concatenate([start + t * (end - start), corners[side == 0]])
        if len(points) < 3 or not np.isfinite(points).all():
            return None
        points = points - np.outer(points @ n + d, n)                 # onto the plane exactly
        mid = points.mean(axis=0)
        u = points[np.argmax(np.linalg.norm(points - mid, axis=1))] - mid
        v = np.cross(n, u)                     # (u, v, n) right-handed: angle grows CCW from +n
        points = points[np.argsort(np.arctan2((points - mid) @ v, (points - mid) @ u))]
        clip = np.concatenate([points, np.ones((len(points), 1))], axis=1) @ np.asarray(clip_from_world).T
        ndc = clip[:, :3] / clip[:, 3:]
        if not np.isfinite(ndc).all():
            return None
        points = _simplified(points, ndc)
    if len(points) < 3:
        return None
    count = len(points)
    faces = np.stack([np.zeros(count - 2, np.int64), np.arange(1, count - 1), np.arange(2, count)], 1)
    return Mesh(points, np.tile(n, (count, 1)), faces, f"plane polygon ({count} vertices)")


def object_plane_polygon(shape: Plane, model: np.ndarray, clip_from_world: np.ndarray,
                         mapping: DepthMapping = STANDARD_DEPTH) -> Mesh | None:
    """plane_polygon of an object's analytic plane `shape` through `model` (its camera-relative
    world matrix, parents applied; Scene.matrices' ObjectMatrices.model), with UVs by the
    plane rule (renderer/core/uv_rules.py) at each vertex's object-space point, so that a
    textured plane is textured as before (the point the matrix maps there; where it flattens
    a direction, the nearest such point to the object's origin)."""
    m = np.asarray(model, np.float64)
    mesh = plane_polygon(world_shape(shape, m), clip_from_world, mapping)
    if mesh is not None:
        local = (mesh.positions - m[:3, 3]) @ np.linalg.pinv(m[:3, :3]).T
        mesh.uvs = plane_uv(local, shape.normal)
    return mesh
