"""The output stage on every built-in scene at 320 x 240 (the issue's bar): each scene's GPU
linear frame (the rasteriser's through GpuRenderer, the ray tracer's scenes through RayTracer)
goes through both twins of the stage (the GPU's on EGL and on OSMesa), and the codes are identical for the undithered baseline,
Bayer 2, 4 and 8 and blue noise at 1 and 8 bits, linear and sRGB; Floyd-Steinberg and
Jarvis-Judice-Ninke at 1 bit linear and 8 bits sRGB (the small frames of
tests/test_output_diffusion.py hold every other combination); half-tones with a screen on the
pixel grid and without. The default run holds the
same rules on small frames made to hold every case (tests/test_output_dither.py); this is
the full run's: about 100 s with the error diffusion and half-tone cases (load average 4.5,
2026-12-02).
"""

import functools

import numpy as np
import pytest

import reference.output
from conftest import RAYTRACE_SCENES
from renderer.core.builtin import builtin_scenes
from renderer.core.output_settings import ERROR_DIFFUSION, Halftone, OutputSettings, Transfer
from renderer.core.scene_file import load_scene
from renderer.gpu import GpuRenderer
from renderer.gpu.raytracer import RayTracer

SIZE = (320, 240)
METHODS = ("none", "bayer2", "bayer4", "bayer8", "blue-noise")


@functools.lru_cache(maxsize=None)          # each scene rendered once for the tests below
def linear_frame(name: str, ctx) -> np.ndarray:
    scene = load_scene(name)
    if name in RAYTRACE_SCENES:
        with RayTracer(scene, *SIZE, context=ctx) as tracer:
            return tracer.render().linear
    with GpuRenderer(scene, *SIZE, context=ctx) as gpu:
        return gpu.render(linear=True, depth=False).linear


@pytest.mark.slow
@pytest.mark.parametrize("name", sorted(builtin_scenes()))
def test_every_scene_gives_the_same_codes_on_both_twins(gl_contexts, output_passes, name):
    linear = linear_frame(name, gl_contexts["egl"])
    for transfer in (Transfer("linear"), Transfer("srgb")):
        for bits in (1, 8):
            for dither in METHODS:
                settings = OutputSettings(transfer=transfer, bits=bits, dither=dither)
                twin = reference.output.apply(linear, settings)
                for kind, stage in output_passes.items():
                    np.testing.assert_array_equal(stage.apply(linear, settings), twin,
                                                  err_msg=f"{kind}: {dither}, {bits} bits, {transfer}")


@pytest.mark.slow
@pytest.mark.parametrize("name", sorted(builtin_scenes()))
def test_every_scene_diffuses_and_screens_alike_on_both_twins(gl_contexts, output_passes, name):
    linear = linear_frame(name, gl_contexts["egl"])
    diffused = [OutputSettings(transfer=transfer, bits=bits, dither=kernel)
                for kernel in ERROR_DIFFUSION
                for transfer, bits in ((Transfer("linear"), 1), (Transfer("srgb"), 8))]
    screened = [OutputSettings(halftone=halftone) for halftone in (Halftone(6, 0), Halftone(7.5, 22.5))]
    for settings in diffused + screened:
        twin = reference.output.apply(linear, settings)
        for kind, stage in output_passes.items():
            np.testing.assert_array_equal(stage.apply(linear, settings), twin,
                                          err_msg=f"{kind}: {settings}")
