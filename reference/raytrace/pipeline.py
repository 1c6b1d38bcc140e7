"""# Twin: renderer/gpu/raytracer.py

The reference ray tracer's frame (docs/conventions.md, "Rays"): per pixel and sample a camera
ray through the window point (i + 0.5) + dx, (j + 0.5) + dy (float32, as gl_FragCoord.xy +
offset), the offsets those of renderer/core/sampling.py's pattern; each traced by trace.py from
near to far; the samples' linear colours averaged; rgba8 = to_unorm8 of the clamped average
with alpha 255 where some sample's camera ray hit; depth = the nearest first hit's view depth
(camera rays have s = -z_eye), +inf where none hit. Row 0 at the top, as every Frame.
In float32 as the GPU, or in float64 (dtype=np.float64: the uniforms, offsets and lights in
float64 too), the ground truth; the frame's ray_tree holds each pixel's hash of its samples'
ray trees (trace.py), which tells where the two precisions disagree on a grazing ray.
"""

from __future__ import annotations

import time

import numpy as np

from reference.lighting import Lights
from reference.output import flip_rows
from reference.raytrace.camera import camera_ray
from reference.raytrace.trace import mix64, trace
from renderer.core.camera_rays import camera_ray_uniforms
from renderer.core.frame import Frame
from renderer.core.gl_rules import to_unorm8
from renderer.core.raytrace_scene import ray_scene
from renderer.core.sampling import DEFAULT_SEED, pattern as sample_pattern

F32 = np.float32
DEFAULT_MAX_DEPTH = 4
CHUNK_RAYS = 1 << 16         # camera rays traced at once (bounds the working memory)


def render(scene, width: int, height: int, *, samples: int = 1, pattern: str = "regular",
           max_depth: int = DEFAULT_MAX_DEPTH, seed: int = DEFAULT_SEED, shadows: bool = True,
           rs=None, dtype=F32) -> Frame:
    """The frame (module docstring); `rs` a ray_scene(scene) made before, `shadows`=False
    traces no shadow rays; `dtype` float32 (the GPU's twin) or float64."""
    start = time.perf_counter()
    t = np.dtype(dtype).type
    rs = rs if rs is not None else ray_scene(scene)
    offsets = np.asarray(sample_pattern(pattern, samples, seed), t)
    matrices = scene.matrices(width, height)
    uniforms = camera_ray_uniforms(matrices.view, matrices.projection, width, height)
    uniforms = {k: v.astype(t) for k, v in uniforms.items()}
    lights = Lights.from_scene(scene, t, origin=matrices.origin)
    i = np.arange(width, dtype=t) + t(0.5)
    j = np.arange(height, dtype=t) + t(0.5)
    x, y = np.meshgrid(i, j)                                 # (H, W), row 0 at the bottom
    windows = np.stack([np.stack([x + dx, y + dy], -1) for dx, dy in offsets])   # (S, H, W, 2)
    O, D = camera_ray(windows.reshape(-1, 2), uniforms)
    cam = scene.camera
    trees = np.zeros(len(O), np.uint64)
    parts = [trace(rs, lights, O[k:k + CHUNK_RAYS], D[k:k + CHUNK_RAYS], cam.near, cam.far,
                   scene.background, max_depth, shadows, trees[k:k + CHUNK_RAYS])
             for k in range(0, len(O), CHUNK_RAYS)]
    colour, hit, s = (np.concatenate(part) for part in zip(*parts))
    n = len(offsets)
    trees = mix64(trees.reshape(n, -1) + np.arange(n, dtype=np.uint64)[:, None]).sum(0, dtype=np.uint64)
    colour = colour.reshape(n, height * width, 3)
    total = colour[0].copy()
    for k in range(1, n):                                    # in sample order, as the GLSL
        total += colour[k]
    average = total / t(n)
    hit = hit.reshape(n, -1)
    covered = hit.any(0)
    depth = np.where(hit, s.reshape(n, -1), t(np.inf)).min(0)
    linear = np.concatenate([average, covered[:, None].astype(t)], -1).reshape(height, width, 4)
    rgba8 = to_unorm8(linear)
    rgba8[..., 3] = np.where(covered.reshape(height, width), 255, 0)
    return Frame(flip_rows(rgba8), flip_rows(linear.astype(F32)),
                 flip_rows(depth.reshape(height, width).astype(F32)),
                 (time.perf_counter() - start) * 1000.0,
                 ray_tree=flip_rows(trees.reshape(height, width)))
