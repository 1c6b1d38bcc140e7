"""# Twin: glsl/shadow/depth.vert, glsl/shadow/depth.frag

The shadow maps' depth pass: each `ShadowPass` of a frame's `ShadowPlan` draws its casters
into its tile of the atlas with the reference's own rasteriser, as GL draws them with the
viewport on the tile: gl_Position = u_clip_from_model * vec4(in_position, 1) with
u_clip_from_model = pass.clip_from_world @ model (camera-relative), clipping with standard
depth (z_w = (z_ndc + 1) / 2), snapping with SUBPIXEL_BITS, no culling, the fill rule, and the
GL_LESS depth test against 1.0 (of equal depths the first drawn stays). A large tile is drawn
band by band (REFERENCE_TILE_PIXELS), so its memory stays bounded.

Output, `ShadowAtlas` (every array (S, S), GL rows: row 0 at the bottom, atlas texel (x, y) at
[y, x]):
  depth      float32, 1.0 where nothing was drawn, else the winner's z_w rounded to float32
             (what a DEPTH_COMPONENT32F texture stores);
  caster     int32, the object index that won the texel (-1: none), to tell acne (a receiver
             shadowing itself) from a shadow;
  tolerance  float32, how far GL's stored depth may lie from `depth` (z_w units,
             STORE_TIE_ROUNDINGS below): the lookup's ties (lookup.py) add it.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from reference.clipping import clip_triangles
from reference.depth_buffer import DepthBuffer
from reference.rasterizer import rasterize, setup_triangles
from renderer.core.gl_rules import SUBPIXEL_BITS
from renderer.core.memory import REFERENCE_TILE_PIXELS

# llvmpipe sets up and evaluates the depth plane in float32 at ABSOLUTE window coordinates
# (a0 at the window origin, then a0 + dz/dx x + dz/dy y: lp_state_setup.c calc_coef4,
# lp_bld_interp.c), so its stored depth is off the exact plane by rounding of the size of
# 2^-24 (|z| + |dz/dx| x + |dz/dy| y) (measured: up to 8784 ulps, 3e-4, at texel (2976, 1472);
# /work/notes/llvmpipe-shadow-sampler.md section 6), plus its float32 vertex transform moving
# the vertices by 2^-24 times the magnitude of the products that make them. The bound below
# is that sum times STORE_TIE_ROUNDINGS: the roundings of the vertex product (4 terms), the
# plane's set-up (3) and its evaluation (2) would be 9 at worst, and measured against llvmpipe
# (five built-in scenes at 320x240, atlases of 2048 and 4096, tests/test_shadow_depth.py) the
# largest error was 3.7 of them (4872 ulps at a 4096 atlas): 8 is twice what was seen.
STORE_TIE_ROUNDINGS = 8
UNIT_ROUNDOFF32 = 2.0 ** -24


@dataclass
class ShadowAtlas:
    depth: np.ndarray
    caster: np.ndarray
    tolerance: np.ndarray

    @property
    def side(self) -> int:
        return self.depth.shape[0]


def clip_from_model(shadow_pass, model) -> np.ndarray:
    """u_clip_from_model of the depth pass, float64 (4, 4)."""
    return np.asarray(shadow_pass.clip_from_world, np.float64) @ np.asarray(model, np.float64)


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


def _plane_gradients(window) -> tuple[np.ndarray, np.ndarray]:
    """(dz/dx, dz/dy) per window triangle, in z_w per texel (float64)."""
    x, y, z = (np.asarray(a, np.float64) for a in (window.x_w, window.y_w, window.z_w))
    dx1, dy1, dz1 = x[:, 1] - x[:, 0], y[:, 1] - y[:, 0], z[:, 1] - z[:, 0]
    dx2, dy2, dz2 = x[:, 2] - x[:, 0], y[:, 2] - y[:, 0], z[:, 2] - z[:, 0]
    area = dx1 * dy2 - dx2 * dy1
    area = np.where(area != 0, area, np.inf)          # no area: no fragments to bound
    return (dz1 * dy2 - dz2 * dy1) / area, (dx1 * dz2 - dx2 * dz1) / area


@dataclass
class _PreparedCaster:
    index: int
    window: object                # WindowTriangles, zero-area ones dropped
    source: np.ndarray            # (T,) mesh triangle of each
    dzdx: np.ndarray
    dzdy: np.ndarray
    vertex_error: np.ndarray      # (T, 3) window x, y (texels), z: rounding scale of the vertices


def _prepare_caster(index, mesh, matrix, size, dtype) -> _PreparedCaster:
    triangles, magnitude = _caster_triangles(mesh, matrix, dtype)
    clipped = clip_triangles(triangles, reversed_z=False)
    window = setup_triangles(clipped.gl_Position, size, size, SUBPIXEL_BITS, reversed_z=False)
    keep = window.area2 != 0                          # no culling; zero area draws nothing
    window, source = window.select(keep), clipped.source[keep]
    w = np.abs(np.asarray(clipped.gl_Position[keep][..., 3], np.float64)).min(axis=1)
    m = magnitude[source]
    # a window coordinate (ndc + 1) * size / 2 moves by the rounding of x_clip / w: the
    # products' magnitude (x and w) over w, in texels; z_w = (z_ndc + 1) / 2 likewise
    scale = (m[:, 3] + m[:, :3].T).T / w[:, None]
    vertex_error = scale * np.array([size / 2.0, size / 2.0, 0.5])
    dzdx, dzdy = _plane_gradients(window)
    return _PreparedCaster(index, window, source, dzdx, dzdy, vertex_error)


def draw_pass(scene, matrices, shadow_pass, atlas: ShadowAtlas, dtype=np.float64,
              tile_pixels: int = REFERENCE_TILE_PIXELS) -> None:
    """Draw one pass's casters into its tile of `atlas` (band by band)."""
    tile, size = shadow_pass.tile, shadow_pass.tile.size
    casters, first_orders, order = [], [], 0
    for index in shadow_pass.casters:
        obj = scene.objects[index]
        matrix = clip_from_model(shadow_pass, matrices.objects[index].model)
        casters.append(_prepare_caster(index, obj.mesh, matrix, size, dtype))
        first_orders.append(order)
        order += len(obj.mesh.faces)
    rows = max(1, tile_pixels // size)
    for y0 in range(0, size, rows):
        y1 = min(y0 + rows, size)
        region = (0, y0, size, y1)
        buffer = DepthBuffer(size, y1 - y0, dtype, reversed_z=False)
        for caster, first in zip(casters, first_orders):
            for fragments in rasterize(caster.window, size, size, region=region):
                t = fragments.triangle
                x_abs = (tile.x + fragments.x + 0.5).astype(np.float64)
                y_abs = (tile.y + fragments.y + 0.5).astype(np.float64)
                error = caster.vertex_error[t]
                z = np.asarray(fragments.z_w, np.float64)
                tolerance = STORE_TIE_ROUNDINGS * UNIT_ROUNDOFF32 * (
                    np.abs(z) + error[:, 2] + np.abs(caster.dzdx[t]) * (x_abs + error[:, 0])
                    + np.abs(caster.dzdy[t]) * (y_abs + error[:, 1]))
                buffer.test_and_write((fragments.y - y0) * size + fragments.x, fragments.z_w,
                                      first + caster.source[t],
                                      object=np.full(len(t), caster.index, np.int32),
                                      tolerance=tolerance)
        drawn = buffer.drawn.reshape(y1 - y0, size)
        rows_at = slice(tile.y + y0, tile.y + y1)
        cols_at = slice(tile.x, tile.x + size)
        # GL clamps a fragment's depth to [0, 1] and stores it as float32
        stored = np.clip(np.asarray(buffer.z, np.float64), 0.0, 1.0).astype(np.float32)
        atlas.depth[rows_at, cols_at] = np.where(drawn, stored.reshape(drawn.shape), np.float32(1.0))
        if buffer.payload:
            atlas.caster[rows_at, cols_at] = np.where(
                drawn, buffer.payload["object"].reshape(drawn.shape), -1)
            atlas.tolerance[rows_at, cols_at] = np.where(
                drawn, buffer.payload["tolerance"].reshape(drawn.shape), 0.0)


def render_atlas(scene, matrices, plan, dtype=np.float64,
                 tile_pixels: int = REFERENCE_TILE_PIXELS) -> ShadowAtlas:
    """The frame's atlas: cleared to 1.0 (caster -1, tolerance 0), then every pass drawn."""
    side = plan.atlas_side
    atlas = ShadowAtlas(np.ones((side, side), np.float32), np.full((side, side), -1, np.int32),
                        np.zeros((side, side), np.float32))
    for shadow_pass in plan.passes:
        draw_pass(scene, matrices, shadow_pass, atlas, dtype, tile_pixels)
    return atlas
