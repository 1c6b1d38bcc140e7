"""# Twin: renderer/gpu/raytracer.py

The reference ray tracer's frame (docs/conventions.md, "Rays", "Sample positions"): per pixel
(i, j) and sample k a camera ray through the window point (i + 0.5) + dx, (j + 0.5) + dy
(float32, as gl_FragCoord.xy + offset), the offset sampling.py's for sample index
first_sample + k, through its lens point where the camera has an aperture (camera.py's
thin_lens_ray; an aperture of 0 too, which must leave the ray as it is); each traced by trace.py from near to far; the samples' linear colours summed
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

Area lights (a point light with an area, of any size): `light_samples` M points on each per
hit (renderer/core/light_areas.py's uniform, area_lights.py's area_light_terms).

In float32 as the GPU, or in float64 (dtype=np.float64: the uniforms, offsets and lights in
float64 too), the ground truth; the frame's ray_tree holds each pixel's hash of its samples'
ray trees (trace.py), which tells where the two precisions disagree on a grazing ray.
"""

from __future__ import annotations

import time

import numpy as np

from reference.lighting import Lights
from reference.framebuffer import flip_rows
from reference.raytrace.camera import camera_ray, lens_point, thin_lens_ray
from reference.raytrace.sampling import RaySamples, sample_offset
from reference.raytrace.trace import mix64, trace
from renderer.core.camera_rays import camera_ray_uniforms, lens_uniforms
from renderer.core.frame import Frame
from renderer.core.gl_rules import to_unorm8
from renderer.core.light_areas import AREA_UNIFORM, area_light_uniforms, declares_area_lights
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
           rs=None, first_sample: int = 0, adaptive_threshold: float | None = None,
           dtype=F32, light_samples: int = 1, progress=None, tracer=trace) -> Frame:
    """The frame (module docstring) of sample indices first_sample .. first_sample + N - 1;
    `rs` a ray_scene(scene) made before, `shadows`=False traces no shadow rays; `dtype`
    float32 (the GPU's twin) or float64; `progress(share done)`, if given, after each chunk of
    rays (an adaptive frame's first set fills half, its refinement the rest); `tracer`: what
    traces the camera rays, trace.py's trace (Whitted) or, its emitters bound, pathtrace.py's
    path_trace (the GLSL's PATH_TRACE)."""
    start = time.perf_counter()
    t = np.dtype(dtype).type
    rs = rs if rs is not None else ray_scene(scene)
    sampling = ray_sampling(pattern, samples, seed, adaptive_threshold, light_samples)
    first_sample = check_first_sample(first_sample, sampling.samples)
    matrices = scene.matrices(width, height)
    uniforms = camera_ray_uniforms(matrices.view, matrices.projection, width, height)
    uniforms = {k: v.astype(t) for k, v in uniforms.items()}
    lights = Lights.from_scene(scene, t, origin=matrices.origin)
    areas = area_light_uniforms(scene)[AREA_UNIFORM] if declares_area_lights(scene) else None
    cam = scene.camera
    lens = _lens(cam, matrices.view, t)
    y, x = np.divmod(np.arange(width * height, dtype=np.uint32), np.uint32(width))  # row 0 at the bottom

    refining = sampling.adaptive and sampling.samples > sampling.first_set

    def told(share: float) -> None:
        if progress is not None:
            progress(share)

    def traced(pixels, ks, shares=(0.0, 1.0)):
        """Each sample k of `ks` at each pixel of `pixels` (flat indices): colour (S, P, 3),
        hit (S, P), s (S, P), and the hash of each ray tree mixed with its k (S, P).
        `shares`: the part of the frame's progress its chunks go from and to."""
        if len(pixels) == 0:
            return (np.zeros((len(ks), 0, 3), t), np.zeros((len(ks), 0), bool),
                    np.zeros((len(ks), 0), t), np.zeros((len(ks), 0), np.uint64))
        px, py = x[pixels], y[pixels]
        centres = np.stack([px, py], -1).astype(t) + t(0.5)
        windows = np.stack([centres + sample_offset(px, py, k, first_sample, sampling).astype(t) for k in ks])
        O, D = camera_ray(windows.reshape(-1, 2), uniforms)
        owners = RaySamples(np.tile(px, len(ks)), np.tile(py, len(ks)),
                            np.repeat(np.asarray(ks, np.int64), len(pixels)), first_sample, sampling)
        if lens is not None:
            O, D = thin_lens_ray(lens_point(owners.x, owners.y, owners.k, first_sample, sampling, t),
                                 O, D, lens)
        trees = np.zeros(len(O), np.uint64)
        parts = []
        for i in range(0, len(O), CHUNK_RAYS):
            parts.append(tracer(rs, lights, O[i:i + CHUNK_RAYS], D[i:i + CHUNK_RAYS], cam.near,
                               cam.far, scene.background, max_depth, shadows,
                               trees[i:i + CHUNK_RAYS],
                               RaySamples(*(a[i:i + CHUNK_RAYS] for a in (owners.x, owners.y, owners.k)),
                                          first_sample, sampling), areas))
            told(shares[0] + (shares[1] - shares[0]) * min(i + CHUNK_RAYS, len(O)) / len(O))
        colour, hit, s = (np.concatenate(part) for part in zip(*parts))
        trees = mix64(trees.reshape(len(ks), -1) + np.asarray(ks, np.uint64)[:, None])
        return (colour.reshape(len(ks), len(pixels), 3), hit.reshape(len(ks), -1),
                s.reshape(len(ks), -1), trees)

    def accumulate(state, colour, hit, s, trees):
        """(total, covered, depth, trees) with the samples added, in sample order as the GLSL."""
        total, covered, depth, tree = (a.copy() for a in state)
        for k in range(len(colour)):
            total += colour[k]
        return (total, covered | hit.any(0), np.minimum(depth, np.where(hit, s, t(np.inf)).min(0)),
                tree + trees.sum(0, dtype=np.uint64))

    everywhere = np.arange(width * height)
    colour, hit, s, trees = traced(everywhere, range(sampling.first_set), (0.0, 0.5 if refining else 1.0))
    empty = (np.zeros((width * height, 3), t), np.zeros(width * height, bool),
             np.full(width * height, t(np.inf)), np.zeros(width * height, np.uint64))
    first = accumulate(empty, colour, hit, s, trees)
    count = np.full(width * height, sampling.first_set, np.int32)
    decided, other = (first, count), None
    if refining:
        clamped = np.clip(colour, t(0), t(1))
        spread = (clamped.max(0) - clamped.min(0)).max(-1)
        threshold = t(F32(sampling.threshold))
        refine = spread > threshold
        near = np.abs(spread.astype(np.float64) - float(threshold)) <= DECISION_MARGIN
        more = np.flatnonzero(refine | near)
        rest = accumulate([a[more] for a in first], *traced(more, range(sampling.first_set, sampling.samples),
                                                            (0.5, 1.0)))

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
    frame = _frame(*decided, width, height, t)
    frame.rgba8_tie = None if other is None else _frame(*other, width, height, t).rgba8
    frame.milliseconds = (time.perf_counter() - start) * 1000.0
    return frame


def _lens(camera, view, t) -> dict | None:
    """The thin lens's uniforms in dtype `t` when the camera has an aperture at all (a radius
    of 0 too: its code then runs and must give the pinhole's rays exactly), else None."""
    if camera.aperture is None:
        return None
    return {k: np.asarray(v).astype(t) for k, v in lens_uniforms(view, camera.aperture, camera.focus).items()}


def _frame(state, count, width: int, height: int, t=F32) -> Frame:
    """The Frame of per-pixel (total, covered, depth, trees) and samples traced (flat, row 0
    at the bottom): the average colour total / count in float32 as the GLSL (or float64)."""
    total, covered, depth, trees = state
    average = total / count[:, None].astype(t)
    linear = np.concatenate([average, covered[:, None].astype(t)], -1).reshape(height, width, 4)
    rgba8 = to_unorm8(linear)
    rgba8[..., 3] = np.where(covered.reshape(height, width), 255, 0)
    return Frame(flip_rows(rgba8), flip_rows(linear.astype(F32)),
                 flip_rows(depth.reshape(height, width).astype(F32)),
                 samples=flip_rows(count.reshape(height, width)),
                 ray_tree=flip_rows(trees.reshape(height, width)))
