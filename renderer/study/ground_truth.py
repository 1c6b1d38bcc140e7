"""The ground truths the report measures every setting against, cached on disk by content.

The rasteriser's truth is the NumPy reference in float64, Phong shading on every object, every
curved primitive at the finest tessellation (renderer/study/tessellation.py FINEST), every
texture as renderer/study/texture_report.py's truth_textures samples it (its texels, trilinear
at each sub-sample), and 16 x 16 supersampling per pixel. Rendering the reference once at 16W x 16H and averaging each
16 x 16 block of clamped linear colour is exactly the 16 x 16 regular grid of sample offsets
((a + 0.5) / 16 - 0.5, (b + 0.5) / 16 - 0.5) (renderer/core/sampling.py regular_grid(256)) at a
256th of the passes' cost.

Radiosity's truth is the path tracer (docs/pathtrace.md), which shares nothing with radiosity
but the scene: PATH_TRUTH_PASSES frames of PATH_TRUTH_SAMPLES jittered paths per pixel (4096),
up to PATH_TRUTH_DEPTH bounces, the ray tracer's truth seed, each frame new paths; on the GPU
(llvmpipe traces them about 13 times as fast as the twin: benchmarks/results/pathtrace.md), whose
paths are the twin's (tests/test_pathtrace.py); the frames' average clamped to [0, 1].

The ray tracer's truth is the reference ray tracer (reference/raytrace/pipeline.py) in float64
at up to RAY_TRUTH_DEPTH bounces, RAY_TRUTH_PASSES frames of RAY_TRUTH_SAMPLES jittered samples per
pixel (1024 in all), the frames' sample indices following one another (first_sample), so each
frame draws new, independent strata; its seed is not the sweep's; a scene with area lights
takes RAY_TRUTH_LIGHT_SAMPLES points on each per hit. The frames' average linear
colour, clamped to [0, 1], is the truth: what the tracer shows of a pixel, as the frames it is
compared with. A frame at a time bounds the memory (the reference holds a frame's rays at once).

    truth_scene(scene)                              the scene as the rasteriser's truth draws it
    ground_truth(scene, 160, 120, cache_dir)        ((120, 160, 3) float64 in [0, 1], cache hit?)
    ground_truth(scene, 160, 120, cache_dir, method="raytrace")     the ray tracer's
    ground_truth(scene, 160, 120, cache_dir, method="radiosity")    radiosity's (path traced)
    ground_truths(scenes, 160, 120, cache_dir, tasks=executor.tasks)  several, the misses elsewhere
"""

from __future__ import annotations

import hashlib
from dataclasses import dataclass
from pathlib import Path
from typing import Callable

import numpy as np

from renderer.core.imageio import write_npy
from renderer.core.light_areas import uses_area_lights
from renderer.core.paths import output_stem
from renderer.core.ray_depth import MAX_DEPTH_LIMIT
from renderer.core.ray_options import RayOptions
from renderer.core.sampling import DEFAULT_SEED
from renderer.core.scene import Scene
from renderer.methods import open_renderer
from renderer.study.supersample import clamped
from renderer.study.tessellation import FINEST, scene_at_level
from renderer.study.texture_report import truth_textures

TRUTH_GRID = 16                        # samples per pixel along x and along y
TRUTH_VERSION = 2                      # bump when the truth's recipe changes: old entries miss
                                       # (2: an analytic plane drawn as its view-volume polygon)
MAX_TRUTH_PIXELS = 5120 * 3840         # the 16x image of 320x240; rendered in one piece
RAY_TRUTH_SAMPLES = 64                 # jittered samples per pixel in one frame (8 x 8 strata)
RAY_TRUTH_PASSES = 16                  # frames averaged: 1024 samples per pixel
RAY_TRUTH_DEPTH = MAX_DEPTH_LIMIT      # as deep as the tracer goes (its weight cut-off ends
                                       # a ray tree before that: renderer/core/ray_depth.py)
RAY_TRUTH_SEED = DEFAULT_SEED + 1      # not the seed of the swept patterns' samples
RAY_TRUTH_VERSION = 1                  # bump when the ray truth's recipe changes
RAY_TRUTH_LIGHT_SAMPLES = 4            # per area light and hit, where the scene has area lights:
                                       # 4096 shadow rays per pixel and light, 16 times the
                                       # light_samples knob's most (renderer/study/distributed_report.py)
PATH_TRUTH_SAMPLES = 256               # radiosity's truth: jittered paths per pixel in one frame
PATH_TRUTH_PASSES = 16                 # frames averaged: 4096 paths per pixel
PATH_TRUTH_DEPTH = MAX_DEPTH_LIMIT     # bounces (Russian roulette ends most paths long before)
PATH_TRUTH_VERSION = 1                 # bump when the path truth's recipe changes


def default_cache_dir() -> Path:
    return Path.home() / ".cache" / "checked-renderer" / "truth"


def truth_scene(scene: Scene) -> Scene:
    """`scene` with Phong shading everywhere, the finest tessellation, and every texture as
    the truth samples it (renderer/study/texture_report.py truth_textures: its texels
    integrated over the pixel)."""
    return truth_textures(scene_at_level(scene.with_shading("phong"), FINEST))


def scene_digest(scene: Scene) -> str:
    """SHA-256 of everything that decides the image: camera, lights, ambient, background,
    the model (renderer/core/physical.py), and per object its name, material, transform, parent, culling, motion and mesh arrays
    (with a textured material, its UVs and texture levels)."""
    digest = hashlib.sha256()
    for part in (scene.camera, scene.directional_lights, scene.point_lights, scene.ambient,
                 scene.background):
        digest.update(repr(part).encode())
    if scene.model != "phong":            # (Phong scenes keep their cached truths)
        digest.update(f"model={scene.model}".encode())
    for obj in scene.objects:
        digest.update(repr((obj.name, obj.material, obj.transform, obj.parent, obj.cull)).encode())
        if obj.velocity is not None or obj.angular_velocity is not None:   # (still objects keep
            digest.update(repr((obj.velocity, obj.angular_velocity)).encode())  # their keys)
        if obj.shape is not None:             # what the ray tracer intersects instead of the mesh
            digest.update(repr(obj.shape).encode())
        for array, dtype in ((obj.mesh.positions, np.float64), (obj.mesh.normals, np.float64),
                             (obj.mesh.faces, np.int64)):
            digest.update(np.ascontiguousarray(array, dtype=dtype).tobytes())
        if obj.material.textured:             # its texels and where they go (the repr is short)
            digest.update(np.ascontiguousarray(obj.mesh.uvs, dtype=np.float64).tobytes())
            for level in obj.material.texture.texture.levels:
                digest.update(level.tobytes())
    return digest.hexdigest()


def cache_path(scene: Scene, width: int, height: int, cache_dir, method: str = "raster") -> Path:
    """Where the truth of `method` (a key of TRUTHS) is cached: named after the scene and
    size, keyed by the content of the scene it draws and the truth's recipe."""
    truth = truth_of(method)
    drawn, stem, recipe = truth.drawn(scene), output_stem(scene) + truth.suffix, truth.recipe(scene)
    key = hashlib.sha256(f"{scene_digest(drawn)} {width}x{height} {recipe}".encode()).hexdigest()[:24]
    return Path(cache_dir) / f"{stem}-{width}x{height}-{key}.npy"


def _ray_recipe(scene: Scene) -> str:
    recipe = (f"jittered={RAY_TRUTH_SAMPLES}x{RAY_TRUTH_PASSES} depth={RAY_TRUTH_DEPTH} "
              f"seed={RAY_TRUTH_SEED} v{RAY_TRUTH_VERSION}")
    if truth_light_samples(scene) > 1:          # (other scenes keep their cached truths)
        recipe += f" light_samples={truth_light_samples(scene)}"
    return recipe


def render_truth(scene: Scene, width: int, height: int, progress=None) -> np.ndarray:
    """(H, W, 3) float64: the truth rendered now (see the module docstring). One frame:
    `progress` is not told before it is done."""
    big_w, big_h = width * TRUTH_GRID, height * TRUTH_GRID
    if big_w * big_h > MAX_TRUTH_PIXELS:
        raise ValueError(f"a ground truth of {width}x{height} needs a {big_w}x{big_h} reference "
                         f"image; the most it renders is {MAX_TRUTH_PIXELS} pixels (320x240)")
    with open_renderer(truth_scene(scene), (big_w, big_h), backend="reference",
                       precision="float64") as truth:
        frame = truth.render(linear=True, depth=False)
    blocks = clamped(frame.linear[..., :3]).reshape(height, TRUTH_GRID, width, TRUTH_GRID, 3)
    return blocks.mean(axis=(1, 3))


def truth_light_samples(scene: Scene) -> int:
    """The light samples per hit of the ray tracer's truth: RAY_TRUTH_LIGHT_SAMPLES where some
    point light has an area, else 1 (more would change nothing)."""
    return RAY_TRUTH_LIGHT_SAMPLES if uses_area_lights(scene) else 1


def render_ray_truth(scene: Scene, width: int, height: int, progress=None) -> np.ndarray:
    """(H, W, 3) float64: the ray tracer's truth rendered now (see the module docstring);
    `progress(share done)`, if given, as each frame's rows are traced."""
    options = RayOptions(samples=RAY_TRUTH_SAMPLES, pattern="jittered", max_depth=RAY_TRUTH_DEPTH,
                         seed=RAY_TRUTH_SEED, light_samples=truth_light_samples(scene))
    total = np.zeros((height, width, 3))
    with open_renderer(scene, (width, height), method="raytrace", backend="reference",
                       options=options, precision="float64") as truth:      # one BVH for every pass
        for frame in range(RAY_TRUTH_PASSES):
            told = None if progress is None else (
                lambda rows, of, frame=frame: progress((frame + rows / of) / RAY_TRUTH_PASSES))
            total += truth.render(first_sample=frame * RAY_TRUTH_SAMPLES, progress=told).linear[..., :3]
    return clamped(total / RAY_TRUTH_PASSES)


def _path_recipe(scene: Scene) -> str:
    return (f"pathtrace jittered={PATH_TRUTH_SAMPLES}x{PATH_TRUTH_PASSES} depth={PATH_TRUTH_DEPTH} "
            f"seed={RAY_TRUTH_SEED} v{PATH_TRUTH_VERSION}")


def render_path_truth(scene: Scene, width: int, height: int, progress=None) -> np.ndarray:
    """(H, W, 3) float64: radiosity's truth, path traced now (module docstring);
    `progress(share done)` after each frame."""
    from renderer.checks.radiosity_vs_pathtrace import path_traced
    from renderer.core.path_options import PathOptions
    options = PathOptions(samples=PATH_TRUTH_SAMPLES, pattern="jittered", max_depth=PATH_TRUTH_DEPTH,
                          seed=RAY_TRUTH_SEED)
    return clamped(path_traced(scene, (width, height), options, PATH_TRUTH_PASSES, progress=progress)[0])


@dataclass(frozen=True)
class Truth:
    """A method's ground truth (module docstring): the scene it draws, what its cache files'
    names add to the scene's, its recipe (part of the cache key) and how it is rendered."""
    drawn: Callable[[Scene], Scene]
    suffix: str
    recipe: Callable[[Scene], str]
    render: Callable[..., np.ndarray]          # (scene, width, height, progress=None)


# Each method's truth, by the name renderer/methods registers it under.
TRUTHS = {"raster": Truth(truth_scene, "", lambda scene: f"grid={TRUTH_GRID} v{TRUTH_VERSION}", render_truth),
          "raytrace": Truth(lambda scene: scene, "-raytrace", _ray_recipe, render_ray_truth),
          "radiosity": Truth(lambda scene: scene, "-pathtrace", _path_recipe, render_path_truth)}


def truth_of(method: str) -> Truth:
    if method not in TRUTHS:
        raise ValueError(f"no ground truth is made for method {method!r}; one of {', '.join(TRUTHS)}")
    return TRUTHS[method]


def render_ground_truth(scene: Scene, width: int, height: int, method: str = "raster",
                        progress=None) -> np.ndarray:
    """The truth of `method` rendered now, uncached (a plain function: a task elsewhere);
    `progress(share done)` as the truth can tell it."""
    return truth_of(method).render(scene, width, height, progress=progress)


def ground_truths(scenes: list, width: int, height: int, cache_dir, method: str = "raster",
                  tasks=None, done=None, step=None) -> list[tuple[np.ndarray, bool]]:
    """ground_truth of each of `scenes`; the misses rendered through `tasks(function, args)`
    ((index, result) pairs in any order: an executor's, renderer/cluster/executor.py, which may
    render them elsewhere, at once; default here, one after another) and stored here.
    `done(scene)`, if given, as each truth is ready (a progress bar: a miss takes minutes);
    `step(scene, share done)` inside a truth rendered here (not through `tasks`)."""
    paths = [cache_path(scene, width, height, cache_dir, method) for scene in scenes]
    truths = [(np.load(path), True) if path.is_file() else None for path in paths]
    missing = [index for index, truth in enumerate(truths) if truth is None]
    for index in range(len(scenes)) if done is not None else ():
        if truths[index] is not None:
            done(scenes[index])
    if tasks is None:
        def tasks(function, args):
            for k, a in enumerate(args):
                yield k, function(*a, progress=None if step is None else
                                  (lambda share, scene=a[0]: step(scene, share)))
    for k, truth in tasks(render_ground_truth, [(scenes[i], width, height, method) for i in missing]):
        write_npy(paths[missing[k]], truth)
        truths[missing[k]] = (truth, False)
        if done is not None:
            done(scenes[missing[k]])
    return truths


def ground_truth(scene: Scene, width: int, height: int, cache_dir,
                 method: str = "raster") -> tuple[np.ndarray, bool]:
    """(truth (H, W, 3) float64, whether it came from the cache) of `method` ("raster" or
    "raytrace"). A miss renders it and stores it atomically under `cache_dir`, named after
    the scene, size and content hash."""
    return ground_truths([scene], width, height, cache_dir, method)[0]
