"""# Twin: glsl/shadow/depth.vert, glsl/shadow/depth.frag

The shadow maps' depth pass: each `ShadowPass` of a frame's `ShadowPlan` draws its casters
into its layer of the array texture, as GL draws them with the viewport at (0, 0), R x R on
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
             STORE_TIE_ROUNDINGS below): the lookup's ties (lookup.py) add it.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from reference.clipping import clip_triangles
from reference.rasterizer import WindowTriangles, coverage, depth_planes, setup_triangles
from renderer.core.gl_rules import SUBPIXEL_BITS
from renderer.core.memory import REFERENCE_TILE_PIXELS

# llvmpipe sets up and evaluates the depth plane in float32 from the window origin (a0 at
# (0, 0), then a0 + dz/dx x + dz/dy y: lp_state_setup.c calc_coef4, lp_bld_interp.c), so its
# stored depth is off the exact plane by rounding of the size of 2^-24 (|z| + |dz/dx| x +
# |dz/dy| y) (/work/notes/llvmpipe-shadow-sampler.md section 5), plus its float32 vertex
# transform moving the vertices by 2^-24 times the magnitude of the products that make them.
# Every map is drawn from texel (0, 0) of its layer, so x, y < R. The bound below is that sum
# times STORE_TIE_ROUNDINGS: the roundings of the vertex product (4 terms), the plane's set-up
# (3) and its evaluation (2) would be 9 at worst. Measured against llvmpipe (the 14 built-in
# scenes at 320x240, automatic resolutions, maps of 512 and 1024; tests/test_shadow_depth.py's
# comparison): coverage identical, the largest error 2.47 of them (tir_bubble; 1.8 or less
# elsewhere): 5 is twice what was seen. (At a forced 2048 some scenes differ in a texel's
# coverage and reach 9 to 22 roundings: float32 vertex positions this model does not follow.)
STORE_TIE_ROUNDINGS = 5
UNIT_ROUNDOFF32 = 2.0 ** -24


@dataclass
class ShadowLayers:
    depth: np.ndarray
    caster: np.ndarray
    tolerance: np.ndarray

    @classmethod
    def cleared(cls, layers: int, side: int) -> "ShadowLayers":
        """Cleared to depth 1.0, caster -1, tolerance 0."""
        shape = (layers, side, side)
        return cls(np.ones(shape, np.float32), np.full(shape, -1, np.int32), np.zeros(shape, np.float32))

    @property
    def side(self) -> int:
        return self.depth.shape[1]


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


@dataclass
class _PassTriangles:
    """A pass's casters' window triangles in draw order (caster by caster, each in its mesh's
    triangle order), zero-area ones dropped."""
    window: WindowTriangles
    caster: np.ndarray            # (T,) object index
    plane: tuple                  # depth_planes(window)
    vertex_error: np.ndarray      # (T, 3) window x, y (texels), z: rounding scale of the vertices


def _prepare_caster(index, mesh, matrix, size, dtype):
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
    return window, np.full(len(source), index, np.int32), scale * np.array([size / 2.0, size / 2.0, 0.5])


def _pass_triangles(scene, matrices, shadow_pass, dtype) -> _PassTriangles:
    parts = [_prepare_caster(index, scene.objects[index].mesh,
                             clip_from_model(shadow_pass, matrices.objects[index].model),
                             shadow_pass.tile.size, dtype)
             for index in shadow_pass.casters]
    window = WindowTriangles.concatenate([p[0] for p in parts])
    return _PassTriangles(window, np.concatenate([p[1] for p in parts]), depth_planes(window),
                          np.concatenate([p[2] for p in parts]))


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


def draw_pass(scene, matrices, shadow_pass, layers: ShadowLayers, dtype=np.float64,
              tile_pixels: int = REFERENCE_TILE_PIXELS) -> None:
    """Draw one pass's casters into texels [0, R)^2 of its layer (band by band)."""
    size, layer = shadow_pass.tile.size, shadow_pass.tile.layer
    tris = _pass_triangles(scene, matrices, shadow_pass, dtype)
    x0, y0, z0, dzdx, dzdy = tris.plane
    rows = max(1, tile_pixels // size)
    for band0 in range(0, size, rows):
        band1 = min(band0 + rows, size)
        z_buffer = np.ones((band1 - band0) * size, dtype)
        winner = np.full(len(z_buffer), -1, np.int64)
        first = np.full(len(z_buffer), NONE)
        for t, px, py in coverage(tris.window, size, size, region=(0, band0, size, band1)):
            cx, cy = (px + 0.5).astype(dtype), (py + 0.5).astype(dtype)    # texel centres
            z = z0[t] + dzdx[t] * (cx - x0[t]) + dzdy[t] * (cy - y0[t])
            # GL clamps a fragment's depth to [0, 1] before its depth test
            _nearest_first(z_buffer, winner, first, (py - band0) * size + px, np.clip(z, 0, 1), t)
        drawn = winner >= 0
        texels = np.flatnonzero(drawn)
        t, x, y = winner[texels], texels % size, texels // size + band0
        depth = z_buffer[texels].astype(np.float64)
        at = (layer, slice(band0, band1), slice(0, size))
        layers.depth[at] = np.where(drawn, z_buffer, 1.0).astype(np.float32).reshape(-1, size)
        caster = np.full(len(z_buffer), -1, np.int32)
        caster[texels] = tris.caster[t]
        layers.caster[at] = caster.reshape(-1, size)
        tolerance = np.zeros(len(z_buffer), np.float32)
        tolerance[texels] = _tolerance(tris, t, x, y, depth)
        layers.tolerance[at] = tolerance.reshape(-1, size)


def render_layers(scene, matrices, plan, dtype=np.float64,
                  tile_pixels: int = REFERENCE_TILE_PIXELS) -> ShadowLayers:
    """The frame's maps: `plan.layout.layers` layers of side S cleared, then every pass drawn."""
    layers = ShadowLayers.cleared(plan.layout.layers, plan.side)
    for shadow_pass in plan.passes:
        draw_pass(scene, matrices, shadow_pass, layers, dtype, tile_pixels)
    return layers
