"""A turntable camera for the interactive viewer: orbit, pan and zoom about the look point.

`OrbitCamera` only makes new `Camera` values; the viewer reads `.camera` each frame. All
math is float64 and done on `eye - look`, so a scene 1e6 units from the origin turns as
smoothly as one at the origin (the eye is rebuilt as `look + offset` once, at the end).

Directions, in the camera's own frame (`transforms.look_at_rotation`: right = forward x up,
screen up = right x forward):
- `orbit(a, e)`: `renderer.core.camera_paths.orbit` (its docstring: +a turns the eye towards
  the camera's right about up, +e raises it, the polar angle stays within [1°, 179°]).
- `pan(+dx, +dy, H)`: the cursor moved right / down in window coordinates (y grows
  downwards, as glfw reports it): the camera moves left / up, so that the point at the look
  distance under the cursor stays under it.
- `zoom(+s)`: closer (perspective: the eye moves towards the look point; parallel: the view
  volume gets smaller).

`camera.up` is never changed; only eye, look (pan) and, for parallel cameras, height are.
"""

from __future__ import annotations

import math
from dataclasses import replace

import numpy as np

from renderer.core.camera_paths import as_tuple as _tuple, as_vec as _vec, orbit, view_rotation
from renderer.core.scene import Camera

ZOOM_FACTOR = 0.9          # one wheel step closer multiplies the distance (or height) by this
# Perspective zoom keeps the look point between these multiples of the clip planes: past
# the near plane it (and whatever surrounds it) would be clipped, past the far plane too.
NEAR_MARGIN = 1.5
FAR_MARGIN = 0.9
# Parallel zoom keeps the view height within this factor of the initial height either way
# (a bound like the clip planes' for perspective, so the wheel never reaches 0 or inf).
PARALLEL_ZOOM_RANGE = 1e4


def _towards(current: float, proposed: float, low: float, high: float) -> float:
    """`proposed` clamped to [low, high], but never past `current` when that is already
    outside: a step may only come back towards the range, so nothing jumps."""
    if proposed < current:
        return max(proposed, min(current, low))
    if proposed > current:
        return min(proposed, max(current, high))
    return current


class OrbitCamera:
    """Turntable control over a Camera: orbit about the look point, pan, zoom, reset."""

    def __init__(self, camera: Camera):
        self._initial = replace(camera)
        self.camera = replace(camera)

    def reset(self) -> None:
        """Back to the camera this controller was made with."""
        self.camera = replace(self._initial)

    # ------------------------------------------------------------------------ the camera's frame

    def _offset(self) -> tuple[np.ndarray, np.ndarray, float]:
        """Look point, eye - look and its length, in float64."""
        look = _vec(self.camera.look)
        offset = _vec(self.camera.eye) - look
        return look, offset, float(np.linalg.norm(offset))

    def _rotation(self, offset: np.ndarray) -> np.ndarray:
        return view_rotation(offset, self.camera.up)

    # ------------------------------------------------------------------------ the moves

    def orbit(self, d_azimuth_deg: float, d_elevation_deg: float) -> None:
        """Turn the eye about the look point (`camera_paths.orbit`: azimuth about up, +
        towards the camera's right; elevation + upwards; polar angle kept in range)."""
        self.camera = orbit(self.camera, d_azimuth_deg, d_elevation_deg)

    def pan(self, dx_px: float, dy_px: float, viewport_height_px: int) -> None:
        """Move eye and look across the view so that the scene follows the cursor: the
        cursor moved dx_px right and dy_px down (window coordinates, y down)."""
        if viewport_height_px <= 0:
            return                                   # a minimised window: nothing to follow
        cam = self.camera
        look, offset, distance = self._offset()
        if cam.projection == "perspective":
            # The view's height at the look distance, over the pixels that show it.
            unit = 2.0 * distance * math.tan(math.radians(cam.fov_y) / 2.0) / viewport_height_px
        else:
            unit = cam.height / viewport_height_px
        rotation = self._rotation(offset)
        move = unit * (-dx_px * rotation[0, :3] + dy_px * rotation[1, :3])
        new_look = look + move
        self.camera = replace(cam, eye=_tuple(new_look + offset), look=_tuple(new_look))

    def zoom(self, steps: float) -> None:
        """Wheel steps, + closer: the distance (parallel: the view height) times
        ZOOM_FACTOR ** steps, clamped (NEAR_MARGIN, FAR_MARGIN, PARALLEL_ZOOM_RANGE)."""
        if steps == 0:
            return
        factor = ZOOM_FACTOR ** steps
        cam = self.camera
        if cam.projection == "parallel":
            initial = self._initial.height
            height = _towards(cam.height, cam.height * factor,
                              initial / PARALLEL_ZOOM_RANGE, initial * PARALLEL_ZOOM_RANGE)
            self.camera = replace(cam, height=float(height))
            return
        look, offset, distance = self._offset()
        new = _towards(distance, distance * factor, NEAR_MARGIN * cam.near, FAR_MARGIN * cam.far)
        self.camera = replace(cam, eye=_tuple(look + offset * (new / distance)))
