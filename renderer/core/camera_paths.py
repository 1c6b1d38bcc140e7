"""Camera moves as pure functions of a Camera: the turntable orbit the viewer drags and the
batch runner's orbit views (K cameras round the look point).

All maths is float64 on `eye - look`, so a scene 1e6 units from the origin turns as
smoothly as one at the origin (the eye is rebuilt as `look + offset` once, at the end).
Only the eye changes; look and `camera.up` are kept.

Directions, in the camera's own frame (`transforms.look_at_rotation`: right = forward x up,
screen up = right x forward):
- `orbit(camera, +a, 0)`: the eye turns about the up axis towards the camera's right (a
  right-hand rotation by +a about up). From eye (0, 0, 5), look (0, 0, 0), up +y, a turn of
  90 puts the eye at (5, 0, 0); the scene seems to turn to the left.
- `orbit(camera, 0, +e)`: the eye rises towards up. The polar angle between `eye - look` and
  up is kept within [MIN_POLAR_DEG, MAX_POLAR_DEG], so the camera never passes over a pole,
  where the image would flip. A camera authored on a pole (up parallel to the view, where
  look_at falls back to `transforms.fallback_up`) is moved 1° off it, towards the bottom of
  its image, so that its first orbit does not turn the image; from there azimuth is about up.
- `orbit_cameras(camera, K, elevation)`: view k is `orbit(camera, 360 k / K, ...)` from the
  given camera itself (never step by step, so no rounding adds up), view 0 at its azimuth.
"""

from __future__ import annotations

import math
from dataclasses import replace

import numpy as np

from renderer.core import transforms
from renderer.core.scene import Camera

MIN_POLAR_DEG = 1.0        # closest the eye gets to the up axis above the look point ...
MAX_POLAR_DEG = 179.0      # ... and below it


def as_vec(v) -> np.ndarray:
    return np.asarray(v, dtype=np.float64)


def as_tuple(v) -> tuple:
    return tuple(float(x) for x in v)


def view_rotation(offset: np.ndarray, up) -> np.ndarray:
    """The view rotation (rows: right, screen up, back); it depends on eye - look only."""
    return transforms.look_at_rotation(offset, np.zeros(3), up)


def _rotate(v: np.ndarray, axis: np.ndarray, angle: float) -> np.ndarray:
    """Rodrigues' rotation of v by `angle` radians about the unit `axis` (right-hand rule)."""
    c, s = math.cos(angle), math.sin(angle)
    return v * c + np.cross(axis, v) * s + axis * (np.dot(axis, v) * (1.0 - c))


def _up_axis(camera: Camera, direction: np.ndarray) -> np.ndarray:
    """The turntable axis: up as given, normalised; a zero up means look_at's fallback."""
    up = as_vec(camera.up)
    length = np.linalg.norm(up)
    if length > 0:
        return up / length
    return transforms.fallback_up(-direction)


def _polar(camera: Camera):
    """Look point, eye - look, its length and direction, the up axis, and the polar angle
    between them with its sine and cosine."""
    look = as_vec(camera.look)
    offset = as_vec(camera.eye) - look
    distance = float(np.linalg.norm(offset))
    direction = offset / distance
    k = _up_axis(camera, direction)
    cos_polar = float(np.dot(k, direction))
    sin_polar = float(np.linalg.norm(np.cross(k, direction)))
    return look, offset, distance, direction, k, math.atan2(sin_polar, cos_polar), sin_polar, cos_polar


def orbit(camera: Camera, d_azimuth_deg: float, d_elevation_deg: float) -> Camera:
    """The camera with its eye turned about the look point: azimuth about up (+ towards the
    camera's right), elevation towards up (+ upwards), polar angle kept in range."""
    look, offset, distance, direction, k, polar, sin_polar, cos_polar = _polar(camera)
    target = min(max(polar - math.radians(d_elevation_deg), math.radians(MIN_POLAR_DEG)),
                 math.radians(MAX_POLAR_DEG))
    if target != polar:
        # The unit vector h across the up axis in the plane of up and the eye, pointing
        # away from the axis to the eye's side: sin p * dir - cos p * screen_up. Unlike
        # the eye's horizontal part it is defined on a pole too, where look_at's screen
        # up (from its fallback) decides which way the eye leaves the pole.
        screen_up = view_rotation(offset, camera.up)[1, :3]
        h = sin_polar * direction - cos_polar * screen_up
        h = h / np.linalg.norm(h)
        direction = math.cos(target) * k + math.sin(target) * h
    if d_azimuth_deg != 0:
        direction = _rotate(direction, k, math.radians(d_azimuth_deg))
    # Renormalised so that the distance is kept to rounding, however many turns add up.
    offset = direction * (distance / np.linalg.norm(direction))
    return replace(camera, eye=as_tuple(look + offset))


def orbit_cameras(camera: Camera, views: int, elevation: float | None = None) -> list[Camera]:
    """`views` cameras evenly round the up axis through the look point, view 0 at `camera`'s
    azimuth; all at `elevation` degrees above the plane across up (default: the camera's
    own), each made from `camera` in one step."""
    if views < 1:
        raise ValueError(f"an orbit needs at least 1 view, got {views}")
    d_elevation = 0.0
    if elevation is not None:
        d_elevation = elevation - (90.0 - math.degrees(_polar(camera)[5]))
    return [orbit(camera, 360.0 * i / views, d_elevation) for i in range(views)]
