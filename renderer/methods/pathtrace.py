"""The path tracer (issue 33; docs/pathtrace.md; glsl/raytrace/pathtrace.glsl, twin
reference/raytrace/pathtrace.py), registered as method "pathtrace": PathTracer on the GPU, the
reference path tracer behind the same protocol. Its options are PathOptions (the ray tracer's,
with a Monte Carlo estimate's defaults); successive frames bring new samples, as the ray
tracer's."""

from __future__ import annotations

import functools

from renderer.core.frame import Frame
from renderer.core.path_options import PathOptions
from renderer.methods.raytrace import ReferenceRayTracer, _need, _samples
from renderer.methods.registry import Method


class ReferencePathTracer(ReferenceRayTracer):
    """reference/raytrace/pathtrace.py's paths through the ray tracer's frame
    (reference/raytrace/pipeline.py), the scene's emitters made with its ray scene."""

    def _render_keywords(self) -> dict:
        from reference.raytrace.pathtrace import path_trace
        from renderer.core.path_emitters import path_emitters
        return {"tracer": functools.partial(path_trace, emitters=path_emitters(self.scene, self.ray_scene))}


def _open_gpu(scene, width, height, options: PathOptions, context, context_kind):
    from renderer.gpu.pathtracer import PathTracer
    return PathTracer(scene, width, height, options, context=context, context_kind=context_kind)


def _open_reference(scene, width, height, options, precision, subpixel_bits):
    return ReferencePathTracer(scene, width, height, options, precision)


def _words(options: PathOptions, frame: Frame) -> str:
    return f"pathtrace {options.samples} spp, up to {options.max_depth} bounces"


# The viewer's M key steps to it after the ray tracer: one path a pixel a frame, the mean refining
# while the view is still (renderer/viewer/progressive.py).
METHOD = Method("pathtrace", "path tracer", PathOptions, _open_gpu, _open_reference, _need,
                _words, _samples, progressive=True, seeded=True, shutter=True)
