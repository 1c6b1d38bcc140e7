"""# Twin: renderer/gpu/pipeline.py (the draw as a whole; each stage's twin is named in its module)

The reference draw, stage by stage as dEQP's drawBasicPrimitives reads: for each object in
scene order, vertex processing -> primitive assembly -> (flat: geometry stage) -> clipping
-> viewport transform and snapping -> facing and culling -> rasterisation -> depth test;
then fragment shading for the one surviving fragment per pixel, and output conversion.
Objects wholly outside the view volume are skipped (renderer/core/visibility.py, as the GPU path).
Where a pixel's runner-up is within depth precision of its winner (a depth tie, see
docs/conventions.md) the runner-up is shaded too, into Frame.rgba8_tie.

Input:  a `renderer.core.scene.Scene` and the image size. Output: a `renderer.core.frame.Frame`
(rgba8 (H, W, 4) uint8 row 0 at the top, optional linear (H, W, 4) float32, depth (H, W)
float32 -z_eye with +inf background). Conventions: docs/conventions.md.
"""

from __future__ import annotations

import time

import numpy as np

from reference.clipping import clip_triangles
from reference.depth_buffer import DepthBuffer
from reference.fragment import ObjectVaryings, shade_fragments
from reference.geometry import shade_triangles
from reference.lighting import Lights
from reference.output import compose_frame
from reference.rasterizer import is_drawn, rasterize, setup_triangles
from reference.vertex import shade_vertices
from renderer.core.frame import Frame
from renderer.core.gl_rules import SUBPIXEL_BITS, check_light_count
from renderer.core.visibility import visible_objects


def draw_object(index: int, obj, matrices, frame_matrices, lights: Lights, eye, depth: DepthBuffer,
                first_order: int, width: int, height: int, subpixel_bits: int, dtype) -> ObjectVaryings:
    """Vertex processing to depth test for one object; returns what the fragment stage needs.

    Draw order is first_order + the triangle's index in the mesh, so it is global across
    objects; the triangles a clipped triangle turns into share its order.
    """
    mesh, material = obj.mesh, obj.material
    vertices = shade_vertices(mesh.positions, mesh.normals, u_model=matrices.model,
                              u_normal_matrix=matrices.normal, u_view=frame_matrices.view,
                              u_projection=frame_matrices.projection, u_eye=eye,
                              material=material, lights=lights, dtype=dtype)
    faces = np.asarray(mesh.faces, dtype=np.int64)                         # primitive assembly
    triangles = (shade_triangles(vertices.v_world_position[faces], material, lights, eye)
                 if material.shading == "flat" else None)
    reversed_z = depth.reversed_z
    clipped = clip_triangles(vertices.gl_Position[faces], reversed_z)
    window = setup_triangles(clipped.gl_Position, width, height, subpixel_bits, reversed_z)
    keep = is_drawn(window.area2, obj.cull)
    window, source, clip_weights = window.select(keep), clipped.source[keep], clipped.weights[keep]

    for fragments in rasterize(window, width, height):
        t = fragments.triangle
        # weights w.r.t. the source triangle's vertices: sum_k b_k * clip_weights[k, :]
        b, cw = fragments.barycentric, clip_weights[t]
        weights = b[:, 0:1] * cw[:, 0] + b[:, 1:2] * cw[:, 1] + b[:, 2:3] * cw[:, 2]
        depth.test_and_write(fragments.y * width + fragments.x, fragments.z_w,
                             first_order + source[t],
                             object=np.full(len(t), index, dtype=np.int32), triangle=source[t],
                             weights=weights, gl_FrontFacing=fragments.gl_FrontFacing)
    return ObjectVaryings(material, faces, vertices, triangles)


def render(scene, width: int, height: int, *, dtype=np.float64, subpixel_bits: int = SUBPIXEL_BITS,
           linear: bool = False, depth: bool = True, sample_offset=(0.0, 0.0)) -> Frame:
    """Render `scene` at width x height with the NumPy reference pipeline, each pixel sampled
    at `sample_offset` (dx, dy) pixels from its centre (Scene.matrices)."""
    start = time.perf_counter()
    check_light_count(scene)             # the GPU's limit, held alike (renderer/core/gl_rules.py)
    dtype = np.dtype(dtype)
    frame_matrices = scene.matrices(width, height, sample_offset)
    # Camera-relative positions, as the GPU gets them (renderer.core.scene.FrameMatrices).
    lights = Lights.from_scene(scene, dtype, origin=frame_matrices.origin)
    eye = frame_matrices.relative(scene.camera.eye).astype(dtype)
    depth_buffer = DepthBuffer(width, height, dtype, scene.camera.reversed_z)

    # Objects wholly outside the view volume are skipped, as the GPU path skips them.
    visible = visible_objects(scene, frame_matrices)
    objects, first_order = [], 0
    for index, (obj, matrices) in enumerate(zip(scene.objects, frame_matrices.objects)):
        objects.append(draw_object(index, obj, matrices, frame_matrices, lights, eye, depth_buffer,
                                   first_order, width, height, subpixel_bits, dtype)
                       if visible[index] else None)
        first_order += len(obj.mesh.faces)

    drawn = depth_buffer.drawn
    color, view_depth = shade_surviving(objects, depth_buffer.payload, drawn, lights, eye, dtype)
    frame = compose_frame(color, drawn, view_depth if depth else None, scene.background,
                          width, height, linear=linear)
    # Where two surfaces are closer in depth than GL can order, the other one may show: its
    # colour goes beside the winner's, for comparisons to accept either (renderer/checks/compare.py).
    ties = depth_buffer.depth_ties()
    if ties.any():
        other, _ = shade_surviving(objects, depth_buffer.payload_second, ties, lights, eye, dtype)
        frame.rgba8_tie = compose_frame(np.where(ties[:, None], other, color), drawn, None,
                                        scene.background, width, height, linear=False).rgba8
    frame.milliseconds = (time.perf_counter() - start) * 1000.0
    return frame


def shade_surviving(objects: list[ObjectVaryings | None], payload: dict, pixels_mask: np.ndarray,
                    lights: Lights, eye, dtype) -> tuple[np.ndarray, np.ndarray]:
    """Fragment stage for the fragments `payload` names at the pixels of `pixels_mask`:
    (colour (H*W, 4), view depth (H*W,)), zero elsewhere."""
    color = np.zeros((len(pixels_mask), 4), dtype=dtype)
    view_depth = np.full(len(pixels_mask), np.inf, dtype=dtype)
    for index, varyings in enumerate(objects):
        if varyings is None:                                   # culled: it has no fragments
            continue
        pixels = np.flatnonzero(pixels_mask & (payload.get("object", -1) == index))
        if len(pixels) == 0:
            continue
        color[pixels], view_depth[pixels] = shade_fragments(
            varyings, payload["triangle"][pixels], payload["weights"][pixels],
            payload["gl_FrontFacing"][pixels], lights, eye)
    return color, view_depth
