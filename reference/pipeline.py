"""# Twin: renderer/gpu/pipeline.py (the draw as a whole; each stage's twin is named in its module)

The reference draw, stage by stage as dEQP's drawBasicPrimitives reads: for each object in
scene order, vertex processing -> primitive assembly -> (flat: geometry stage) -> clipping
-> viewport transform and snapping -> facing and culling -> rasterisation -> depth test;
then fragment shading for the one surviving fragment per pixel, and output conversion. A
large frame runs the stages from rasterisation on band by band (TILE_PIXELS), so that its
memory stays bounded. Each object draws what the camera pass draws of it (renderer/core/drawn.py:
its mesh, or an analytic plane's polygon in the view volume, as the GPU path); objects wholly
outside the view volume are skipped (renderer/core/visibility.py, as the GPU path).
Where a pixel's runner-up is within depth precision of its winner (a depth tie, see
docs/conventions.md) the runner-up is shaded too, into Frame.rgba8_tie.
When the scene has shadow maps (renderer/core/shadows.py: shadow_layout(...).any), the
frame's maps are drawn first (reference/shadow/depth.py, a layer each) and receivers, of
every shading mode, look them up (reference/shadow/lookup.py); where a lookup had a tied tap, the pixel's colour with those
taps decided the other way goes into Frame.rgba8_tie too (a pixel with both kinds of tie
shows the depth tie's other surface there: either is an acceptable answer, and one
alternative per pixel is what compare takes), and Frame.shadow_ties marks those pixels.

`surface_pixels` runs the same stages up to the depth test and hands out the surface each
drawn pixel of a Phong object shows (P, the lit N, its triangle's plane normal, its object),
with the frame's shadow maps, for holding the fragment stage's inputs against another method
(renderer/checks/shadow_truth.py).

Input:  a `renderer.core.scene.Scene` and the image size. Output: a `renderer.core.frame.Frame`
(rgba8 (H, W, 4) uint8 row 0 at the top, optional linear (H, W, 4) float32, depth (H, W)
float32 -z_eye with +inf background). Conventions: docs/conventions.md.
"""

from __future__ import annotations

import time
from dataclasses import dataclass

import numpy as np

from reference.clipping import clip_triangles
from reference.depth_buffer import DepthBuffer
from reference.fragment import ObjectVaryings, facet_normal, lit_point, shade_fragments, world_facet_normals
from reference.geometry import shade_triangles
from reference.lighting import Lights, normalize_or_zero
from reference.framebuffer import compose_frame
from reference.rasterizer import WindowTriangles, is_drawn, rasterize, setup_triangles
from reference.shadow.depth import render_layers
from reference.shadow.lookup import ShadowMaps
from reference.tessellation.surface import tessellated_mesh
from reference.vertex import shade_vertices
from renderer.core.drawn import DrawnMesh, drawn_meshes
from renderer.core.facets import face_creases
from renderer.core.frame import Frame
from renderer.core.gl_rules import SUBPIXEL_BITS, check_light_count
from renderer.core.memory import REFERENCE_TILE_PIXELS
from renderer.core.shadows import plan_shadows, shadow_layout
from renderer.core.visibility import visible_objects


# A frame of more pixels than this is drawn in tiles of at most this many (bands of rows), so
# that the depth buffer, its runner-up and the fragment stage's arrays (about 300 bytes a
# pixel in float64) stay bounded however large the image: only the output arrays grow with it.
# Defined with the memory estimates that count on it (renderer/core/memory.py).
TILE_PIXELS = REFERENCE_TILE_PIXELS


@dataclass
class PreparedObject:
    """One object after vertex processing, clipping, the viewport transform and culling:
    what rasterisation needs for any tile, and the fragment stage's varyings."""
    varyings: ObjectVaryings
    window: WindowTriangles       # the drawn triangles in window coordinates
    source: np.ndarray            # (T,) the mesh triangle each came from
    clip_weights: np.ndarray      # (T, 3, 3) its vertices as weights of the source's


def prepare_object(obj, drawn: DrawnMesh, frame_matrices, lights: Lights, eye, width: int,
                   height: int, subpixel_bits: int, reversed_z: bool, dtype,
                   displace_lookup=None, index: int = -1, shadowed: bool = False) -> PreparedObject:
    """Vertex processing -> primitive assembly -> (flat: geometry stage) -> clipping ->
    viewport transform and snapping -> facing and culling, for one object: `drawn`, what the
    camera pass draws of it (renderer/core/drawn.py: its mesh, or a plane's polygon)."""
    mesh, matrices, material = drawn.mesh, drawn.matrices, obj.material
    if obj.tessellation is not None:      # the tessellation stages' points and triangles
        positions, normals, faces = tessellated_mesh(obj, matrices, frame_matrices.view,
                                                     frame_matrices.projection, height)
        in_uv = None
    else:
        positions, normals, faces = mesh.positions, mesh.normals, np.asarray(mesh.faces, dtype=np.int64)
        in_uv = obj.texture_coordinates(mesh)
    vertices = shade_vertices(positions, normals, u_model=matrices.model,
                              u_normal_matrix=matrices.normal, u_view=frame_matrices.view,
                              u_projection=frame_matrices.projection, u_eye=eye,
                              material=material, lights=lights, dtype=dtype, in_uv=in_uv)
                                                                           # primitive assembly
    triangles = (shade_triangles(vertices.v_world_position[faces], material, lights, eye,
                                 v_uv=None if vertices.v_uv is None else vertices.v_uv[faces])
                 if material.shading == "flat" else None)
    clipped = clip_triangles(vertices.gl_Position[faces], reversed_z)
    window = setup_triangles(clipped.gl_Position, width, height, subpixel_bits, reversed_z)
    keep = is_drawn(window.area2, obj.cull)
    # a mesh's facets are its surface; an analytic shape's triangles only stand in for it; a
    # tessellated sphere's lookup takes N and no crease (glsl/fragment.glsl, TESSELLATED)
    receiver = shadowed and obj.receives_shadows
    facets = world_facet_normals(mesh, matrices.normal, dtype) if receiver and obj.tessellation is None else None
    creases = face_creases(mesh) if receiver and obj.shape is None else None
    return PreparedObject(ObjectVaryings(material, faces, vertices, triangles, obj.receives_shadows,
                                         displace_lookup, index, facets, creases),
                          window.select(keep),
                          clipped.source[keep], clipped.weights[keep])


def draw_tile(index: int, prepared: PreparedObject, depth: DepthBuffer, first_order: int,
              width: int, height: int, region) -> None:
    """Rasterisation -> depth test of one prepared object within `region` (x0, y0, x1, y1),
    the tile `depth` covers.

    Draw order is first_order + the triangle's index in the mesh, so it is global across
    objects; the triangles a clipped triangle turns into share its order.
    """
    x0, y0, x1, _ = region
    source, clip_weights = prepared.source, prepared.clip_weights
    for fragments in rasterize(prepared.window, width, height, region=region):
        t = fragments.triangle
        # weights w.r.t. the source triangle's vertices: sum_k b_k * clip_weights[k, :]
        b, cw = fragments.barycentric, clip_weights[t]
        weights = b[:, 0:1] * cw[:, 0] + b[:, 1:2] * cw[:, 1] + b[:, 2:3] * cw[:, 2]
        depth.test_and_write((fragments.y - y0) * (x1 - x0) + (fragments.x - x0), fragments.z_w,
                             first_order + source[t],
                             object=np.full(len(t), index, dtype=np.int32), triangle=source[t],
                             weights=weights, gl_FrontFacing=fragments.gl_FrontFacing)


def tiles(width: int, height: int, tile_pixels: int = TILE_PIXELS) -> list[tuple[int, int, int, int]]:
    """The frame as bands of whole rows (x0, y0, x1, y1), GL rows, of at most `tile_pixels`
    pixels each (at least one row); one band when the frame is that small."""
    rows = max(1, tile_pixels // width)
    return [(0, y, width, min(y + rows, height)) for y in range(0, height, rows)]


def render(scene, width: int, height: int, *, dtype=np.float64, subpixel_bits: int = SUBPIXEL_BITS,
           linear: bool = False, depth: bool = True, sample_offset=(0.0, 0.0),
           tile_pixels: int = TILE_PIXELS, displace_lookup=None) -> Frame:
    """Render `scene` at width x height with the NumPy reference pipeline, each pixel sampled
    at `sample_offset` (dx, dy) pixels from its centre (Scene.matrices). A frame of more than
    `tile_pixels` pixels is drawn band by band (the same image: every stage after culling
    works pixel by pixel), so its memory beyond the output arrays stays bounded.
    `displace_lookup`: a check's only (reference/texture.py), None for the picture."""
    start = time.perf_counter()
    dtype = np.dtype(dtype)
    prepared = prepare_frame(scene, width, height, dtype, subpixel_bits, sample_offset, tile_pixels,
                             displace_lookup)
    bands = tiles(width, height, tile_pixels)
    if len(bands) == 1:
        frame = _render_tile(bands[0], prepared, scene, width, height, linear, depth, dtype)
    else:
        frame = _render_in_tiles(bands, prepared, scene, width, height, linear, depth, dtype)
    frame.milliseconds = (time.perf_counter() - start) * 1000.0
    return frame


@dataclass
class PreparedFrame:
    """What every tile of a frame starts from: the lights and the eye (camera-relative, in the
    pipeline's dtype), each object after culling (None: outside the view volume, skipped),
    its first draw order, and the frame's shadow maps (None: the scene has none)."""
    lights: Lights
    eye: np.ndarray
    objects: list[PreparedObject | None]
    first_orders: list[int]
    shadows: ShadowMaps | None

    @property
    def varyings(self) -> list[ObjectVaryings | None]:
        return [p.varyings if p is not None else None for p in self.objects]


def prepare_frame(scene, width: int, height: int, dtype, subpixel_bits: int = SUBPIXEL_BITS,
                  sample_offset=(0.0, 0.0), tile_pixels: int = TILE_PIXELS,
                  displace_lookup=None) -> PreparedFrame:
    """Every object through prepare_object (those in view), and the frame's shadow maps."""
    check_light_count(scene)             # the GPU's limit, held alike (renderer/core/gl_rules.py)
    frame_matrices = scene.matrices(width, height, sample_offset)
    # Camera-relative positions, as the GPU gets them (renderer.core.scene.FrameMatrices).
    lights = Lights.from_scene(scene, dtype, origin=frame_matrices.origin)
    eye = frame_matrices.relative(scene.camera.eye).astype(dtype)
    reversed_z = scene.camera.reversed_z

    # What the camera pass draws (an analytic plane: its polygon in the view volume, the same
    # at every sample offset), and, as the GPU path, not the objects wholly outside the view.
    drawn = drawn_meshes(scene, frame_matrices)
    visible = visible_objects(scene, frame_matrices, drawn)
    shadows = shadow_maps(scene, frame_matrices, width, height, visible, lights, dtype, tile_pixels)
    prepared, first_orders, first_order = [], [], 0
    for index, (obj, item, shown) in enumerate(zip(scene.objects, drawn, visible)):
        prepared.append(prepare_object(obj, item, frame_matrices, lights, eye, width, height,
                                       subpixel_bits, reversed_z, dtype, displace_lookup,
                                       index=index, shadowed=shadows is not None)
                        if shown else None)
        first_orders.append(first_order)
        first_order += len(item.mesh.faces) if prepared[-1] is None else len(prepared[-1].varyings.faces)
    return PreparedFrame(lights, eye, prepared, first_orders, shadows)


def shadow_maps(scene, frame_matrices, width, height, visible, lights, dtype,
                tile_pixels=TILE_PIXELS) -> ShadowMaps | None:
    """The frame's shadow maps (layers drawn, uniforms in `dtype`), or None when the scene has
    none (then no program compiles shadow code)."""
    layout = shadow_layout(scene, width, height)
    if not layout.any:
        return None
    plan = plan_shadows(scene, frame_matrices, layout, visible)
    return ShadowMaps.from_plan(render_layers(scene, frame_matrices, plan, dtype, tile_pixels),
                                plan, lights, dtype)


def depth_test_tile(region, prepared: PreparedFrame, width, height, reversed_z, dtype) -> DepthBuffer:
    """Rasterisation and depth test of every object within `region`: the tile's depth buffer,
    whose payload names each pixel's surviving fragment."""
    x0, y0, x1, y1 = region
    depth_buffer = DepthBuffer(x1 - x0, y1 - y0, dtype, reversed_z)
    for index, item in enumerate(prepared.objects):
        if item is not None:
            draw_tile(index, item, depth_buffer, prepared.first_orders[index], width, height, region)
    return depth_buffer


def _render_tile(region, prepared: PreparedFrame, scene, width, height, linear, depth, dtype) -> Frame:
    """Rasterisation, depth test, fragment shading and output of one tile: a Frame of the
    tile's size."""
    x0, y0, x1, y1 = region
    depth_buffer = depth_test_tile(region, prepared, width, height, scene.camera.reversed_z, dtype)
    objects, lights, eye, shadows = prepared.varyings, prepared.lights, prepared.eye, prepared.shadows
    drawn = depth_buffer.drawn
    window = (region, width, height)
    color, view_depth, shadow_tied, shadow_other = shade_surviving(
        objects, depth_buffer.payload, drawn, lights, eye, dtype, shadows, window)
    frame = compose_frame(color, drawn, view_depth if depth else None, scene.background,
                          x1 - x0, y1 - y0, linear=linear)
    # Where two surfaces are closer in depth than GL can order, the other one may show: its
    # colour goes beside the winner's, for comparisons to accept either (renderer/checks/compare.py).
    # Where a shadow-map tap was tied, the other decision's colour likewise; at a pixel with
    # both, the depth tie's (one alternative per pixel: either is acceptable).
    ties = depth_buffer.depth_ties()
    if not (ties.any() or shadow_tied.any()):
        return frame
    alternative = np.where(shadow_tied[:, None], shadow_other, color)
    if ties.any():
        other = shade_surviving(objects, depth_buffer.payload_second, ties, lights, eye, dtype, shadows,
                                window)[0]
        alternative = np.where(ties[:, None], other, alternative)
    frame.rgba8_tie = compose_frame(alternative, drawn, None, scene.background, x1 - x0, y1 - y0,
                                    linear=False).rgba8
    rows = lambda mask: mask.reshape(y1 - y0, x1 - x0)[::-1]          # noqa: E731  image rows
    frame.shadow_ties = rows(shadow_tied & ~ties) & (frame.rgba8_tie != frame.rgba8).any(axis=-1)
    return frame


def _render_in_tiles(bands, prepared: PreparedFrame, scene, width, height, linear, depth, dtype) -> Frame:
    """Each band drawn as its own tile and pasted into the frame's arrays (image rows are top
    first: GL rows [y0, y1) are image rows [H - y1, H - y0))."""
    frame = Frame(np.empty((height, width, 4), np.uint8),
                  np.empty((height, width, 4), np.float32) if linear else None,
                  np.empty((height, width), np.float32) if depth else None)
    ties = []
    for region in bands:
        _, y0, _, y1 = region
        rows = slice(height - y1, height - y0)
        part = _render_tile(region, prepared, scene, width, height, linear, depth, dtype)
        frame.rgba8[rows] = part.rgba8
        if linear:
            frame.linear[rows] = part.linear
        if depth:
            frame.depth[rows] = part.depth
        if part.rgba8_tie is not None:
            ties.append((rows, part.rgba8_tie, part.shadow_ties))
    if ties:
        frame.rgba8_tie = frame.rgba8.copy()
        frame.shadow_ties = np.zeros((height, width), bool)
        for rows, tie, shadow_ties in ties:
            frame.rgba8_tie[rows] = tie
            frame.shadow_ties[rows] = shadow_ties
    return frame


def shade_surviving(objects: list[ObjectVaryings | None], payload: dict, pixels_mask: np.ndarray,
                    lights: Lights, eye, dtype, shadows: ShadowMaps | None = None, window=None):
    """Fragment stage for the fragments `payload` names at the pixels of `pixels_mask`:
    (colour (H*W, 4), view depth (H*W,), shadow-tied (H*W,) bool, the colour with the tied
    taps decided the other way (H*W, 4)), zero (False) elsewhere. `window` (region, width,
    height): where the tile's pixels are in the viewport (a textured material's lookup needs
    each fragment's gl_FragCoord)."""
    color = np.zeros((len(pixels_mask), 4), dtype=dtype)
    view_depth = np.full(len(pixels_mask), np.inf, dtype=dtype)
    shadow_tied = np.zeros(len(pixels_mask), bool)
    shadow_other = color.copy()
    for index, varyings in enumerate(objects):
        if varyings is None:                                   # culled: it has no fragments
            continue
        pixels = np.flatnonzero(pixels_mask & (payload.get("object", -1) == index))
        if len(pixels) == 0:
            continue
        color[pixels], view_depth[pixels], tie = shade_fragments(
            varyings, payload["triangle"][pixels], payload["weights"][pixels],
            payload["gl_FrontFacing"][pixels], lights, eye, shadows,
            **_fragment_window(varyings, pixels, window))
        if tie is not None:
            shadow_tied[pixels], shadow_other[pixels] = tie
    return color, view_depth, shadow_tied, shadow_other


def _fragment_window(varyings: ObjectVaryings, pixels: np.ndarray, window) -> dict:
    """shade_fragments' gl_FragCoord (pixel centres, window coordinates) and viewport for
    the tile's `pixels` of a textured object; nothing for another."""
    if varyings.material.texture is None:
        return {}
    (x0, y0, x1, _), width, height = window
    x, y = x0 + pixels % (x1 - x0), y0 + pixels // (x1 - x0)
    return {"gl_FragCoord": np.stack([x, y], axis=-1) + 0.5, "viewport": (width, height)}


@dataclass
class SurfacePixels:
    """The surface each drawn pixel shows (its surviving fragment), as the fragment stage sees
    it: for measuring what it computes there against another method
    (renderer/checks/shadow_truth.py). Per such pixel, in the pipeline's dtype:"""
    pixel: np.ndarray             # (K,) index into the image's H*W pixels, row 0 at the top
    object: np.ndarray            # (K,) the object's index in the scene
    P: np.ndarray                 # (K, 3) the interpolated point, camera-relative world
    N: np.ndarray                 # (K, 3) the lit unit normal (flipped on a two-sided back face)
    Ng: np.ndarray                # (K, 3) the unit normal of the triangle's plane, as wound
    position_scale: np.ndarray    # (K,) the largest |coordinate| of its triangle's vertices
    facet: np.ndarray             # (K, 3) the shadow lookup's facet normal (lit side; receivers)
    crease: np.ndarray            # (K,) its facet's crease on that side (renderer/core/facets.py)


def _surface(varyings: ObjectVaryings, triangle, weights, gl_FrontFacing):
    """(P, N, Ng, position_scale, facet) of one object's fragments: where the fragment stage
    looks its shadows up (reference/fragment.py, lit_point, facet_normal) and the lookup's tie
    scale (reference/shadow/lookup.py)."""
    P, N = lit_point(varyings, triangle, weights, gl_FrontFacing)
    corners = varyings.vertices.v_world_position[varyings.faces[triangle]]
    Ng = normalize_or_zero(np.cross(corners[:, 1] - corners[:, 0], corners[:, 2] - corners[:, 0]))
    facet, crease = facet_normal(varyings, triangle, N)
    return P, N, Ng, np.abs(corners).max(axis=(1, 2)), facet, crease


def surface_pixels(scene, width: int, height: int, *, dtype=np.float64,
                   subpixel_bits: int = SUBPIXEL_BITS,
                   tile_pixels: int = TILE_PIXELS) -> tuple[SurfacePixels, ShadowMaps | None]:
    """The surface at every drawn pixel (SurfacePixels) and the frame's
    shadow maps, from the same stages as `render` (band by band), without shading."""
    dtype = np.dtype(dtype)
    prepared = prepare_frame(scene, width, height, dtype, subpixel_bits, tile_pixels=tile_pixels)
    varyings = prepared.varyings
    parts = []
    for region in tiles(width, height, tile_pixels):
        x0, y0, x1, y1 = region
        buffer = depth_test_tile(region, prepared, width, height, scene.camera.reversed_z, dtype)
        payload, drawn = buffer.payload, buffer.drawn
        for index, item in enumerate(varyings):
            if item is None:
                continue
            at = np.flatnonzero(drawn & (payload.get("object", -1) == index))
            if len(at) == 0:
                continue
            gl_row, column = y0 + at // (x1 - x0), x0 + at % (x1 - x0)
            pixel = (height - 1 - gl_row) * width + column          # image rows: top first
            parts.append((pixel, np.full(len(at), index), *_surface(
                item, payload["triangle"][at], payload["weights"][at], payload["gl_FrontFacing"][at])))
    if not parts:
        empty = np.zeros((0, 3), dtype)
        return SurfacePixels(np.zeros(0, np.int64), np.zeros(0, np.int64), empty, empty, empty,
                             np.zeros(0, dtype), empty, np.zeros(0, dtype)), prepared.shadows
    columns = [np.concatenate(column) for column in zip(*parts)]
    return SurfacePixels(*columns), prepared.shadows
