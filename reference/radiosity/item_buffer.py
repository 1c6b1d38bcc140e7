"""# Twin: glsl/radiosity/item_buffer.vert, item_buffer.geom, item_buffer.frag

Radiosity's item buffers (issue 33), as renderer/gpu/item_buffers.py has GL draw them: every
element's triangle (renderer/core/radiosity_elements.py, float32 positions relative to the
elements' centre) through each hemicube face's clip_from_world (renderer/core/hemicube.py,
composed in float64, used in float32: one float32 product, as the vertex shader), clipped with
reversed-Z (hemicube.DEPTH_MAPPING: 0 <= z <= w), each face an N x N layer drawn from texel
(0, 0), snapped with SUBPIXEL_BITS, no culling, the reference rasteriser's coverage (the same
edge functions and fill rule), z_w on each triangle's affine plane clamped to [0, 1], and
GL_GREATER against a buffer cleared to 0 (of equal depths the first drawn stays: triangles in
element order, a clipped triangle's pieces in fan order). A pixel's item is the element's
index + 1, with hemicube.ITEM_BACK_BIT where its snapped triangle is clockwise (its back is
seen), 0 where nothing is. A side face's lower half (GL rows below N / 2) lies below the
element's plane: its fragments are discarded (no item, no depth).

Output, `Items`: the items (H, 5, N, N) uint32, faces in hemicube.FACES' order, row 0 at the
top of each face, and `tied` (H, 5, N, N) bool: pixels whose runner-up fragment is within
DEPTH_TIE_TOLERANCE (relative, as reversed-Z keeps precision) of the winner, or within the
two fragments' plane slack: llvmpipe sets a triangle's depth plane up and evaluates it in
float32 from the window origin, off this float64 plane by a few roundings of |z| + |dz/dx| x +
|dz/dy| y (reference/shadow/depth.py, STORE_TIE_ROUNDINGS), much more than z's own rounding
for a triangle seen edge on. There GL may keep either.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from reference.clipping import clip_triangles
from reference.depth_buffer import DEPTH_TIE_TOLERANCE
from reference.rasterizer import coverage, depth_planes, is_front_facing, setup_triangles
from reference.shadow.depth import STORE_TIE_ROUNDINGS, UNIT_ROUNDOFF32
from renderer.core.gl_rules import SUBPIXEL_BITS
from renderer.core.hemicube import FACES, ITEM_BACK_BIT, clip_from_world, depth_range


@dataclass
class Items:
    items: np.ndarray
    tied: np.ndarray


def _clip_coordinates(positions32: np.ndarray, matrices: np.ndarray) -> np.ndarray:
    """(F, V, 4) float32: the vertices through each face's matrix (F, 4, 4) as llvmpipe's
    vertex shader computes M * vec4(p, 1): column by column, each product and each sum
    rounded to float32 in turn, no fused multiply-add ((c0 x + c1 y) + c2 z) + c3 (measured
    bit for bit by transform feedback: tests/test_item_buffers.py)."""
    m = matrices.astype(np.float32)                                   # (F, 4 rows, 4 columns)
    p = positions32
    clip = m[:, None, :, 0] * p[None, :, 0, None]
    for k in (1, 2):
        clip = clip + m[:, None, :, k] * p[None, :, k, None]
    return clip + m[:, None, :, 3]


def draw_hemicube(positions32: np.ndarray, matrices: np.ndarray, resolution: int, horizon: int | None = None):
    """One hemicube's five layers: (items (5, N, N) uint32, tied (5, N, N) bool), row 0 at the
    top. `positions32`: (3 E, 3) float32, element e's corners at rows 3e .. 3e + 2. `horizon`
    (N / 2 by default): the GL rows below it on a side face are not drawn; 0 for whole views
    (a light's, `draw_views`), whatever their number."""
    n, faces = resolution, len(matrices)
    elements = len(positions32) // 3
    clip = _clip_coordinates(positions32, matrices).reshape(faces * elements, 3, 4)
    clipped = clip_triangles(clip, reversed_z=True)
    window = setup_triangles(clipped.gl_Position, n, n, SUBPIXEL_BITS, reversed_z=True)
    keep = window.area2 != 0                               # zero area draws nothing
    window, source = window.select(keep), clipped.source[keep]
    layer, element = source // elements, source % elements
    x0, y0, z0, dzdx, dzdy = depth_planes(window)
    pixel_parts, z_parts, t_parts, slack_parts = [], [], [], []
    horizon = n // 2 if horizon is None else horizon       # glsl's u_horizon
    for t, px, py in coverage(window, n, n):
        above = (layer[t] == 0) | (py >= horizon)          # a side face: its upper half only
        t, px, py = t[above], px[above], py[above]
        cx, cy = px + 0.5, py + 0.5
        z = z0[t] + dzdx[t] * (cx - x0[t]) + dzdy[t] * (cy - y0[t])
        pixel_parts.append((layer[t] * n + py) * n + px)
        z_parts.append(np.clip(z, 0.0, 1.0))
        t_parts.append(t)
        # how far llvmpipe's float32 plane, set up and evaluated from the window origin, may lie
        # from this one (reference/shadow/depth.py's STORE_TIE_ROUNDINGS)
        slack_parts.append(STORE_TIE_ROUNDINGS * UNIT_ROUNDOFF32 * (np.abs(z) + np.abs(dzdx[t]) * cx
                                                                      + np.abs(dzdy[t]) * cy))
    items = np.zeros(faces * n * n, np.uint32)
    tied = np.zeros(faces * n * n, bool)
    pixel, z, t, slack = (np.concatenate(p) if p else np.zeros(0)
                          for p in (pixel_parts, z_parts, t_parts, slack_parts))
    if len(pixel):
        order = np.lexsort((t, -z, pixel))                 # nearest (largest z_w) first, then drawn first
        pixel, z, t, slack = pixel[order], z[order], t[order], slack[order]
        first = np.flatnonzero(np.r_[True, pixel[1:] != pixel[:-1]])
        winner = t[first]
        items[pixel[first]] = ((element[winner] + 1).astype(np.uint32)
                               | np.where(is_front_facing(window.area2[winner]), 0, ITEM_BACK_BIT).astype(np.uint32))
        has_second = np.r_[first[1:], len(pixel)] - first > 1
        second = np.minimum(first + 1, len(pixel) - 1)
        close = has_second & (z[first] - z[second] <= np.maximum(DEPTH_TIE_TOLERANCE * np.abs(z[first]),
                                                                 slack[first] + slack[second]))
        tied[pixel[first][close]] = True
    shape = (faces, n, n)
    return items.reshape(shape)[:, ::-1], tied.reshape(shape)[:, ::-1]      # GL rows to row 0 top


def _positions32(elements) -> np.ndarray:
    """(3 E, 3) float32: the elements' corners relative to their centre, as the GPU's buffer."""
    origin, _ = elements.extent()
    return (elements.corners - origin).astype(np.float32).reshape(-1, 3)


def draw(elements, resolution: int, indices=None) -> Items:
    """The item buffers of the hemicubes on `elements`' `indices` (all by default), as
    renderer/gpu/item_buffers.py ItemBuffers draws them."""
    indices = np.arange(len(elements)) if indices is None else np.asarray(indices, np.int64)
    origin, diameter = elements.extent()
    near, far = depth_range(elements.shortest_edge(), diameter)
    positions32 = _positions32(elements)
    matrices = clip_from_world(elements.frames()[indices], elements.centres[indices], origin, near, far)
    drawn = [draw_hemicube(positions32, m, resolution) for m in matrices]
    shape = (0, len(FACES), resolution, resolution)
    return Items(np.stack([d[0] for d in drawn]) if drawn else np.zeros(shape, np.uint32),
                 np.stack([d[1] for d in drawn]) if drawn else np.zeros(shape, bool))


def draw_views(elements, resolution: int, matrices) -> Items:
    """The item buffers of whole views (F, 4, 4) of `elements` (a light's,
    renderer/core/light_buffers.py), as ItemBuffers.views draws them: (F, N, N), row 0 at the
    top, every row drawn."""
    items, tied = draw_hemicube(_positions32(elements), np.asarray(matrices, np.float64), resolution, horizon=0)
    return Items(items, tied)


class ItemBuffers:
    """The twin of renderer/gpu/item_buffers.py's ItemBuffers for radiosity's solve
    (renderer/core/radiosity.py `refreshed`): `draw(indices)` hemicubes, `batch` of them at a
    time, and `views(matrices)`, the items only."""
    batch = 16                      # hemicubes summed at once (each drawn on its own)

    def __init__(self, elements, resolution: int):
        self.elements, self.resolution = elements, int(resolution)

    def draw(self, indices) -> np.ndarray:
        return draw(self.elements, self.resolution, indices).items

    def views(self, matrices) -> np.ndarray:
        return draw_views(self.elements, self.resolution, matrices).items
