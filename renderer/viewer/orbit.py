"""A turntable camera for the interactive viewer: orbit, pan and zoom about the look point.

`OrbitCamera` only makes new `Camera` values; the viewer reads `.camera` each frame. All
math is float64 and done on `eye - look`, so a scene 1e6 units from the origin turns as
smoothly as one at the origin (the eye is rebuilt as `look + offset` once, at the end).

Directions, in the camera's own frame (`transforms.look_at_rotation`: right = forward x up,
screen up = right x forward):
- `orbit(+a, 0)`: the eye turns about the up axis towards the camera's right (a right-hand
  rotation by +a about up). From eye (0, 0, 5), look (0, 0, 0), up +y, `orbit(90, 0)` puts
  the eye at (5, 0, 0); the scene seems to turn to the left.
- `orbit(0, +e)`: the eye rises towards up. The polar angle between `eye - look` and up is
  kept within [1°, 179°] after every orbit, so the camera never passes over a pole, where
  the image would flip. A camera authored on a pole (up parallel to the view, where look_at
  falls back to `transforms.fallback_up`) is moved 1° off it, towards the bottom of its
  image, so that its first orbit does not turn the image; from there azimuth is about up.
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

from renderer.core import transforms
from renderer.core.scene import Camera

ZOOM_FACTOR = 0.9          # one wheel step closer multiplies the distance (or height) by this
MIN_POLAR_DEG = 1.0        # closest the eye gets to the up axis above the look point ...
MAX_POLAR_DEG = 179.0      # ... and below it
# Perspective zoom keeps the look point between these multiples of the clip planes: past
# the near plane it (and whatever surrounds it) would be clipped, past the far plane too.
NEAR_MARGIN = 1.5
FAR_MARGIN = 0.9
# Parallel zoom keeps the view height within this factor of the initial height either way
# (a bound like the clip planes' for perspective, so the wheel never reaches 0 or inf).
PARALLEL_ZOOM_RANGE = 1e4


def _vec(v) -> np.ndarray:
    return np.asarray(v, dtype=np.float64)


def _tuple(v) -> tuple:
    return tuple(float(x) for x in v)


def _rotate(v: np.ndarray, axis: np.ndarray, angle: float) -> np.ndarray:
    """Rodrigues' rotation of v by `angle` radians about the unit `axis` (right-hand rule)."""
    c, s = math.cos(angle), math.sin(angle)
    return v * c + np.cross(axis, v) * s + axis * (np.dot(axis, v) * (1.0 - c))


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
        """The view rotation (rows: right, screen up, back); it depends on eye - look only."""
        return transforms.look_at_rotation(offset, np.zeros(3), self.camera.up)

    def _up_axis(self, direction: np.ndarray) -> np.ndarray:
        """The turntable axis: up as given, normalised; a zero up means look_at's fallback."""
        up = _vec(self.camera.up)
        length = np.linalg.norm(up)
        if length > 0:
            return up / length
        return transforms.fallback_up(-direction)

    # ------------------------------------------------------------------------ the moves

    def orbit(self, d_azimuth_deg: float, d_elevation_deg: float) -> None:
        """Turn the eye about the look point: azimuth about up (+ towards the camera's
        right), elevation towards up (+ upwards), polar angle kept in [1°, 179°]."""
        look, offset, distance = self._offset()
        direction = offset / distance
        k = self._up_axis(direction)
        cos_polar = float(np.dot(k, direction))
        sin_polar = float(np.linalg.norm(np.cross(k, direction)))
        polar = math.atan2(sin_polar, cos_polar)
        target = min(max(polar - math.radians(d_elevation_deg), math.radians(MIN_POLAR_DEG)),
                     math.radians(MAX_POLAR_DEG))
        if target != polar:
            # The unit vector h across the up axis in the plane of up and the eye, pointing
            # away from the axis to the eye's side: sin p * dir - cos p * screen_up. Unlike
            # the eye's horizontal part it is defined on a pole too, where look_at's screen
            # up (from its fallback) decides which way the eye leaves the pole.
            screen_up = self._rotation(offset)[1, :3]
            h = sin_polar * direction - cos_polar * screen_up
            h = h / np.linalg.norm(h)
            direction = math.cos(target) * k + math.sin(target) * h
        if d_azimuth_deg != 0:
            direction = _rotate(direction, k, math.radians(d_azimuth_deg))
        # Renormalised so that the distance is kept to rounding, however many turns add up.
        offset = direction * (distance / np.linalg.norm(direction))
        self.camera = replace(self.camera, eye=_tuple(look + offset))

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
