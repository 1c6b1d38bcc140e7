"""Frustum culling of whole objects: which objects of a frame can show at all.

Both pipelines ask this before drawing (renderer/gpu/pipeline.py when it plans a frame, and
reference/pipeline.py), so an object wholly outside the view volume costs neither of them
its vertex work. The test is exact for the object's bounding box and never drops anything
visible: the box's 8 corners are taken to clip space (p_clip = P V M p, float64) and the
object is dropped only when all 8 lie outside one and the same clip plane (GL keeps
-w <= x, y, z <= w, docs/conventions.md). Each plane's inequality is linear in clip
coordinates, so when the corners fail it so does every point of the box, whatever w is
(this holds for corners behind the eye too). Under reversed-Z the depth range is
0 <= z <= w, inside -w <= z <= w, so the same planes stay conservative there.
"""

from __future__ import annotations

import numpy as np

from renderer.core.scene import FrameMatrices, Mesh, Scene

# Clip-space planes as (axis, sign): inside when w + sign * coordinate[axis] >= 0.
CLIP_PLANES = ((0, 1.0), (0, -1.0), (1, 1.0), (1, -1.0), (2, 1.0), (2, -1.0))


def box_corners(mesh: Mesh) -> np.ndarray:
    """(8, 4) homogeneous corners of the mesh's axis-aligned bounding box in object space."""
    lo, hi = mesh.positions.min(axis=0), mesh.positions.max(axis=0)
    pick = np.array([[(i >> k) & 1 for k in range(3)] for i in range(8)], dtype=bool)
    corners = np.where(pick, hi, lo)
    return np.hstack([corners, np.ones((8, 1))])


def outside_view_volume(clip_from_object: np.ndarray, mesh: Mesh) -> bool:
    """True when the mesh is wholly outside one clip plane under `clip_from_object` (P V M)."""
    if mesh.triangle_count == 0:
        return True
    clip = box_corners(mesh) @ np.asarray(clip_from_object, dtype=np.float64).T    # (8, 4)
    return any(bool(np.all(clip[:, 3] + sign * clip[:, axis] < 0.0)) for axis, sign in CLIP_PLANES)


def visible_objects(scene: Scene, matrices: FrameMatrices) -> list[bool]:
    """For each object of the scene, whether any of it may fall inside the view volume."""
    clip_from_world = matrices.projection @ matrices.view
    return [not outside_view_volume(clip_from_world @ m.model, obj.mesh)
            for obj, m in zip(scene.objects, matrices.objects)]
