"""# Twin: fixed-function GL (OpenGL 4.5 core spec §13.5 Primitive Clipping)

Clips triangles in homogeneous clip space against the view volume -w <= x, y, z <= w (under
reversed-Z, glClipControl ZERO_TO_ONE: -w <= x, y <= w and 0 <= z <= w) with
Sutherland-Hodgman, one plane at a time, vectorised over triangles, and re-fans each
clipped polygon into triangles (0, k, k+1), as GL's clipper does.

GL interpolates every varying of a new vertex linearly in clip space with the same
parameter t as its position. Rather than carrying the varyings, each clipped vertex carries
its weights with respect to the three vertices of the triangle it came from (barycentric
coordinates in clip space, interpolated with that same t): any varying at a clipped vertex
is then sum_j weights[j] * varying_j, exactly what GL computes.

Inputs:  gl_Position (T, 3, 4) clip coordinates of each triangle's vertices (float dtype).
Outputs: `ClippedTriangles`, in the input's dtype:
         gl_Position (T', 3, 4)  clip coordinates of the output triangles
         source (T',) int64      index of the input triangle each output came from
                                 (sorted, so draw order is kept)
         weights (T', 3, 3)      weights[t, k, j]: vertex k of output t as a combination
                                 of vertex j of its source triangle
Triangles entirely inside pass unchanged (weights = identity); triangles entirely outside
one plane, and polygons clipped away to nothing, produce no output.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from renderer.core.gl_rules import STANDARD_DEPTH, DepthMapping, depth_mapping



def clip_planes(mapping: DepthMapping) -> tuple:
    """The six planes as (axis, sign, w_factor): inside when w_factor * w + sign *
    coordinate[axis] >= 0, that is -w <= x, x <= w, -w <= y, y <= w, then the depth range of
    the mapping (core/gl_rules.py): -w <= z (near) or, reversed-Z, 0 <= z (far), and z <= w."""
    return ((0, 1.0, 1.0), (0, -1.0, 1.0), (1, 1.0, 1.0), (1, -1.0, 1.0),
            (2, 1.0, mapping.clip_z_min_w), (2, -1.0, 1.0))


CLIP_PLANES = clip_planes(STANDARD_DEPTH)

# A triangle clipped by six planes gains at most one vertex per plane.
MAX_POLYGON_VERTICES = 3 + len(CLIP_PLANES)


@dataclass
class ClippedTriangles:
    gl_Position: np.ndarray
    source: np.ndarray
    weights: np.ndarray

    def __len__(self) -> int:
        return len(self.source)


def plane_distance(gl_Position: np.ndarray, axis: int, sign: float, w_factor: float) -> np.ndarray:
    """Signed distance-like value (w or 0) ± coordinate: >= 0 on the inside of the plane."""
    return w_factor * gl_Position[..., 3] + sign * gl_Position[..., axis]


def is_inside_plane(distance: np.ndarray) -> np.ndarray:
    """A point on the plane is inside (GL keeps -w <= x <= w, boundaries included)."""
    return distance >= 0


def intersect_edge(inside_vertex, outside_vertex, d_inside, d_outside):
    """The point where an edge crosses the plane, interpolated from its outside end as
    llvmpipe's clipper does it (draw_pipe_clip.c: t = d_out / (d_out - d_in), then
    out + t (in - out), each operation rounded in the vertices' dtype), so that in float32
    the new vertex is GL's bit for bit.

    Always starting from the same end makes the new vertex the same whichever triangle of a
    shared edge is clipped, so neighbours stay watertight.
    """
    t = (d_outside / (d_outside - d_inside))[..., None]
    return outside_vertex + t * (inside_vertex - outside_vertex)


def clip_polygons_against_plane(vertices: np.ndarray, count: np.ndarray, plane: tuple):
    """One Sutherland-Hodgman pass over polygons (P, M, C) with `count` vertices each.

    Components C are the 4 clip coordinates followed by the weights; all of them are
    interpolated alike. For every edge (current -> next): emit the current vertex if it
    is inside, then the crossing point if the edge crosses the plane.
    """
    polygons, slots, components = vertices.shape
    slot = np.arange(slots)
    valid = slot[None, :] < count[:, None]
    nxt = np.where(slot[None, :] + 1 < count[:, None], slot[None, :] + 1, 0)
    nxt_vertices = np.take_along_axis(vertices, nxt[..., None], axis=1)

    d_cur = plane_distance(vertices, *plane)
    d_nxt = plane_distance(nxt_vertices, *plane)
    inside_cur, inside_nxt = is_inside_plane(d_cur), is_inside_plane(d_nxt)
    emit_current = valid & inside_cur
    emit_crossing = valid & (inside_cur != inside_nxt)

    n_emit = emit_current.astype(np.int64) + emit_crossing
    first_slot = np.cumsum(n_emit, axis=1) - n_emit
    out = np.zeros((polygons, slots + 1, components), dtype=vertices.dtype)

    rows, cols = np.nonzero(emit_current)
    out[rows, first_slot[rows, cols]] = vertices[rows, cols]

    rows, cols = np.nonzero(emit_crossing)
    cur, nx = vertices[rows, cols], nxt_vertices[rows, cols]
    dc, dn = d_cur[rows, cols], d_nxt[rows, cols]
    going_out = inside_cur[rows, cols]
    inside_vertex = np.where(going_out[:, None], cur, nx)
    outside_vertex = np.where(going_out[:, None], nx, cur)
    d_in = np.where(going_out, dc, dn)
    d_out = np.where(going_out, dn, dc)
    out[rows, first_slot[rows, cols] + emit_current[rows, cols]] = intersect_edge(
        inside_vertex, outside_vertex, d_in, d_out)
    return out[:, :slots], n_emit.sum(axis=1)


def fan_triangulate(vertices: np.ndarray, count: np.ndarray, source: np.ndarray):
    """Polygon (v0, v1, ..., v_{n-1}) -> triangles (v0, v_k, v_{k+1}) for k = 1 .. n-2."""
    triangles, sources = [], []
    for k in range(1, vertices.shape[1] - 1):
        has = count > k + 1
        if np.any(has):
            triangles.append(vertices[has][:, [0, k, k + 1]])
            sources.append(source[has])
    if not triangles:
        return np.zeros((0, 3, vertices.shape[2]), vertices.dtype), np.zeros(0, np.int64)
    return np.concatenate(triangles), np.concatenate(sources)


def classify_triangles(gl_Position: np.ndarray, planes=CLIP_PLANES):
    """(all vertices inside every plane, all vertices outside some one plane) per triangle."""
    inside = np.stack([is_inside_plane(plane_distance(gl_Position, *plane))
                       for plane in planes], axis=-1)                     # (T, 3, planes)
    trivially_inside = inside.all(axis=(1, 2))
    trivially_outside = (~inside).all(axis=1).any(axis=1)
    return trivially_inside, trivially_outside


def clip_triangles(gl_Position: np.ndarray, reversed_z: bool = False) -> ClippedTriangles:
    """Clip triangles (T, 3, 4) against the view volume; see the module docstring."""
    gl_Position = np.asarray(gl_Position)
    dtype = gl_Position.dtype
    T = len(gl_Position)
    planes = clip_planes(depth_mapping(reversed_z))
    identity = np.broadcast_to(np.eye(3, dtype=dtype), (T, 3, 3))
    trivially_inside, trivially_outside = classify_triangles(gl_Position, planes)
    needs_clipping = ~trivially_inside & ~trivially_outside

    kept = np.nonzero(trivially_inside)[0]
    positions, weights, sources = [gl_Position[kept]], [identity[kept]], [kept]

    clip_index = np.nonzero(needs_clipping)[0]
    if len(clip_index):
        polygon = np.zeros((len(clip_index), MAX_POLYGON_VERTICES, 7), dtype=dtype)
        polygon[:, :3, :4] = gl_Position[clip_index]
        polygon[:, :3, 4:] = np.eye(3, dtype=dtype)
        count = np.full(len(clip_index), 3, dtype=np.int64)
        for plane in planes:
            polygon, count = clip_polygons_against_plane(polygon, count, plane)
        fanned, fan_source = fan_triangulate(polygon, count, clip_index)
        positions.append(fanned[..., :4])
        weights.append(fanned[..., 4:])
        sources.append(fan_source)

    source = np.concatenate(sources)
    order = np.argsort(source, kind="stable")
    return ClippedTriangles(np.concatenate(positions)[order], source[order],
                            np.concatenate(weights)[order])
