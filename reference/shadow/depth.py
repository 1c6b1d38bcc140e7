"""# Twin: glsl/shadow/depth.vert, glsl/shadow/depth.frag

The shadow maps' depth pass: each `ShadowPass` of a frame's `ShadowPlan` draws its casters
into its layer of its light kind's array texture, as GL draws them with the viewport at (0, 0), R x R on
that layer: gl_Position = u_clip_from_model * vec4(in_position, 1) with u_clip_from_model =
pass.clip_from_world @ model (camera-relative), clipping with standard depth
(z_w = (z_ndc + 1) / 2), snapping with SUBPIXEL_BITS, no culling, the reference rasteriser's
coverage (reference/rasterizer.py `coverage`: the same edge functions and fill rule), z_w on
the triangle's affine plane (`depth_planes`, what `rasterize` interpolates), clamped to
[0, 1] as GL does before its test, and the GL_LESS test against 1.0 (of equal depths the
first drawn stays). Depth only: no varyings, no perspective weights; a large map is drawn
band by band (REFERENCE_TILE_PIXELS), so its memory stays bounded.

Output, `ShadowLayers` (every array (layers, S, S), GL rows: row 0 at the bottom, texel (x, y)
of layer l at [l, y, x]; texels a pass did not draw, and those beyond its R x R, as cleared):
  depth      float32, 1.0 where nothing was drawn, else the winner's z_w rounded to float32
             (what a DEPTH_COMPONENT32F texture stores);
  caster     int32, the object index that won the texel (-1: none), to tell acne (a receiver
             shadowing itself) from a shadow;
  tolerance  float32, how far GL's stored depth may lie from `depth` (z_w units,
             STORE_TIE_ROUNDINGS below): the lookup's ties (lookup.py) add it;
  below, above  float32 >= 0, how much nearer (below) and farther (above) than `depth` GL's
             stored depth may be because its float32 vertex positions may snap to the
             neighbouring sub-pixel (SNAP_TIE_ROUNDINGS below), so that a triangle covers a
             texel centre near its edge in GL and not here, or the other way round: the
             nearest depth of the triangles that may cover the texel, and of those that surely
             do (1.0: none). 0 wherever no vertex near the texel is in doubt (almost all).
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from reference.clipping import clip_triangles
from reference.rasterizer import WindowTriangles, coverage, depth_planes, edge_equations, setup_triangles
from renderer.core.gl_rules import SUBPIXEL_BITS, is_inside_edge, pixel_centre
from renderer.core.memory import REFERENCE_TILE_PIXELS
from renderer.core.shadows import SHADOW_KINDS

# llvmpipe sets up and evaluates the depth plane in float32 from the window origin (a0 at
# (0, 0), then a0 + dz/dx x + dz/dy y: lp_state_setup.c calc_coef4, lp_bld_interp.c), so its
# stored depth is off the exact plane by rounding of the size of 2^-24 (|z| + |dz/dx| x +
# |dz/dy| y) (docs/llvmpipe/shadow-sampler.md section 5), plus its float32 vertex
# transform moving the vertices by 2^-24 times the magnitude of the products that make them.
# Every map is drawn from texel (0, 0) of its layer, so x, y < R. The bound below is that sum
# times STORE_TIE_ROUNDINGS: the roundings of the vertex product (4 terms), the plane's set-up
# (3) and its evaluation (2) would be 9 at worst. Measured against llvmpipe (the 14 built-in
# scenes at 320x240, automatic resolutions, maps of 512 and 1024; tests/test_shadow_depth.py's
# comparison): coverage identical, the largest error 2.47 of them (tir_bubble; 1.8 or less
# elsewhere): 5 is twice what was seen. (At a forced 2048 some scenes differ in a texel's
# coverage and reach 9 to 22 roundings: float32 vertex positions this model does not follow.)
STORE_TIE_ROUNDINGS = 5
# GL snaps x_w = (x_clip / w + 1) R / 2 to 1 / 2^SUBPIXEL_BITS computed in float32: x_clip and
# w are 4-term products (up to 4 roundings each of the products' magnitude |M_x|.|p| and
# |M_w|.|p|), the division 1 rounding of |x_ndc| <= 1, the viewport's multiply-add 1 of x_w
# <= R; in texels that is at most ~7 roundings of the triangle's `vertex_error`
# ((|M_x|.|p| + |M_w|.|p|) / w R / 2, >= R / 2). SNAP_TIE_ROUNDINGS = 8 of them: a vertex
# whose float64 position (in sub-pixel units) lies that close to a rounding boundary n + 1/2
# may snap one unit the other way in GL (seen: shadow_room 640x480, 32082.506 here, 32082.5
# in float32, rounded to even). Moving an edge's endpoints a = (xa, ya), b by e, f in
# {-1, 0, 1}^2 changes its edge function at p by exactly
#   e_x (y_b - p_y) + e_y (p_x - x_b) + f_x (p_y - y_a) + f_y (x_a - p_x) + f_y e_x - f_x e_y,
# at most (|e_x| + |f_x|) H + (|e_y| + |f_y|) W + |f_y e_x| + |f_x e_y| for p in the
# triangle's box (W, H its sides plus 2, sub-pixel units): the edge's margin (`snap_margin`).
SNAP_TIE_ROUNDINGS = 8
UNIT_ROUNDOFF32 = 2.0 ** -24


@dataclass
class ShadowLayers:
    depth: np.ndarray
    caster: np.ndarray
    tolerance: np.ndarray
    below: np.ndarray
    above: np.ndarray

    @classmethod
    def cleared(cls, layers: int, side: int) -> "ShadowLayers":
        """Cleared to depth 1.0, caster -1, tolerance, below and above 0."""
        shape = (layers, side, side)
        return cls(np.ones(shape, np.float32), np.full(shape, -1, np.int32),
                   *(np.zeros(shape, np.float32) for _ in range(3)))

    @property
    def side(self) -> int:
        return self.depth.shape[1]


def clip_from_model(shadow_pass, model) -> np.ndarray:
    """u_clip_from_model of the depth pass, float64 (4, 4)."""
    return np.asarray(shadow_pass.clip_from_world, np.float64) @ np.asarray(model, np.float64)


def caster_mesh(scene, matrices, shadow_pass, index: int):
    """(mesh, u_clip_from_model) a pass draws of caster `index`: an analytic plane's polygon in
    the pass's volume (pass.polygons; camera-relative world, so the identity model), else the
    object's mesh through its model matrix."""
    if index in shadow_pass.polygons:
        return shadow_pass.polygons[index], np.asarray(shadow_pass.clip_from_world, np.float64)
    return scene.objects[index].mesh, clip_from_model(shadow_pass, matrices.objects[index].model)


def _caster_triangles(mesh, clip_from_model_matrix, dtype):
    """(T, 3, 4) clip coordinates of a mesh's triangles in `dtype`, and (T, 4) the magnitude
    of the products that made each coordinate (largest over the triangle's vertices, float64):
    the scale of float32 rounding in GL's vertex stage."""
    positions = np.asarray(mesh.positions, np.float64)
    homogeneous = np.concatenate([positions, np.ones((len(positions), 1))], axis=1)
    matrix = clip_from_model_matrix.astype(dtype)
    clip = homogeneous.astype(dtype) @ matrix.T
    magnitude = np.abs(homogeneous) @ np.abs(clip_from_model_matrix).T
    faces = np.asarray(mesh.faces, np.int64)
    return clip[faces], magnitude[faces].max(axis=1)


@dataclass
class _PassTriangles:
    """A pass's casters' window triangles in draw order (caster by caster, each in its mesh's
    triangle order), zero-area ones dropped."""
    window: WindowTriangles
    caster: np.ndarray            # (T,) object index
    plane: tuple                  # depth_planes(window)
    vertex_error: np.ndarray      # (T, 3) window x, y (texels), z: rounding scale of the vertices
    margin: np.ndarray            # (3, T) int64 snap_margin: edges whose coverage is in doubt


def snap_margin(window: WindowTriangles, vertex_error: np.ndarray) -> np.ndarray:
    """(3, T) int64: by how much each edge function (row k: the edge opposite vertex k, as
    rasterizer.edge_equations) may differ in GL, whose float32 vertex positions may snap to
    the neighbouring sub-pixel where the float64 ones lie within SNAP_TIE_ROUNDINGS roundings
    of `vertex_error` (T, 3 texels) of a rounding boundary; 0 where no endpoint is in doubt."""
    one = 1 << window.subpixel_bits
    doubt = SNAP_TIE_ROUNDINGS * UNIT_ROUNDOFF32 * one * np.asarray(vertex_error[:, :2], np.float64)

    def may_flip(position, band):                 # (T, 3) bool
        s = np.asarray(position, np.float64) * one
        return np.abs(s - np.floor(s) - 0.5) <= band[:, None]

    fx = may_flip(window.x_w, doubt[:, 0]).astype(np.int64)
    fy = may_flip(window.y_w, doubt[:, 1]).astype(np.int64)
    width = (np.ptp(window.x, axis=1) + 2)[:, None]
    height = (np.ptp(window.y, axis=1) + 2)[:, None]
    start, end = [1, 2, 0], [2, 0, 1]
    margin = ((fx[:, start] + fx[:, end]) * height + (fy[:, start] + fy[:, end]) * width
              + fx[:, start] * fy[:, end] + fy[:, start] * fx[:, end])
    return margin.T


def _pass_triangles(scene, matrices, shadow_pass, dtype) -> _PassTriangles:
    """The pass's casters' triangles, all at once (clipping keeps each source triangle's place,
    so the draw order is the casters', each in its mesh's order): clipped, set up at the
    tile's size, zero-area ones dropped (no culling)."""
    size = shadow_pass.tile.size
    parts = [_caster_triangles(*caster_mesh(scene, matrices, shadow_pass, index), dtype)
             for index in shadow_pass.casters]
    triangles = np.concatenate([p[0] for p in parts])
    magnitude = np.concatenate([p[1] for p in parts])
    caster = np.concatenate([np.full(len(p[0]), index, np.int32)
                             for index, p in zip(shadow_pass.casters, parts)])
    clipped = clip_triangles(triangles, reversed_z=False)
    window = setup_triangles(clipped.gl_Position, size, size, SUBPIXEL_BITS, reversed_z=False)
    keep = window.area2 != 0                          # no culling; zero area draws nothing
    window, source = window.select(keep), clipped.source[keep]
    w = np.abs(np.asarray(clipped.gl_Position[keep][..., 3], np.float64)).min(axis=1)
    m = magnitude[source]
    # a window coordinate (ndc + 1) * size / 2 moves by the rounding of x_clip / w: the
    # products' magnitude (x and w) over w, in texels; z_w = (z_ndc + 1) / 2 likewise
    scale = (m[:, 3] + m[:, :3].T).T / w[:, None]
    error = scale * np.array([size / 2.0, size / 2.0, 0.5])
    return _PassTriangles(window, caster[source], depth_planes(window), error,
                          snap_margin(window, error))


NONE = np.iinfo(np.int64).max


def _nearest_first(z_buffer, winner, first, texel, z, triangle) -> None:
    """GL_LESS over one batch (`triangle`: draw order): per texel the batch's smallest z, the
    earliest drawn of equal ones, replaces the stored one only if strictly nearer (the stored
    one was drawn before). `first`: scratch, NONE everywhere, left so."""
    before = z_buffer[texel]
    np.minimum.at(z_buffer, texel, z)
    after = z_buffer[texel]
    best = np.flatnonzero((after < before) & (z == after))
    changed = texel[best]
    np.minimum.at(first, changed, triangle[best])
    winner[changed] = first[changed]
    first[changed] = NONE


def _tolerance(tris: _PassTriangles, t, x, y, z) -> np.ndarray:
    """The per-texel bound of GL's stored depth (STORE_TIE_ROUNDINGS) for winners t at texels
    (x, y) of depth z: roundings of |z| + |dz/dx| x + |dz/dy| y at the texel centre, the
    vertices' errors carried along the plane."""
    gx, gy = (np.abs(np.asarray(g, np.float64)) for g in tris.plane[3:])
    error = tris.vertex_error
    constant = error[:, 2] + gx * (0.5 + error[:, 0]) + gy * (0.5 + error[:, 1])
    return STORE_TIE_ROUNDINGS * UNIT_ROUNDOFF32 * (np.abs(z) + constant[t] + gx[t] * x + gy[t] * y)


def _texel_depth(plane, t, px, py, dtype) -> np.ndarray:
    """Triangles t's z_w at texel centres (px, py), clamped to [0, 1] as GL does before its
    depth test."""
    x0, y0, z0, dzdx, dzdy = plane
    cx, cy = (px + 0.5).astype(dtype), (py + 0.5).astype(dtype)
    return np.clip(z0[t] + dzdx[t] * (cx - x0[t]) + dzdy[t] * (cy - y0[t]), 0, 1)


def _surely_covered(edges, margin, in_doubt, t, px, py) -> np.ndarray:
    """Whether triangles t cover texels (px, py) whatever GL's snapping (`snap_margin`): in no
    doubt, or inside every edge moved inwards by its margin."""
    sure = ~in_doubt[t]
    d = np.flatnonzero(~sure)
    t, cx, cy = t[d], pixel_centre(px[d], SUBPIXEL_BITS), pixel_centre(py[d], SUBPIXEL_BITS)
    sure[d] = np.logical_and.reduce([
        is_inside_edge(edges.a[k, t] * cy - edges.b[k, t] * cx + edges.c[k, t] - margin[k, t],
                       edges.inclusive[k, t]) for k in range(3)])
    return sure


def _ring(tris: _PassTriangles, doubt, band0, size, region, dtype):
    """The band's (texel, triangle, depth) (N,) each that a doubtful triangle (`doubt`: their
    indices) may cover but not surely: within the margins of its edges (`snap_margin`); the
    depth less its store tolerance (`_tolerance`: the nearest GL may store there)."""
    texels, triangles, depths = [np.zeros(0, np.int64)], [np.zeros(0, np.int64)], [np.zeros(0, dtype)]
    for t, px, py in coverage(tris.window.select(doubt), size, size, region=region,
                              margin=tris.margin[:, doubt]):
        z = _texel_depth(tris.plane, doubt[t], px, py, dtype)
        texels.append((py - band0) * size + px)
        triangles.append(doubt[t])
        depths.append(z - _tolerance(tris, doubt[t], px, py, z))
    return np.concatenate(texels), np.concatenate(triangles), np.concatenate(depths)


def draw_pass(scene, matrices, shadow_pass, layers: ShadowLayers, dtype=np.float64,
              tile_pixels: int = REFERENCE_TILE_PIXELS) -> None:
    """Draw one pass's casters into texels [0, R)^2 of its layer (band by band), and where GL's
    snapping may change a triangle's coverage, the range of depths it may store (below, above:
    `_ring`)."""
    size, layer = shadow_pass.tile.size, shadow_pass.tile.layer
    tris = _pass_triangles(scene, matrices, shadow_pass, dtype)
    doubt = np.flatnonzero(tris.margin.any(axis=0))      # triangles with a margin
    in_doubt = np.zeros(len(tris.window), bool)
    in_doubt[doubt] = True
    edges = edge_equations(tris.window)
    rows = max(1, tile_pixels // size)
    # one band's buffers, made once and refilled: a fresh array a band costs its page faults
    # again (most of a large map's time); `first` is left NONE by _nearest_first
    scratch = min(rows, size) * size
    z_all, winner_all, in_ring_all = np.empty(scratch, dtype), np.empty(scratch, np.int64), np.empty(scratch, bool)
    behind_all, first = np.empty(scratch, dtype), np.full(scratch, NONE)
    for band0 in range(0, size, rows):
        band1 = min(band0 + rows, size)
        region = (0, band0, size, band1)
        count = (band1 - band0) * size
        z_buffer, winner, in_ring, behind = (a[:count] for a in (z_all, winner_all, in_ring_all, behind_all))
        z_buffer.fill(1.0)
        winner.fill(-1)
        in_ring.fill(False)
        behind.fill(1.0)        # at ring texels: the nearest sure cover + tolerance
        ring_texel, ring_triangle, ring_z = _ring(tris, doubt, band0, size, region, dtype)
        in_ring[ring_texel] = True
        for t, px, py in coverage(tris.window, size, size, region=region):
            texel, z = (py - band0) * size + px, _texel_depth(tris.plane, t, px, py, dtype)
            _nearest_first(z_buffer, winner, first, texel, z, t)
            ring = np.flatnonzero(in_ring[texel])
            ring = ring[_surely_covered(edges, tris.margin, in_doubt, t[ring], px[ring], py[ring])]
            farthest = z[ring] + _tolerance(tris, t[ring], px[ring], py[ring], z[ring])
            np.minimum.at(behind, texel[ring], farthest)
        # GL may store a ring triangle's depth where it did not win here (below: down to the
        # nearest of them), or, where it won here, not (above: up to the nearest sure cover),
        # each give or take its store tolerance
        where, index = np.unique(ring_texel, return_inverse=True)
        nearest = z_buffer[where].copy()
        np.minimum.at(nearest, index, ring_z)
        layers.below[layer, where // size + band0, where % size] = z_buffer[where] - nearest
        unsure = ring_texel[winner[ring_texel] == ring_triangle]
        layers.above[layer, unsure // size + band0, unsure % size] = behind[unsure] - z_buffer[unsure]
        texels = np.flatnonzero(winner >= 0)         # the rest stay cleared
        t, x, y = winner[texels], texels % size, texels // size + band0
        depth = z_buffer[texels].astype(np.float64)
        layers.depth[layer, y, x] = depth.astype(np.float32)
        layers.caster[layer, y, x] = tris.caster[t]
        layers.tolerance[layer, y, x] = _tolerance(tris, t, x, y, depth)


def render_layers(scene, matrices, plan, dtype=np.float64,
                  tile_pixels: int = REFERENCE_TILE_PIXELS) -> dict[str, ShadowLayers]:
    """The frame's maps, per kind of light (renderer/core/shadows.py SHADOW_KINDS): its stack's
    layers of its side cleared, then every pass of that kind drawn into its layer."""
    stacks = {kind: ShadowLayers.cleared(plan.layout.stack(kind).layers, plan.layout.stack(kind).side)
              for kind in SHADOW_KINDS}
    for shadow_pass in plan.passes:
        draw_pass(scene, matrices, shadow_pass, stacks[shadow_pass.kind], dtype, tile_pixels)
    return stacks
