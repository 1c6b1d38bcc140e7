"""Orbit views for the batch runner (`camera_paths.orbit_cameras`); the turntable rule
itself (`camera_paths.orbit`, the viewer's drag) is specified in tests/test_orbit.py."""

import math

import numpy as np
import pytest

from renderer.core.camera_paths import orbit, orbit_cameras
from renderer.core.scene import Camera

CAMERA = Camera(eye=(0.0, 0.0, 5.0), look=(0.0, 0.0, 0.0), up=(0.0, 1.0, 0.0))


def test_four_views_are_the_quarter_turns_towards_the_right():
    eyes = [c.eye for c in orbit_cameras(CAMERA, 4)]
    np.testing.assert_allclose(eyes, [(0, 0, 5), (5, 0, 0), (0, 0, -5), (-5, 0, 0)], atol=1e-12)


def test_views_keep_everything_but_the_eye():
    moved = orbit_cameras(Camera(eye=(1.0, 2.0, 3.0), look=(1.0, 0.0, 0.0), fov_y=30.0), 3)
    assert all((c.look, c.up, c.fov_y) == ((1.0, 0.0, 0.0), (0.0, 1.0, 0.0), 30.0) for c in moved)


def test_an_elevation_sets_the_height_above_the_look_point():
    # 30° up at distance 5: height 5 sin 30° = 2.5, horizontal distance 5 cos 30°.
    for camera in orbit_cameras(CAMERA, 3, elevation=30.0):
        x, y, z = camera.eye
        assert y == pytest.approx(2.5)
        assert math.hypot(x, z) == pytest.approx(5 * math.cos(math.radians(30)))


def test_each_view_is_one_turn_from_the_camera_not_a_chain_of_steps():
    views = orbit_cameras(CAMERA, 7, elevation=-20.0)
    assert views[5] == orbit(CAMERA, 360.0 * 5 / 7, -20.0)


def test_an_orbit_needs_a_view():
    with pytest.raises(ValueError, match="at least 1 view"):
        orbit_cameras(CAMERA, 0)
