"""Frustum culling of whole objects: which objects of a frame can show at all.

Both pipelines ask this before drawing (renderer/gpu/pipeline.py when it plans a frame, and
reference/pipeline.py), so an object wholly outside the view volume costs neither of them
its vertex work. It tests what the camera pass draws of each object (renderer/core/drawn.py:
its mesh, or an analytic plane's polygon in the view volume, empty where the plane misses it).
The test is exact for that mesh's bounding box and never drops anything visible: the box's 8 corners are taken to clip space (p_clip = P V M p, float64) and the
object is dropped only when all 8 lie outside one and the same clip plane (GL keeps
-w <= x, y, z <= w, docs/conventions.md). Each plane's inequality is linear in clip
coordinates, so when the corners fail it so does every point of the box, whatever w is
(this holds for corners behind the eye too). Under reversed-Z the depth range is
0 <= z <= w, inside -w <= z <= w, so the same planes stay conservative there.

The same corners say why a frame shows nothing (`not_in_view`, `nothing_in_view`, for the
command line's warning): an object is nearer than the near plane or beyond the far plane
when every corner is outside that plane of the camera's depth mapping (gl_rules.DepthMapping:
z_ndc = ndc_near at the near plane, ndc_far at the far one), and behind the camera when it
is outside the near plane with every corner at or behind the eye (w <= 0 in perspective,
where w is the distance in front of the eye; for a parallel projection, whose w is 1, the
corners' camera-space depth says it); to the left, right, above or below the view when every
corner is outside that side plane.
"""

from __future__ import annotations

import numpy as np

from renderer.core.drawn import DrawnMesh, drawn_meshes, is_plane
from renderer.core.gl_rules import depth_mapping
from renderer.core.scene import FrameMatrices, Mesh, Scene
from renderer.errors import show_number

# Clip-space planes as (axis, sign): inside when w + sign * coordinate[axis] >= 0.
CLIP_PLANES = ((0, 1.0), (0, -1.0), (1, 1.0), (1, -1.0), (2, 1.0), (2, -1.0))


# Corner k of a box takes its high end on axis a where bit a of k is set.
CORNER_PICK = np.array([[(i >> k) & 1 for k in range(3)] for i in range(8)], dtype=bool)


def corners(lo: np.ndarray, hi: np.ndarray) -> np.ndarray:
    """(..., 8, 4) homogeneous corners of boxes with low and high ends lo, hi (..., 3)."""
    lo, hi = np.asarray(lo, dtype=np.float64), np.asarray(hi, dtype=np.float64)
    picked = np.where(CORNER_PICK, hi[..., None, :], lo[..., None, :])
    return np.concatenate([picked, np.ones(picked.shape[:-1] + (1,))], axis=-1)


def box_corners(mesh: Mesh) -> np.ndarray:
    """(8, 4) homogeneous corners of the mesh's axis-aligned bounding box in object space."""
    return corners(mesh.positions.min(axis=0), mesh.positions.max(axis=0))


def clip_corners(clip_from_object: np.ndarray, mesh: Mesh) -> np.ndarray:
    """(8, 4) corners of the mesh's bounding box in clip space under `clip_from_object`."""
    return box_corners(mesh) @ np.asarray(clip_from_object, dtype=np.float64).T


def all_outside(clip: np.ndarray) -> np.ndarray:
    """(...) whether the points clip (..., 8, 4) (a box's corners in clip space) all lie
    outside one clip plane: then nothing of the box is in the view volume."""
    w = clip[..., 3]
    return np.any([np.all(w + sign * clip[..., axis] < 0.0, axis=-1) for axis, sign in CLIP_PLANES],
                  axis=0)


def outside_view_volume(clip_from_object: np.ndarray, mesh: Mesh) -> bool:
    """True when the mesh is wholly outside one clip plane under `clip_from_object` (P V M)."""
    if mesh.triangle_count == 0:
        return True
    return bool(all_outside(clip_corners(clip_from_object, mesh)))


def visible_objects(scene: Scene, matrices: FrameMatrices,
                    drawn: list[DrawnMesh] | None = None) -> list[bool]:
    """For each object of the scene, whether any of what the camera pass draws of it
    (`drawn`, renderer/core/drawn.py; made from `matrices` when not given) may fall inside the
    view volume. A plane's polygon lies in it, or is empty where the plane misses it."""
    drawn = drawn_meshes(scene, matrices) if drawn is None else drawn
    clip_from_world = matrices.projection @ matrices.view
    return [not outside_view_volume(clip_from_world @ d.matrices.model, d.mesh) for d in drawn]


# Why an analytic plane draws nothing: no point of it is in the view volume.
PLANE_MISSES = "outside the view volume (an infinite plane that misses it)"

# Side planes as (axis, sign, where the box is): outside when sign * coordinate > w.
SIDES = ((0, -1.0, "to the left of the view"), (0, 1.0, "to the right of the view"),
         (1, 1.0, "above the view"), (1, -1.0, "below the view"))


def not_in_view(scene: Scene, matrices: FrameMatrices) -> list[str | None]:
    """For each object, why none of it can show, as a user would say it ("behind the
    camera", "beyond the far plane (100)", ...), from the bounding box's corners in clip space
    of what the camera pass draws of it (renderer/core/drawn.py); None when the box reaches
    into the view volume. In order: no triangles (for an analytic plane: it misses the view
    volume), behind the camera or else nearer than the near plane, beyond the far plane,
    beside the view."""
    camera = scene.camera
    mapping = depth_mapping(camera.reversed_z)
    inward = np.sign(mapping.ndc_far - mapping.ndc_near)     # +1, or -1 under reversed-Z
    clip_from_world = matrices.projection @ matrices.view
    reasons = []
    for obj, drawn in zip(scene.objects, drawn_meshes(scene, matrices)):
        mesh, model = drawn.mesh, drawn.matrices.model
        if mesh.triangle_count == 0:
            reasons.append(PLANE_MISSES if is_plane(obj) else "has no triangles")
            continue
        x, y, z, w = clip_corners(clip_from_world @ model, mesh).T
        depth = -clip_corners(matrices.view @ model, mesh)[:, 2]    # -z_eye; w in perspective
        if np.all(inward * (z - mapping.ndc_near * w) < 0.0):
            reasons.append("behind the camera" if np.all(depth <= 0.0) else
                           f"nearer than the near plane ({show_number(camera.near)})")
        elif np.all(inward * (mapping.ndc_far * w - z) < 0.0):
            reasons.append(f"beyond the far plane ({show_number(camera.far)})")
        else:
            coordinate = (x, y)
            side = next((where for axis, sign, where in SIDES
                         if np.all(sign * coordinate[axis] > w)), None)
            reasons.append(side)
    return reasons


def _subject(names: list[str], total: int) -> str:
    """The objects of one group as the subject of a sentence."""
    if len(names) == total == 2:
        return f"both {names[0]} and {names[1]}"
    if len(names) == total == 3:
        return f"all of {names[0]}, {names[1]} and {names[2]}"
    if len(names) == total > 3:
        return f"all {total} objects"
    if len(names) > 3:
        return f"{len(names)} objects"
    return names[0] if len(names) == 1 else f"{', '.join(names[:-1])} and {names[-1]}"


def nothing_in_view(scene: Scene, matrices: FrameMatrices) -> str:
    """Why a frame of the scene in which nothing was drawn shows nothing, in one clause:
    the objects grouped by `not_in_view`'s reason, e.g. "ball and box are behind the
    camera; floor is beyond the far plane (10)". Call it when nothing was drawn: an object
    whose box reaches into the view volume is said to draw nothing there."""
    if not scene.objects:
        return "the scene has no objects"
    groups: dict[str, list[str]] = {}
    for obj, reason in zip(scene.objects, not_in_view(scene, matrices)):
        if reason is None:
            reason = "in the view volume, yet no triangle covers a pixel centre"
            if obj.cull != "none":
                reason += f' or all that do are culled (cull = "{obj.cull}")'
        groups.setdefault(reason, []).append(obj.name)
    parts = []
    for reason, names in groups.items():
        plural = len(names) > 1
        if reason.startswith("has "):
            predicate = f"have {reason[4:]}" if plural else reason
        else:
            predicate = f"{'are' if plural else 'is'} {reason}"
        parts.append(f"{_subject(names, len(scene.objects))} {predicate}")
    return "; ".join(parts)
