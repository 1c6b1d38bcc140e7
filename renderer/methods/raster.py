"""The rasteriser (docs/conventions.md; glsl/vertex.glsl .. fragment.glsl, twin
reference/pipeline.py), registered as method "raster": GpuRenderer on the GPU, the reference
pipeline behind the same protocol."""

from __future__ import annotations

from renderer.core.frame import Frame
from renderer.core.memory import raster_need
from renderer.core.raster_options import RasterOptions
from renderer.methods.reference_backend import ReferenceRenderer
from renderer.methods.registry import Method


class ReferenceRaster(ReferenceRenderer):
    """reference.render for the Renderer protocol; `subpixel_bits` the GPU's (None: the
    reference's default, GL's minimum). render()'s extra keywords (sample_offset,
    displace_lookup) are the reference pipeline's own."""

    def __init__(self, scene, width, height, options: RasterOptions, precision=None,
                 subpixel_bits: int | None = None):
        super().__init__(scene, width, height, options, precision)
        self.subpixel_bits = subpixel_bits

    def _frame(self, *, linear: bool, depth: bool, progress=None, **extra) -> Frame:
        import reference
        if self.subpixel_bits is not None:
            extra["subpixel_bits"] = self.subpixel_bits
        return reference.render(self.scene, self.width, self.height, dtype=self.dtype,
                                linear=linear, depth=depth, **extra)


def _open_gpu(scene, width, height, options: RasterOptions, context, context_kind):
    from renderer.gpu.pipeline import GpuRenderer
    return GpuRenderer(scene, width, height, context=context, context_kind=context_kind,
                       specialise=options.specialise, prune_shadows=options.prune_shadows)


def _open_reference(scene, width, height, options, precision, subpixel_bits):
    return ReferenceRaster(scene, width, height, options, precision, subpixel_bits)


def _need(size, backends, options):
    return raster_need(size, backends)


METHOD = Method("raster", "rasteriser", RasterOptions, _open_gpu, _open_reference, _need)
