"""The GPU path tracer (glsl/raytrace/pathtrace.glsl through raytrace.frag; twin: reference/
raytrace/pathtrace.py; docs/pathtrace.md): the ray tracer's pass (renderer/gpu/raytracer.py:
its samples, camera, BVH, materials, lights and targets, update, reseed and bands) compiled with
PATH_TRACE, which follows one path per camera sample instead of the Whitted tree, and
ROULETTE_DEPTH (renderer/core/path_options.py). Two more float textures: each object's emission
(u_emission) and, under EMITTERS, the emitting triangles next-event estimation samples
(u_emitters, renderer/core/path_emitters.py; u_emitter_count of them). SECONDARY (the Whitted
stack) is never compiled; GLOSSY where some material is glossy, as the ray tracer's.

One sample a pass (SAMPLE_PASSES, u_sample): llvmpipe ends every loop of a shader invocation once
they have run 65535 iterations together (gallivm's LP_MAX_TGSI_LOOP_ITERATIONS, shared by all
the loops of a shader), and a pixel's samples of long paths through a BVH reach that: its last
samples were cut short, silently (a white furnace of rho = 0.9 came out 1.2 % dark). Each pass's
colours are read back and summed here in sample order, as the twin sums them, then averaged;
coverage is any sample's hit and depth the nearest first hit."""

from __future__ import annotations

import time

import numpy as np

from renderer.core.frame import Frame
from renderer.core.gl_rules import to_unorm8
from renderer.core.path_emitters import path_emitters
from renderer.core.path_options import ROULETTE_DEPTH, PathOptions
from renderer.gpu.raytracer import BAND_SAMPLES, RayTracer, _flip_read


class PathTracer(RayTracer):
    """Path traces one scene at one size (module docstring); `options` a PathOptions."""

    def __init__(self, scene, width, height, options: PathOptions | None = None, **keywords):
        self.emitters = None                     # the scene's (_defines), kept in number by update()
        super().__init__(scene, width, height, PathOptions() if options is None else options, **keywords)

    def _defines(self, rs) -> dict:
        emitters = path_emitters(self.scene, rs)
        if self.emitters is not None and emitters.count != self.emitters.count:
            # before any texture is written again: the emitters' texture has another size
            raise ValueError("the scene's emitting triangles changed in number since this "
                             "PathTracer was made; make a new one")
        self.emitters = emitters
        defines = super()._defines(rs)
        defines.update({"PATH_TRACE": True, "SAMPLE_PASSES": True, "SECONDARY": False,
                        "ROULETTE_DEPTH": ROULETTE_DEPTH,
                        "GLOSSY": (rs.glossy or not self.specialise) and self.max_depth > 0,
                        "EMITTERS": self.emitters.count > 0})
        return defines

    def _texture_arrays(self, rs) -> dict:
        arrays = super()._texture_arrays(rs)
        arrays["u_emission"] = self.emitters.emission[:, None, :]
        if self.emitters.count:
            arrays["u_emitters"] = self.emitters.texels()
        return arrays

    def _more_uniforms(self, rs) -> dict:
        values = {"u_sample": np.int32(0).tobytes()}          # render() writes each pass's
        if self.emitters.count:
            values["u_emitter_count"] = np.int32(self.emitters.count).tobytes()
        return values

    def render(self, out: Frame | None = None, *, linear: bool = True, depth: bool = True,
               first_sample: int = 0, progress=None) -> Frame:
        """The frame of sample indices first_sample .. first_sample + N - 1, as RayTracer's
        render (the same Frame, row 0 at the top), one pass a sample (module docstring);
        `progress(rows done, rows)` after each band of each pass."""
        self._check_alive()
        start = time.perf_counter()
        images = self._begin_frame(first_sample)
        h, w, n = self.height, self.width, self.sampling.samples
        total = np.zeros((h, w, 3), np.float32)
        covered = np.zeros((h, w), bool)
        nearest = np.full((h, w), np.inf, np.float32)
        try:
            for k in range(n):
                self.program["u_sample"].value = k
                self._trace_bands(progress, (k / n, (k + 1) / n))
                colour = _flip_read(self._fbo, 0, (h, w, 4), None)
                total += colour[..., :3]                      # in sample order, as the twin
                covered |= colour[..., 3] > 0
                np.minimum(nearest, _flip_read(self._fbo, 1, (h, w), None), out=nearest)
        finally:
            self._end_frame(images)
        average = total / np.float32(n)
        colour = np.concatenate([average, covered[..., None].astype(np.float32)], -1)
        rgba8 = to_unorm8(colour)
        rgba8[..., 3] = np.where(covered, np.uint8(255), np.uint8(0))
        if out is not None:
            out.linear[...], out.depth[...] = colour, nearest
            colour, nearest = out.linear, out.depth
        return Frame(rgba8, colour, nearest, (time.perf_counter() - start) * 1000.0,
                     gl_info=self.gl_info, samples=np.full((h, w), n, np.int32))

    def bands(self) -> list[tuple[int, int]]:
        """A pass traces one sample: bands of about BAND_SAMPLES paths."""
        per_row = self.width * self.sampling.light_samples
        rows = max(1, BAND_SAMPLES // per_row)
        return [(y, min(rows, self.height - y)) for y in range(0, self.height, rows)]
