"""The ground truth the report measures every setting against, cached on disk by content.

The truth is the NumPy reference in float64, Phong shading on every object, every curved
primitive at the finest tessellation (renderer/study/tessellation.py FINEST), and 16 x 16
supersampling per pixel. Rendering the reference once at 16W x 16H and averaging each
16 x 16 block of clamped linear colour is exactly the 16 x 16 regular grid of sample offsets
((a + 0.5) / 16 - 0.5, (b + 0.5) / 16 - 0.5) (renderer/core/sampling.py regular_grid(256)) at a
256th of the passes' cost.

    truth_scene(scene)                              the scene as the truth draws it
    ground_truth(scene, 160, 120, cache_dir)        ((120, 160, 3) float64 in [0, 1], cache hit?)
"""

from __future__ import annotations

import hashlib
from pathlib import Path

import numpy as np

import reference
from renderer.core.imageio import write_npy
from renderer.core.paths import output_stem
from renderer.core.scene import Scene
from renderer.study.supersample import clamped
from renderer.study.tessellation import FINEST, scene_at_level

TRUTH_GRID = 16                        # samples per pixel along x and along y
TRUTH_VERSION = 1                      # bump when the truth's recipe changes: old entries miss
MAX_TRUTH_PIXELS = 5120 * 3840         # the 16x image of 320x240; rendered in one piece


def default_cache_dir() -> Path:
    return Path.home() / ".cache" / "checked-renderer" / "truth"


def truth_scene(scene: Scene) -> Scene:
    """`scene` with Phong shading everywhere and the finest tessellation."""
    return scene_at_level(scene.with_shading("phong"), FINEST)


def scene_digest(scene: Scene) -> str:
    """SHA-256 of everything that decides the image: camera, lights, ambient, background,
    and per object its name, material, transform, parent, culling and mesh arrays."""
    digest = hashlib.sha256()
    for part in (scene.camera, scene.directional_lights, scene.point_lights, scene.ambient,
                 scene.background):
        digest.update(repr(part).encode())
    for obj in scene.objects:
        digest.update(repr((obj.name, obj.material, obj.transform, obj.parent, obj.cull)).encode())
        for array, dtype in ((obj.mesh.positions, np.float64), (obj.mesh.normals, np.float64),
                             (obj.mesh.faces, np.int64)):
            digest.update(np.ascontiguousarray(array, dtype=dtype).tobytes())
    return digest.hexdigest()


def cache_path(scene: Scene, width: int, height: int, cache_dir) -> Path:
    key = hashlib.sha256(f"{scene_digest(truth_scene(scene))} {width}x{height} "
                         f"grid={TRUTH_GRID} v{TRUTH_VERSION}".encode()).hexdigest()[:24]
    return Path(cache_dir) / f"{output_stem(scene)}-{width}x{height}-{key}.npy"


def render_truth(scene: Scene, width: int, height: int) -> np.ndarray:
    """(H, W, 3) float64: the truth rendered now (see the module docstring)."""
    big_w, big_h = width * TRUTH_GRID, height * TRUTH_GRID
    if big_w * big_h > MAX_TRUTH_PIXELS:
        raise ValueError(f"a ground truth of {width}x{height} needs a {big_w}x{big_h} reference "
                         f"image; the most it renders is {MAX_TRUTH_PIXELS} pixels (320x240)")
    frame = reference.render(truth_scene(scene), big_w, big_h, dtype=np.float64,
                             linear=True, depth=False)
    blocks = clamped(frame.linear[..., :3]).reshape(height, TRUTH_GRID, width, TRUTH_GRID, 3)
    return blocks.mean(axis=(1, 3))


def ground_truth(scene: Scene, width: int, height: int, cache_dir) -> tuple[np.ndarray, bool]:
    """(truth (H, W, 3) float64, whether it came from the cache). A miss renders it and
    stores it atomically under `cache_dir`, named after the scene, size and content hash."""
    path = cache_path(scene, width, height, cache_dir)
    if path.is_file():
        return np.load(path), True
    truth = render_truth(scene, width, height)
    write_npy(path, truth)
    return truth, False
