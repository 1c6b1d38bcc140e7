"""The NumPy reference pipeline: the same stages as the GLSL in glsl/, written apart from them.

Written apart, but not independent of everything. It takes the scene model (and its matrices)
as its input, and it imports these modules of renderer/core, which the GPU path reads too. A
mistake in one of them is the same on both sides, and no comparison of the GPU with the twin
can see it. tests/test_architecture.py (REFERENCE_SHARES) holds this list. For each module it
says why the module is shared, or which check that does not share it catches its mistakes:

- containers and settings, with no image rule of their own: `frame.py`, `output_settings.py`,
  and `memory.py` (the band size);
- data and rules the twin must reproduce bit for bit, each checked by hand or against another
  implementation: `gl_rules.py`, `uniforms.py`, `colour.py`, `quantise.py`, `blue_noise.py`,
  `error_kernels.py`, `halftone_screen.py`, `sampling.py`, `ray_sampling.py`, `ray_depth.py`,
  `light_areas.py`, `path_options.py`;
- computations held against a check that does not share them: `shadows.py`,
  `shadow_settings.py` and `facets.py` (ray-cast shadow truth), `visibility.py` (the frame
  without culling), `drawn.py` (depth against ray casts), `camera_rays.py` and
  `raytrace_scene.py` (the rasteriser against the ray tracer), `hemicube.py` (Howell's
  closed forms) and `tessellation.py` (the levels' rule by the sagitta it bounds, the sphere
  against the ray tracer's exact one).
"""

from reference.pipeline import render

__all__ = ["render"]
