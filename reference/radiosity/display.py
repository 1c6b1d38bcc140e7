"""# Twin: glsl/radiosity/display.vert, display.frag

Radiosity's display (notes 3.2.1, Gouraud shading), as renderer/gpu/radiosity.py has GL draw
it: each element's corners camera-relative through V then P (the frame's matrices), clipped
(reference/clipping.py), rasterised with the reference's snapping and fill rule
(reference/rasterizer.py), depth-tested with the camera's depth mapping, no culling, in element
order (reference/depth_buffer.py); the winner's colour is its corners' radiosity interpolated
perspective-correct where its front is seen (counter-clockwise in the window), black where its
back is, alpha 1, and its view depth -z_eye likewise; the background elsewhere
(reference/framebuffer.py). Where two elements are closer in depth than GL can order, the
runner-up's colour goes beside the winner's (Frame.rgba8_tie), as the rasteriser's twin does.
With a SpecularDisplay (a scene with a specular term, renderer/core/radiosity.py), a front seen
adds the direct specular term at the fragment's interpolated position and renormalised
interpolated normal (reference/radiosity/specular.py).

Inputs: the element corners (E, 3, 3) world, their displayed radiosity (E, 3, C)
(renderer/core/radiosity.py), the scene (its camera and background), the image size, and the
specular term's SpecularDisplay or None.
"""

from __future__ import annotations

import time

import numpy as np

from reference.clipping import clip_triangles
from reference.depth_buffer import DepthBuffer
from reference.framebuffer import compose_frame
from reference.radiosity.specular import normalize_or_zero, radiosity_specular
from reference.rasterizer import rasterize, setup_triangles
from renderer.core.frame import Frame
from renderer.core.gl_rules import SUBPIXEL_BITS


def _colour(values, view_depth, payload, which, dtype, points=None, specular=None):
    """(colour (P, 4), view depth (P,)) of the fragments recorded in `payload` at pixels `which`
    (`points` (E, 3, 3) the corners camera-relative, for the specular term's positions)."""
    source, weights = payload["triangle"][which], payload["weights"][which].astype(dtype)
    rgb = np.einsum("pk,pkc->pc", weights, values[source].astype(dtype))
    front = payload["front"][which]
    if specular is not None and front.any():
        f = np.flatnonzero(front)
        s, w = source[f], weights[f]
        P = np.einsum("pk,pkc->pc", w, points[s])
        N = normalize_or_zero(np.einsum("pk,pkc->pc", w, specular.normals[s].astype(dtype)))
        rgb[f] += radiosity_specular(P, N, specular.ks[s], specular.shininess[s], specular.obj[s], specular)
    rgb = np.where(front[:, None], rgb, 0)                         # a back seen is black
    colour = np.concatenate([rgb, np.ones((len(which), 1), dtype)], axis=1)
    return colour, np.einsum("pk,pk->p", weights, view_depth[source].astype(dtype))


def render(corners, values, scene, width: int, height: int, *, dtype=np.float64,
           subpixel_bits: int = SUBPIXEL_BITS, linear: bool = False, depth: bool = True,
           specular=None) -> Frame:
    """The elements drawn as renderer/gpu/radiosity.py RadiosityRenderer draws them (`specular`:
    the SpecularDisplay relative to the frame's origin, or None)."""
    start = time.perf_counter()
    dtype = np.dtype(dtype)
    reversed_z = scene.camera.reversed_z
    matrices = scene.matrices(width, height)
    count = len(corners)
    points = matrices.relative(np.asarray(corners, np.float64).reshape(-1, 3)).astype(dtype)
    homogeneous = np.concatenate([points, np.ones((len(points), 1), dtype)], axis=1)
    eye = homogeneous @ matrices.view.astype(dtype).T
    clip = (eye @ matrices.projection.astype(dtype).T).reshape(count, 3, 4)
    view_depth = -eye[:, 2].reshape(count, 3)
    values = np.asarray(values, np.float64)
    buffer = DepthBuffer(width, height, dtype, reversed_z)
    if count:
        clipped = clip_triangles(clip, reversed_z=reversed_z)
        window = setup_triangles(clipped.gl_Position, width, height, subpixel_bits, reversed_z)
        keep = np.flatnonzero(window.area2 != 0)                 # no culling; zero area draws nothing
        window = window.select(keep)
        source, clip_weights = clipped.source[keep], clipped.weights[keep]
        for fragments in rasterize(window, width, height):
            t = fragments.triangle
            b, cw = fragments.barycentric, clip_weights[t]
            weights = b[:, 0:1] * cw[:, 0] + b[:, 1:2] * cw[:, 1] + b[:, 2:3] * cw[:, 2]
            buffer.test_and_write(fragments.y * width + fragments.x, fragments.z_w, source[t],
                                  triangle=source[t], weights=weights, front=fragments.gl_FrontFacing)
    drawn = buffer.drawn
    colour = np.zeros((width * height, 4), dtype)
    shown_depth = np.full(width * height, np.inf, dtype)
    which = np.flatnonzero(drawn)
    if len(which):
        colour[which], shown_depth[which] = _colour(values, view_depth, buffer.payload, which, dtype,
                                                    points.reshape(count, 3, 3), specular)
    frame = compose_frame(colour, drawn, shown_depth if depth else None, scene.background, width, height,
                          linear=linear, milliseconds=(time.perf_counter() - start) * 1000.0)
    ties = np.flatnonzero(buffer.depth_ties())
    if len(ties):
        alternative = colour.copy()
        alternative[ties] = _colour(values, view_depth, buffer.payload_second, ties, dtype,
                                    points.reshape(count, 3, 3), specular)[0]
        frame.rgba8_tie = compose_frame(alternative, drawn, None, scene.background, width, height,
                                        linear=False).rgba8
    return frame
