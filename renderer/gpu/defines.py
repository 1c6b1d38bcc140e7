"""The GLSL #defines that the GPU path builds from shared data. Only the GPU needs them, so they
live here and not in renderer/core, which the reference imports. The twin shares the data and
the rules but none of the shaders' compile switches (tests/test_architecture.py,
REFERENCE_SHARES).

    sampling_defines(sampling)          glsl/raytrace/sampling.glsl's and raytrace.frag's constants
    area_light_defines(scene, every)    trace.glsl's and lighting.glsl's AREA_LIGHTS
    output_defines(settings)            the output pass's (glsl/output/)

The rasteriser's come from ShaderVariant.defines (renderer/gpu/shaders.py).
"""

from __future__ import annotations

from renderer.core.light_areas import uses_area_lights
from renderer.core.output_settings import ERROR_DIFFUSION, ORDERED, OutputSettings
from renderer.core.ray_sampling import RaySampling
from renderer.core.scene import Scene


def sampling_defines(sampling: RaySampling) -> dict[str, object]:
    """sampling.glsl's and raytrace.frag's compile-time constants for the rule `sampling`."""
    return {"NUM_SAMPLES": sampling.samples, "FIRST_SAMPLES": sampling.first_set,
            "SAMPLE_TABLE": sampling.table is not None, "ADAPTIVE": sampling.adaptive,
            "FIRST_COLUMNS": sampling.first_strata[0], "FIRST_ROWS": sampling.first_strata[1],
            "REST_COLUMNS": sampling.rest_strata[0], "REST_ROWS": sampling.rest_strata[1],
            **dimension_defines(sampling)}


def dimension_defines(sampling: RaySampling) -> dict[str, object]:
    """distributed_2d's and distributed_1d's constants: the mode and the strata grids of one
    point per sample (DIMENSION_*) and, with light_samples M > 1, of M points (LIGHT_*)."""
    mode = sampling.dimension_mode
    defines = {"DIMENSION_RANDOM": mode == "random", "DIMENSION_CENTRES": mode == "centres",
               "DIMENSION_TABLE": mode == "table", "LIGHT_SAMPLES": sampling.light_samples}
    for prefix, per_sample in (("DIMENSION", 1), ("LIGHT", sampling.light_samples)):
        for name, which in (("FIRST", 0), ("REST", 1)):
            columns, rows = sampling.dimension_grid(which, per_sample)
            defines[f"{prefix}_{name}_COLUMNS"], defines[f"{prefix}_{name}_ROWS"] = columns, rows
    return defines


def area_light_defines(scene: Scene, every: bool = False) -> dict[str, object]:
    """trace.glsl's and lighting.glsl's AREA_LIGHTS: set where the scene uses area lights, or,
    with `every` (the build that compiles every feature in), where it has point lights.
    (LIGHT_SAMPLES, M, comes from the sampling rule's defines.)"""
    return {"AREA_LIGHTS": bool(scene.point_lights) and (every or uses_area_lights(scene))}


def output_defines(settings: OutputSettings) -> dict[str, str]:
    """The output pass's GLSL defines for `settings` (glsl/output/): a pass compiles only the
    method that its settings use."""
    defines = {"TRANSFER_" + settings.transfer.kind.upper(): "1"}
    if settings.halftone is not None:
        defines["HALFTONE"] = "1"
    elif settings.dither in ORDERED:
        defines["DITHER_ORDERED"] = str(ORDERED[settings.dither])
    elif settings.dither == "blue-noise":
        defines["DITHER_BLUE_NOISE"] = "1"
    elif settings.dither in ERROR_DIFFUSION:
        defines["DITHER_ERROR_DIFFUSION"] = str(ERROR_DIFFUSION.index(settings.dither))
    if not settings.quantised:
        defines["FLOAT_OUTPUT"] = "1"
    return defines
