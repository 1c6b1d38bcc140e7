"""# Twin: fixed-function GL (OpenGL 4.5 core spec §13.6 Coordinate Transformations, §14.6 Polygons)

Perspective divide and viewport transform, vertex snapping, facing and culling, and
rasterisation with fixed-point edge functions, written down as llvmpipe does them (checked
against it in tests/test_rasterizer.py):

- window coordinates x_w = (x_ndc + 1) W / 2, y_w = (y_ndc + 1) H / 2, z_w = (z_ndc + 1) / 2
  (z_w = z_ndc under reversed-Z, glClipControl ZERO_TO_ONE), origin at the bottom-left,
  y up; pixel (i, j) is sampled at its centre (i + 1/2, j + 1/2);
- x_w and y_w are snapped to 1 / 2^subpixel_bits of a pixel, rounding to nearest (ties to
  even), and coverage is decided exactly with int64 edge functions of the snapped vertices;
- facing comes from the signed area of the snapped triangle: counter-clockwise is front;
  zero-area triangles produce no fragments;
- fill rule: a pixel centre exactly on an edge is covered when the edge is a left edge or a
  bottom edge (horizontal, triangle above it), never when it is a right or top edge;
- barycentrics are perspective-correct (weights 1 / w_clip) for the varyings, and plain
  screen-space (affine) for z_w, since z_ndc is affine in window coordinates; like
  llvmpipe's attribute set-up they are computed from the unsnapped window positions (this
  keeps depth within float32 rounding of llvmpipe's; the snapped positions would put it up
  to 1/512 px of slope away on steep triangles);
- a triangle's varyings are planes over the whole window, evaluated also at pixels it does not
  cover: GL shades 2x2 quads, the pixels of a quad outside the triangle as helper
  invocations, whose values the quad's derivatives (a texture's level of detail) take
  (`perspective_weights_at`).

The triangles are walked in batches: each batch expands its triangles' bounding boxes
(clipped to the viewport) into (triangle, pixel) candidates with np.repeat and tests them
all at once; no Python loop runs over pixels.

Inputs:  gl_Position (T, 3, 4) clip coordinates of triangles already clipped to the view
         volume, the viewport size and the number of sub-pixel bits.
Outputs: `WindowTriangles` (setup) and, from `rasterize`, batches of `Fragments`:
         x, y (N,) int64         pixel column and row (row 0 at the bottom, as GL)
         triangle (N,) int64     index of the window triangle
         barycentric (N, 3)      perspective-correct weights of its three vertices
         z_w (N,)                window depth in [0, 1]
         gl_FrontFacing (N,)     bool
"""

from __future__ import annotations

from dataclasses import dataclass
from typing import Iterator

import numpy as np

from renderer.core.gl_rules import (SUBPIXEL_BITS, depth_mapping, inside_columns, is_left_or_bottom_edge,
                                    pixel_centre, snap_to_subpixel_grid)

MAX_CANDIDATES_PER_BATCH = 1 << 19  # (triangle, pixel) pairs tested at once


@dataclass
class WindowTriangles:
    """Triangles after the viewport transform and snapping.

    x, y (T, 3) int64   snapped window coordinates in units of 1 / 2^subpixel_bits pixel
    x_w, y_w (T, 3)     the unsnapped window coordinates (float dtype), for interpolation
    z_w (T, 3)          window depth (float dtype)
    inv_w (T, 3)        1 / w_clip, the perspective-correction weights
    area2 (T,) int64    twice the signed area of the snapped triangle (> 0: CCW, front)
    """
    x: np.ndarray
    y: np.ndarray
    x_w: np.ndarray
    y_w: np.ndarray
    z_w: np.ndarray
    inv_w: np.ndarray
    area2: np.ndarray
    subpixel_bits: int = SUBPIXEL_BITS

    def __len__(self) -> int:
        return len(self.area2)

    def select(self, mask: np.ndarray) -> "WindowTriangles":
        return WindowTriangles(self.x[mask], self.y[mask], self.x_w[mask], self.y_w[mask],
                               self.z_w[mask], self.inv_w[mask], self.area2[mask],
                               self.subpixel_bits)

    @classmethod
    def concatenate(cls, parts: list["WindowTriangles"]) -> "WindowTriangles":
        """The triangles of `parts` one after another (the same sub-pixel bits)."""
        arrays = [np.concatenate([getattr(p, name) for p in parts])
                  for name in ("x", "y", "x_w", "y_w", "z_w", "inv_w", "area2")]
        return cls(*arrays, parts[0].subpixel_bits)


@dataclass
class Fragments:
    x: np.ndarray
    y: np.ndarray
    triangle: np.ndarray
    barycentric: np.ndarray
    z_w: np.ndarray
    gl_FrontFacing: np.ndarray

    def __len__(self) -> int:
        return len(self.x)


# --- the rules, one small helper each (the fill rule and snapping: renderer/core/gl_rules.py) --

def viewport_transform(gl_Position: np.ndarray, width: int, height: int,
                       reversed_z: bool = False):
    """Perspective divide and GL's viewport transform. Returns (x_w, y_w, z_w, 1 / w_clip);
    z_w by the depth mapping (core/gl_rules.py; reversed-Z takes z_w = z_ndc, keeping its
    float precision)."""
    inv_w = 1.0 / gl_Position[..., 3]
    x_ndc, y_ndc, z_ndc = (gl_Position[..., i] * inv_w for i in range(3))
    x_w = (x_ndc + 1.0) * (width / 2.0)
    y_w = (y_ndc + 1.0) * (height / 2.0)
    z_w = depth_mapping(reversed_z).window_depth(z_ndc)
    return x_w, y_w, z_w, inv_w


def edge_function(xa, ya, xb, yb, px, py):
    """(b - a) x (p - a): > 0 when p lies to the left of the directed edge a -> b."""
    return (xb - xa) * (py - ya) - (yb - ya) * (px - xa)


def signed_area_twice(x: np.ndarray, y: np.ndarray) -> np.ndarray:
    """Twice the signed area of triangles (T, 3); positive when counter-clockwise (y up)."""
    return edge_function(x[:, 0], y[:, 0], x[:, 1], y[:, 1], x[:, 2], y[:, 2])


def is_front_facing(area2: np.ndarray) -> np.ndarray:
    """GL_CCW: counter-clockwise in window coordinates is the front face."""
    return area2 > 0


def is_drawn(area2: np.ndarray, cull: str) -> np.ndarray:
    """Zero-area triangles are never drawn; cull 'back' drops CW, 'front' drops CCW."""
    if cull == "back":
        return area2 > 0
    if cull == "front":
        return area2 < 0
    if cull == "none":
        return area2 != 0
    raise ValueError(f"unknown cull mode {cull!r}")


def setup_triangles(gl_Position: np.ndarray, width: int, height: int,
                    subpixel_bits: int = SUBPIXEL_BITS, reversed_z: bool = False) -> WindowTriangles:
    """Window coordinates, snapping and signed area for clipped triangles (T, 3, 4)."""
    x_w, y_w, z_w, inv_w = viewport_transform(gl_Position, width, height, reversed_z)
    x = snap_to_subpixel_grid(x_w, subpixel_bits)
    y = snap_to_subpixel_grid(y_w, subpixel_bits)
    return WindowTriangles(x, y, x_w, y_w, z_w, inv_w, signed_area_twice(x, y), subpixel_bits)


def bounding_boxes(tris: WindowTriangles, width: int, height: int, region=None, grow: int = 0):
    """Pixel ranges [i0, i1] x [j0, j1] whose centres may be covered, clipped to the viewport,
    or to `region` (x0, y0, x1, y1), a rectangle of pixels of it (GL rows; ends excluded);
    `grow`: the box widened by that many sub-pixel units on every side."""
    bits = tris.subpixel_bits
    half = 1 << (bits - 1)
    i0 = -((half - tris.x.min(axis=1) + grow) >> bits)    # ceil((x_min - grow - half) / one)
    j0 = -((half - tris.y.min(axis=1) + grow) >> bits)
    i1 = (tris.x.max(axis=1) + grow - half) >> bits        # floor((x_max + grow - half) / one)
    j1 = (tris.y.max(axis=1) + grow - half) >> bits
    x0, y0, x1, y1 = (0, 0, width, height) if region is None else region
    return (np.maximum(i0, x0), np.minimum(i1, x1 - 1),
            np.maximum(j0, y0), np.minimum(j1, y1 - 1))


def _work_items(tris: WindowTriangles, width: int, height: int, max_candidates: int, region=None,
                grow: int = 0):
    """Split each triangle's bounding box into row bands of at most `max_candidates` pixels.

    Returns per item: triangle, i0, box width, j0, band height.
    """
    i0, i1, j0, j1 = bounding_boxes(tris, width, height, region, grow)
    box_w = np.maximum(i1 - i0 + 1, 0)
    box_h = np.maximum(j1 - j0 + 1, 0)
    rows_per_band = np.maximum(max_candidates // np.maximum(box_w, 1), 1)
    bands = np.where(box_w * box_h > 0, -(-box_h // rows_per_band), 0)
    tri = np.repeat(np.arange(len(tris)), bands)
    band = np.arange(len(tri)) - np.repeat(np.cumsum(bands) - bands, bands)
    band_j0 = j0[tri] + band * rows_per_band[tri]
    band_h = np.minimum(rows_per_band[tri], j1[tri] + 1 - band_j0)
    return tri, i0[tri], box_w[tri], band_j0, band_h


def screen_barycentrics(tris: WindowTriangles, t: np.ndarray, px: np.ndarray,
                        py: np.ndarray) -> np.ndarray:
    """Screen-space barycentrics (N, 3) of pixel centres in triangles t.

    Coverage is decided on the snapped vertices, but like llvmpipe (whose attribute planes
    are set up from the float window positions) the weights come from the unsnapped
    positions, solved relative to vertex 0:
    p - v0 = l1 (v1 - v0) + l2 (v2 - v0), l0 = 1 - l1 - l2.
    Where the unsnapped triangle has no area the snapped one is used instead.
    """
    dtype = tris.x_w.dtype
    x0, y0 = tris.x_w[t, 0], tris.y_w[t, 0]
    dx1, dy1 = tris.x_w[t, 1] - x0, tris.y_w[t, 1] - y0
    dx2, dy2 = tris.x_w[t, 2] - x0, tris.y_w[t, 2] - y0
    area = dx1 * dy2 - dy1 * dx2
    if not np.all(area != 0):
        scale = dtype.type(1 << tris.subpixel_bits)
        snapped = (tris.x[t] / scale).astype(dtype), (tris.y[t] / scale).astype(dtype)
        flat = area == 0
        x0 = np.where(flat, snapped[0][:, 0], x0)
        y0 = np.where(flat, snapped[1][:, 0], y0)
        dx1 = np.where(flat, snapped[0][:, 1] - x0, dx1)
        dy1 = np.where(flat, snapped[1][:, 1] - y0, dy1)
        dx2 = np.where(flat, snapped[0][:, 2] - x0, dx2)
        dy2 = np.where(flat, snapped[1][:, 2] - y0, dy2)
        area = dx1 * dy2 - dy1 * dx2
    qx = (px + 0.5).astype(dtype) - x0                             # pixel centre - v0
    qy = (py + 0.5).astype(dtype) - y0
    l1 = (qx * dy2 - qy * dx2) / area
    l2 = (dx1 * qy - dy1 * qx) / area
    return np.stack([1.0 - l1 - l2, l1, l2], axis=-1)


def perspective_weights_at(gl_Position: np.ndarray, x_w: np.ndarray, y_w: np.ndarray,
                           width: int, height: int) -> np.ndarray:
    """Perspective-correct weights (N, 3) of the vertices of triangles given in clip
    coordinates (N, 3, 4) at window points (x_w, y_w) (N,), inside each triangle or not (a
    helper pixel's): the weights b, summing to 1, whose combination of the vertices' clip
    (x, y, w) lies on the point's ray, b ~ adj(M) (x_ndc, y_ndc, 1) with M's columns the
    vertices' (x, y, w) (homogeneous rasterisation: no divide by a vertex's w, so a clipped
    triangle's source triangle, whose vertices may lie behind the eye, serves as well)."""
    c = gl_Position[..., [0, 1, 3]]                              # (N, 3, 3): rows (x, y, w)
    ndc = np.stack([2.0 * x_w / width - 1.0, 2.0 * y_w / height - 1.0, np.ones_like(x_w)],
                   axis=-1).astype(c.dtype)
    b = np.stack([np.einsum("ni,ni->n", ndc, np.cross(c[:, (k + 1) % 3], c[:, (k + 2) % 3]))
                  for k in range(3)], axis=-1)
    return b / b.sum(axis=-1, keepdims=True)


def depth_planes(tris: WindowTriangles):
    """Each triangle's window depth as an affine plane, the same plane `screen_barycentrics`
    interpolates z_w on (unsnapped positions; snapped where those have no area):
    (x0, y0, z0, dz/dx, dz/dy) (T,), z_w(x, y) = z0 + dz/dx (x - x0) + dz/dy (y - y0)."""
    dtype = tris.x_w.dtype
    x, y, z = tris.x_w, tris.y_w, tris.z_w
    area = (x[:, 1] - x[:, 0]) * (y[:, 2] - y[:, 0]) - (y[:, 1] - y[:, 0]) * (x[:, 2] - x[:, 0])
    if not np.all(area != 0):
        scale = dtype.type(1 << tris.subpixel_bits)
        flat = (area == 0)[:, None]
        x = np.where(flat, (tris.x / scale).astype(dtype), x)
        y = np.where(flat, (tris.y / scale).astype(dtype), y)
        area = (x[:, 1] - x[:, 0]) * (y[:, 2] - y[:, 0]) - (y[:, 1] - y[:, 0]) * (x[:, 2] - x[:, 0])
    dx1, dy1, dz1 = x[:, 1] - x[:, 0], y[:, 1] - y[:, 0], z[:, 1] - z[:, 0]
    dx2, dy2, dz2 = x[:, 2] - x[:, 0], y[:, 2] - y[:, 0], z[:, 2] - z[:, 0]
    return x[:, 0], y[:, 0], z[:, 0], (dz1 * dy2 - dz2 * dy1) / area, (dx1 * dz2 - dx2 * dz1) / area


@dataclass
class EdgeEquations:
    """E_k(p) = a_k p_y - b_k p_x + c_k for the edge opposite vertex k, oriented so that the
    interior is positive (a counter-clockwise traversal); inclusive_k from the fill rule.
    All (3, T) int64 / bool, row k for edge k. E_k is twice the area of the triangle formed
    by p and edge k, so E_k / |area2| is vertex k's screen-space barycentric weight."""
    a: np.ndarray
    b: np.ndarray
    c: np.ndarray
    inclusive: np.ndarray


def edge_equations(tris: WindowTriangles) -> EdgeEquations:
    """Edge (start -> end) opposite each vertex, flipped for clockwise triangles."""
    orientation = np.sign(tris.area2)
    x, y = tris.x.T, tris.y.T                                   # (3, T)
    start, end = [1, 2, 0], [2, 0, 1]
    dx = orientation * (x[end] - x[start])
    dy = orientation * (y[end] - y[start])
    # edge_function(start, end, p) = dx (p_y - start_y) - dy (p_x - start_x)
    c = dy * x[start] - dx * y[start]
    return EdgeEquations(dx, dy, c, is_left_or_bottom_edge(dx, dy))


def coverage(tris: WindowTriangles, width: int, height: int, *,
             max_candidates: int = MAX_CANDIDATES_PER_BATCH, region=None,
             margin: np.ndarray | None = None) -> Iterator[tuple]:
    """The covered (triangle, pixel) pairs, in batches of at most about 2 * max_candidates
    tested candidates, in triangle order: (t, px, py) int64 each. Triangles must have
    area2 != 0. `region` (x0, y0, x1, y1): only the pixels of that rectangle of the viewport
    (a tile). The coverage rules alone (edge functions, fill rule): `rasterize` adds the
    interpolation, the shadow maps' depth pass (reference/shadow/depth.py) only a depth plane.
    `margin` (3, T) int64 >= 0, for the depth pass: instead, the pixels whose coverage is in
    doubt when each edge function may be off by up to its margin: those that pass the fill
    rule with E + margin but not with E - margin (boxes grown by the one sub-pixel unit a
    vertex may move)."""
    edges = edge_equations(tris)
    tri, i0, box_w, j0, box_h = _work_items(tris, width, height, max_candidates, region,
                                            0 if margin is None else 1)
    counts = box_w * box_h
    ends = np.cumsum(counts)
    batch_of_item = (ends - counts) // max_candidates
    boundaries = np.flatnonzero(np.diff(batch_of_item)) + 1
    for items in np.split(np.arange(len(tri)), boundaries):
        if len(items):
            yield _covered(edges, tris.subpixel_bits, tri[items], i0[items], box_w[items],
                           j0[items], box_h[items], margin)


def rasterize(tris: WindowTriangles, width: int, height: int, *,
              max_candidates: int = MAX_CANDIDATES_PER_BATCH, region=None) -> Iterator[Fragments]:
    """Fragments of the triangles, batch by batch as `coverage` finds them."""
    for t, px, py in coverage(tris, width, height, max_candidates=max_candidates, region=region):
        yield _fragments(tris, t, px, py)


def _expand(starts: np.ndarray, lengths: np.ndarray):
    """For runs (start, length): (run index, start + offset) for every member of every run."""
    run = np.repeat(np.arange(len(lengths)), lengths)
    offset = np.arange(len(run)) - np.repeat(np.cumsum(lengths) - lengths, lengths)
    return run, starts[run] + offset


def _spans(edges: EdgeEquations, bits: int, t, cy, lo, hi, shift=None):
    """Each row's columns [lo, hi] narrowed to those passing the three edges' fill rule
    (gl_rules.inside_columns, exact), the edge functions first moved by `shift` (3, T)."""
    for k in range(3):
        c = edges.c[k].take(t) if shift is None else edges.c[k].take(t) + shift[k].take(t)
        edge_lo, edge_hi = inside_columns(edges.a[k].take(t) * cy + c, edges.b[k].take(t),
                                          edges.inclusive[k].take(t), bits)
        lo, hi = np.maximum(lo, edge_lo), np.minimum(hi, edge_hi)
    return lo, hi


def _covered(edges: EdgeEquations, bits: int, tri, i0, box_w, j0, box_h, margin=None):
    """The covered (triangle, px, py) of the items' boxes: along each row of a box, the three
    edges' fill rule solved for the columns, so only covered pixels are made, in triangle,
    row, column order; with `margin` (coverage) the doubtful ones: the columns of the row's
    span with + margin left and right of its span with - margin."""
    item_of_row, py = _expand(j0, box_h)                         # every row of every box
    t = tri[item_of_row]
    cy = pixel_centre(py, bits)
    lo, hi = i0[item_of_row], i0[item_of_row] + box_w[item_of_row] - 1
    if margin is None:
        lo, hi = _spans(edges, bits, t, cy, lo, hi)
    else:
        lo, hi = _spans(edges, bits, t, cy, lo, hi, margin)
        sure_lo, sure_hi = _spans(edges, bits, t, cy, lo, hi, -margin)
        none = sure_hi < sure_lo
        sure_lo, sure_hi = np.where(none, hi + 1, sure_lo), np.where(none, hi, sure_hi)
        # [lo, sure_lo - 1] and [sure_hi + 1, hi]
        t, py = np.concatenate([t, t]), np.concatenate([py, py])
        lo, hi = np.concatenate([lo, sure_hi + 1]), np.concatenate([sure_lo - 1, hi])
    row_of_pixel, px = _expand(lo, np.maximum(hi - lo + 1, 0))  # every covered pixel of it
    return t[row_of_pixel], px, py[row_of_pixel]


def _fragments(tris: WindowTriangles, t, px, py) -> Fragments:
    """The covered pixels' barycentrics, depth and facing."""
    screen = screen_barycentrics(tris, t, px, py)
    z = tris.z_w[t]
    z_w = screen[:, 0] * z[:, 0] + screen[:, 1] * z[:, 1] + screen[:, 2] * z[:, 2]  # affine
    perspective = screen * tris.inv_w[t]                         # weights lambda_k / w_k
    barycentric = perspective / (perspective[:, 0] + perspective[:, 1] + perspective[:, 2])[:, None]
    return Fragments(px, py, t, barycentric, z_w, is_front_facing(tris.area2[t]))
