"""# Twin: renderer/gpu/raytracer.py

The reference ray tracer's frame (docs/conventions.md, "Rays", "Sample positions"): per pixel
(i, j) and sample k a camera ray through the window point (i + 0.5) + dx, (j + 0.5) + dy
(float32, as gl_FragCoord.xy + offset), the offset sampling.py's for sample index
first_sample + k; each traced by trace.py from near to far; the samples' linear colours summed
in sample order and averaged; rgba8 = to_unorm8 of the clamped average with alpha 255 where
some sample's camera ray hit; depth = the nearest first hit's view depth (camera rays have
s = -z_eye), +inf where none hit; samples = the samples traced per pixel. Row 0 at the top, as
every Frame.

Adaptive (renderer/core/ray_sampling.py): the first set for every pixel at once, then the rest
for the pixels whose first samples' clamped colours spread (max - min, the largest channel)
more than the threshold, masks rather than a loop. The GPU decides on its own float32 colours,
which may differ from these in the last bits: a pixel whose spread lies within DECISION_MARGIN
of the threshold is traced both ways, and the frame's rgba8_tie holds the other decision's
colour there (comparisons accept either, as at a depth tie).
"""

from __future__ import annotations

import time

import numpy as np

from reference.lighting import Lights
from reference.output import flip_rows
from reference.raytrace.camera import camera_ray
from reference.raytrace.sampling import sample_offset
from reference.raytrace.trace import trace
from renderer.core.camera_rays import camera_ray_uniforms
from renderer.core.frame import Frame
from renderer.core.gl_rules import to_unorm8
from renderer.core.ray_sampling import check_first_sample, ray_sampling
from renderer.core.raytrace_scene import ray_scene
from renderer.core.sampling import DEFAULT_SEED

F32 = np.float32
DEFAULT_MAX_DEPTH = 4
CHUNK_RAYS = 1 << 16         # camera rays traced at once (bounds the working memory)
# How far a spread may be from the threshold for the GPU's float32 colours to decide otherwise
# (docs/conventions.md, "Sample positions": the colours of one ray agree within ~1e-6).
DECISION_MARGIN = 2.0 ** -12


def render(scene, width: int, height: int, *, samples: int = 1, pattern: str = "regular",
           max_depth: int = DEFAULT_MAX_DEPTH, seed: int = DEFAULT_SEED, shadows: bool = True,
           rs=None, first_sample: int = 0, adaptive_threshold: float | None = None) -> Frame:
    """The frame (module docstring) of sample indices first_sample .. first_sample + N - 1;
    `rs` a ray_scene(scene) made before, `shadows`=False traces no shadow rays."""
    start = time.perf_counter()
    rs = rs if rs is not None else ray_scene(scene)
    sampling = ray_sampling(pattern, samples, seed, adaptive_threshold)
    first_sample = check_first_sample(first_sample, sampling.samples)
    matrices = scene.matrices(width, height)
    uniforms = camera_ray_uniforms(matrices.view, matrices.projection, width, height)
    uniforms = {k: v.astype(F32) for k, v in uniforms.items()}
    lights = Lights.from_scene(scene, F32, origin=matrices.origin)
    cam = scene.camera
    y, x = np.divmod(np.arange(width * height, dtype=np.uint32), np.uint32(width))  # row 0 at the bottom

    def traced(pixels, ks):
        """Each sample k of `ks` at each pixel of `pixels` (flat indices): colour (S, P, 3),
        hit (S, P), s (S, P)."""
        if len(pixels) == 0:
            return np.zeros((len(ks), 0, 3), F32), np.zeros((len(ks), 0), bool), np.zeros((len(ks), 0), F32)
        px, py = x[pixels], y[pixels]
        centres = np.stack([px, py], -1).astype(F32) + F32(0.5)
        windows = np.stack([centres + sample_offset(px, py, k, first_sample, sampling) for k in ks])
        O, D = camera_ray(windows.reshape(-1, 2), uniforms)
        parts = [trace(rs, lights, O[i:i + CHUNK_RAYS], D[i:i + CHUNK_RAYS], cam.near, cam.far,
                       scene.background, max_depth, shadows) for i in range(0, len(O), CHUNK_RAYS)]
        colour, hit, s = (np.concatenate(part) for part in zip(*parts))
        return colour.reshape(len(ks), len(pixels), 3), hit.reshape(len(ks), -1), s.reshape(len(ks), -1)

    def accumulate(state, colour, hit, s):
        """(total, covered, depth) with the samples added, in sample order as the GLSL."""
        total, covered, depth = (a.copy() for a in state)
        for k in range(len(colour)):
            total += colour[k]
        return total, covered | hit.any(0), np.minimum(depth, np.where(hit, s, F32(np.inf)).min(0))

    everywhere = np.arange(width * height)
    colour, hit, s = traced(everywhere, range(sampling.first_set))
    empty = (np.zeros((width * height, 3), F32), np.zeros(width * height, bool),
             np.full(width * height, F32(np.inf)))
    first = accumulate(empty, colour, hit, s)
    count = np.full(width * height, sampling.first_set, np.int32)
    decided, other = (first, count), None
    if sampling.adaptive and sampling.samples > sampling.first_set:
        clamped = np.clip(colour, F32(0), F32(1))
        spread = (clamped.max(0) - clamped.min(0)).max(-1)
        threshold = F32(sampling.threshold)
        refine = spread > threshold
        near = np.abs(spread.astype(np.float64) - float(threshold)) <= DECISION_MARGIN
        more = np.flatnonzero(refine | near)
        rest = accumulate([a[more] for a in first], *traced(more, range(sampling.first_set, sampling.samples)))

        def taking(which):                   # the first set everywhere, refined at `which`
            state = [a.copy() for a in first]
            for whole, part in zip(state, rest):
                whole[which] = part[np.isin(more, which)]
            n = count.copy()
            n[which] = sampling.samples
            return state, n
        decided = taking(np.flatnonzero(refine))
        if near.any():
            other = taking(np.flatnonzero(refine ^ near))
    frame = _frame(*decided, width, height)
    frame.rgba8_tie = None if other is None else _frame(*other, width, height).rgba8
    frame.milliseconds = (time.perf_counter() - start) * 1000.0
    return frame


def _frame(state, count, width: int, height: int) -> Frame:
    """The Frame of per-pixel (total, covered, depth) and samples traced (flat, row 0 at the
    bottom): the average colour total / count in float32, as the GLSL."""
    total, covered, depth = state
    average = total / count[:, None].astype(F32)
    linear = np.concatenate([average, covered[:, None].astype(F32)], -1).reshape(height, width, 4)
    rgba8 = to_unorm8(linear)
    rgba8[..., 3] = np.where(covered.reshape(height, width), 255, 0)
    return Frame(flip_rows(rgba8), flip_rows(linear.astype(F32)), flip_rows(depth.reshape(height, width)),
                 samples=flip_rows(count.reshape(height, width)))
