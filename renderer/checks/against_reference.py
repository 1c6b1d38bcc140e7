"""A GPU frame held against the NumPy reference, as `renderer compare` does it (and `renderer
batch --compare` per item): the reference's frame, what it accepts (texture envelopes,
depth and shadow ties, grazing rays between float32 and float64), the comparison under
the pipeline tolerance, the heat map and the figures.

    check = against_reference(scene, (w, h), gpu_frame, method="raster", subpixel_bits=8)
    check = against_reference(scene, (w, h), gpu_frame, method="raytrace", options=RayOptions(samples=4))
    check.figures          # the JSON object `renderer compare` prints, less GPU timing and GL
    check.failures         # what fails the tolerance (empty: it passes)
"""

from __future__ import annotations

import time
from dataclasses import dataclass, replace

import numpy as np

from renderer.checks.compare import (compare_frames, depth_tie_pixels, either_precision,
                                     heat_map, shadow_tie_pixels)
from renderer.checks.tolerance import PIPELINE_TOLERANCE
from renderer.core.frame import Frame
from renderer.core.jsonio import finite_or_none
from renderer.methods import open_renderer


@dataclass
class ReferenceCheck:
    reference: Frame            # the reference's own frame (float32)
    heat: np.ndarray            # diff.png: where and how far the GPU is off
    figures: dict
    failures: list[str]


def against_reference(scene, size, gpu_frame: Frame, *, method: str = "raster",
                      options=None, subpixel_bits: int | None = None,
                      threshold: int = PIPELINE_TOLERANCE.threshold) -> ReferenceCheck:
    """Render the reference for `scene` at `size` by `method` with its `options` (None: the
    method's defaults; the GPU's `subpixel_bits` for the rasteriser) and compare `gpu_frame`
    with it."""
    tie, tie_depth, grazing, envelope_renders = None, None, 0, 0
    start = time.perf_counter()
    twin = open_renderer(scene, size, method=method, backend="reference", options=options,
                         subpixel_bits=subpixel_bits)
    ref_frame = twin.render()
    reference_ms = (time.perf_counter() - start) * 1000.0
    # What the twin accepts besides its own colour differs by method (a real difference: the
    # ray and path tracers' float32 and float64 trees, the rasteriser's texture lookups' envelope).
    traced = method in ("raytrace", "pathtrace")
    if traced:
        # Where float32 and float64 disagree on a grazing ray, either colour is accepted (and
        # elsewhere the adaptive pattern's other decision, rgba8_tie). Same BVH, other precision.
        twin.precision = "float64"
        tie, tie_depth, grazing = either_precision(ref_frame, twin.render())
        expected = ref_frame.rgba8
    else:
        from renderer.checks.texture_bounds import accepted_colours
        # Anisotropic lookups: the twin's range over the texture verifier's coordinate bound.
        # (the scene as the options draw it: a setting's shading)
        accepted = accepted_colours(twin.scene, ref_frame, *size, subpixel_bits=subpixel_bits)
        expected, tie, envelope_renders = accepted.rgba8, accepted.tie, accepted.displaced_renders
    tolerance = replace(PIPELINE_TOLERANCE, threshold=threshold)
    result = compare_frames(gpu_frame.rgba8, expected, gpu_frame.depth, ref_frame.depth,
                            threshold=tolerance.threshold, deviation=tolerance.deviation,
                            reference_tie=tie, reference_tie_depth=tie_depth)
    heat = heat_map(gpu_frame.rgba8, expected, tolerance.threshold, tolerance.deviation,
                    reference_tie=tie)
    figures = {"scene": scene.name, "size": list(size), "method": method, **result.as_dict(),
               "psnr": finite_or_none(result.psnr),       # null for identical images (inf dB)
               "depth_tie_pixels": 0 if traced else depth_tie_pixels(ref_frame),
               "shadow_tie_pixels": 0 if traced else shadow_tie_pixels(ref_frame),
               "grazing_ray_pixels": grazing, "anisotropic_envelope_renders": envelope_renders,
               "reference_ms": reference_ms}
    if traced:         # adaptive: the samples traced, and where the twins chose differently
        figures |= {"gpu_samples_per_pixel": float(gpu_frame.samples.mean()),
                    "reference_samples_per_pixel": float(ref_frame.samples.mean()),
                    "refined_differently_pixels": int((gpu_frame.samples != ref_frame.samples).sum()),
                    "adaptive_tie_pixels": depth_tie_pixels(ref_frame)}
    failures = tolerance.failures(result)
    figures["passes"] = not failures
    return ReferenceCheck(ref_frame, heat, figures, failures)
