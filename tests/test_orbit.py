"""renderer/viewer/orbit.py: the viewer's turntable camera, a hand-checked case per rule.

The standard camera below looks from (0, 0, 5) at the origin with up +y, so its right is +x
and its screen up +y. Pan is checked by projecting with the project's own matrices
(Scene.matrices): the point that was at the look point must land where the cursor went.
"""

import math
from dataclasses import replace

import numpy as np
import pytest

from renderer.core import builtin
from renderer.core import transforms
from renderer.viewer.orbit import (FAR_MARGIN, NEAR_MARGIN, PARALLEL_ZOOM_RANGE, ZOOM_FACTOR,
                            OrbitCamera)
from renderer.core.scene import Camera, Scene
from renderer.core.scene_file import load_scene

C1, S1 = math.cos(math.radians(1.0)), math.sin(math.radians(1.0))


def standard(**changes) -> OrbitCamera:
    return OrbitCamera(Camera(eye=(0.0, 0.0, 5.0), look=(0.0, 0.0, 0.0), up=(0.0, 1.0, 0.0),
                              **changes))


def distance(camera: Camera) -> float:
    return float(np.linalg.norm(np.subtract(camera.eye, camera.look)))


def window_position(camera: Camera, point, width: int, height: int) -> np.ndarray:
    """Where `point` appears, in pixels from the window's top-left corner (y down, as glfw
    reports the cursor), through Scene.matrices' camera-relative view and projection."""
    m = Scene(camera=camera).matrices(width, height)
    clip = m.projection @ m.view @ np.array([*m.relative(point), 1.0])
    ndc = clip[:3] / clip[3]
    return np.array([(ndc[0] + 1) * width / 2, height - (ndc[1] + 1) * height / 2])


# --------------------------------------------------------------------------- orbit

def test_azimuth_plus_90_moves_the_eye_to_the_cameras_right():
    """Right = forward x up = (0,0,-1) x (0,1,0) = +x: the eye goes from (0,0,5) to (5,0,0)."""
    orbit = standard()
    orbit.orbit(90.0, 0.0)
    np.testing.assert_allclose(orbit.camera.eye, (5.0, 0.0, 0.0), atol=1e-12)
    assert orbit.camera.look == (0.0, 0.0, 0.0)
    assert orbit.camera.up == (0.0, 1.0, 0.0)


def test_azimuth_minus_90_moves_the_eye_to_the_left():
    orbit = standard()
    orbit.orbit(-90.0, 0.0)
    np.testing.assert_allclose(orbit.camera.eye, (-5.0, 0.0, 0.0), atol=1e-12)


def test_azimuth_is_about_the_up_vector_as_given():
    """Up +z, eye (5,0,0): right = (-1,0,0) x (0,0,1) = +y, so +90 puts the eye at (0,5,0).
    A longer up vector (0,0,3) is the same axis."""
    for up in ((0.0, 0.0, 1.0), (0.0, 0.0, 3.0)):
        orbit = OrbitCamera(Camera(eye=(5.0, 0.0, 0.0), look=(0.0, 0.0, 0.0), up=up))
        orbit.orbit(90.0, 0.0)
        np.testing.assert_allclose(orbit.camera.eye, (0.0, 5.0, 0.0), atol=1e-12)
        assert orbit.camera.up == up


def test_elevation_plus_30_raises_the_eye():
    """From the equator, +30° elevation: eye = 5 (0, sin 30°, cos 30°) = (0, 2.5, 4.330...)."""
    orbit = standard()
    orbit.orbit(0.0, 30.0)
    np.testing.assert_allclose(orbit.camera.eye, (0.0, 2.5, 5 * math.cos(math.radians(30))),
                               atol=1e-12)


def test_elevation_is_about_the_cameras_right_axis_after_an_azimuth():
    """After +90° azimuth the eye is at (5,0,0); +30° elevation lifts it within the x-y plane."""
    orbit = standard()
    orbit.orbit(90.0, 30.0)
    np.testing.assert_allclose(orbit.camera.eye, (5 * math.cos(math.radians(30)), 2.5, 0.0),
                               atol=1e-12)


def test_elevation_stops_one_degree_short_of_either_pole():
    """+120° from the equator would pass over the top: it stops 1° from up, at
    5 (0, cos 1°, sin 1°) (still on the front side); -200° stops 1° from down."""
    orbit = standard()
    orbit.orbit(0.0, 120.0)
    np.testing.assert_allclose(orbit.camera.eye, (0.0, 5 * C1, 5 * S1), atol=1e-12)
    orbit.orbit(0.0, 5.0)                               # pushing further does nothing
    np.testing.assert_allclose(orbit.camera.eye, (0.0, 5 * C1, 5 * S1), atol=1e-12)
    orbit.orbit(0.0, -200.0)
    np.testing.assert_allclose(orbit.camera.eye, (0.0, -5 * C1, 5 * S1), atol=1e-12)


def test_a_camera_on_the_pole_leaves_it_without_turning_the_image():
    """Eye (0,5,0) looking down with up +y: look_at falls back to up +z (image up is +z,
    image right -x). Any orbit first moves the eye 1° towards the image's bottom, to
    5 (0, cos 1°, -sin 1°), where the image right is still -x."""
    orbit = OrbitCamera(Camera(eye=(0.0, 5.0, 0.0), look=(0.0, 0.0, 0.0), up=(0.0, 1.0, 0.0)))
    before = transforms.look_at_rotation(orbit.camera.eye, orbit.camera.look, orbit.camera.up)
    np.testing.assert_allclose(before[0, :3], (-1.0, 0.0, 0.0), atol=1e-12)
    orbit.orbit(0.0, 0.0)
    np.testing.assert_allclose(orbit.camera.eye, (0.0, 5 * C1, -5 * S1), atol=1e-12)
    after = transforms.look_at_rotation(orbit.camera.eye, orbit.camera.look, orbit.camera.up)
    np.testing.assert_allclose(after[0, :3], (-1.0, 0.0, 0.0), atol=1e-12)
    # from there, +90° azimuth about +y carries the eye to the camera's right (-x)
    orbit.orbit(90.0, 0.0)
    np.testing.assert_allclose(orbit.camera.eye, (-5 * S1, 5 * C1, 0.0), atol=1e-12)


def test_a_zero_up_vector_orbits_about_look_ats_fallback():
    """Up (0,0,0): look_at uses fallback_up(forward) = +y for forward -z; so does orbit."""
    orbit = OrbitCamera(Camera(eye=(0.0, 0.0, 5.0), look=(0.0, 0.0, 0.0), up=(0.0, 0.0, 0.0)))
    orbit.orbit(90.0, 0.0)
    np.testing.assert_allclose(orbit.camera.eye, (5.0, 0.0, 0.0), atol=1e-12)


def test_orbit_keeps_the_distance_and_the_up_vector():
    rng = np.random.default_rng(1)
    orbit = OrbitCamera(Camera(eye=(1.0, 2.0, 7.0), look=(0.5, -0.25, 1.0), up=(0.1, 1.0, 0.2)))
    start = distance(orbit.camera)
    for d_az, d_el in rng.uniform(-200, 200, size=(200, 2)):
        orbit.orbit(d_az, d_el)
        assert distance(orbit.camera) == pytest.approx(start, rel=1e-12)
    assert orbit.camera.up == (0.1, 1.0, 0.2)
    assert orbit.camera.look == (0.5, -0.25, 1.0)


def test_a_full_turn_comes_back():
    """360° at once, or as 36 steps of 10°, returns to the start (sphere.toml's camera)."""
    camera = load_scene(builtin.resolve_scene("sphere")).camera
    for steps, angle in ((1, 360.0), (36, 10.0)):
        orbit = OrbitCamera(camera)
        for _ in range(steps):
            orbit.orbit(angle, 0.0)
        np.testing.assert_allclose(orbit.camera.eye, camera.eye, atol=1e-9)


def test_orbit_far_from_the_origin_keeps_its_precision():
    """Look at (1e6, 1e6, 1e6), eye 5 units in front: the math is on eye - look, so +90° is
    look + (5, 0, 0) to float64's spacing at 1e6 (1.2e-10), not a float32-sized error."""
    look = (1e6, 1e6, 1e6)
    orbit = OrbitCamera(Camera(eye=(1e6, 1e6, 1e6 + 5.0), look=look, reversed_z=True))
    orbit.orbit(90.0, 0.0)
    np.testing.assert_allclose(np.subtract(orbit.camera.eye, look), (5.0, 0.0, 0.0), atol=1e-9)
    for _ in range(100):
        orbit.orbit(7.0, 3.0)
        assert distance(orbit.camera) == pytest.approx(5.0, rel=1e-9)
    assert orbit.camera.look == look


def test_orbit_leaves_the_callers_camera_alone():
    camera = Camera()
    orbit = OrbitCamera(camera)
    orbit.orbit(45.0, 10.0)
    assert camera == Camera()


# --------------------------------------------------------------------------- pan

def test_pan_perspective_moves_eye_and_look_by_the_pixel_size_at_the_look_distance():
    """45° fov, distance 5, 480 px tall: a pixel is u = 2·5·tan 22.5° / 480 units. The
    cursor moved 30 px right and 20 px up (dy = -20): the camera moves 30u left, 20u down."""
    orbit = standard()
    orbit.pan(30.0, -20.0, 480)
    u = 2 * 5 * math.tan(math.radians(22.5)) / 480
    np.testing.assert_allclose(orbit.camera.look, (-30 * u, -20 * u, 0.0), atol=1e-15)
    np.testing.assert_allclose(orbit.camera.eye, (-30 * u, -20 * u, 5.0), atol=1e-15)


@pytest.mark.parametrize("reversed_z", [False, True])
def test_pan_perspective_keeps_the_look_point_under_the_cursor(reversed_z):
    """The old look point, seen by the panned camera, sits dx, dy pixels from the centre."""
    camera = Camera(eye=(3.0, 2.0, 6.0), look=(0.5, 0.25, -1.0), up=(0.0, 1.0, 0.0),
                    fov_y=50.0, reversed_z=reversed_z)
    orbit = OrbitCamera(camera)
    orbit.pan(37.0, 12.0, 480)
    np.testing.assert_allclose(window_position(orbit.camera, camera.look, 640, 480),
                               (320 + 37, 240 + 12), atol=1e-9)
    assert distance(orbit.camera) == pytest.approx(distance(camera), rel=1e-12)


def test_pan_parallel_uses_the_view_height():
    """Parallel, height 4 over 400 px: 0.01 units a pixel. Cursor 10 right, 10 down: the
    camera moves 0.1 left and 0.1 up, and the old look point lands under the cursor."""
    camera = Camera(eye=(0.0, 0.0, 5.0), projection="parallel", height=4.0)
    orbit = OrbitCamera(camera)
    orbit.pan(10.0, 10.0, 400)
    np.testing.assert_allclose(orbit.camera.look, (-0.1, 0.1, 0.0), atol=1e-15)
    np.testing.assert_allclose(orbit.camera.eye, (-0.1, 0.1, 5.0), atol=1e-15)
    np.testing.assert_allclose(window_position(orbit.camera, camera.look, 600, 400),
                               (300 + 10, 200 + 10), atol=1e-9)


def test_pan_parallel_tilted_camera_follows_the_cursor():
    camera = load_scene(builtin.resolve_scene("orthographic")).camera
    orbit = OrbitCamera(camera)
    orbit.pan(-25.0, 40.0, 300)
    np.testing.assert_allclose(window_position(orbit.camera, camera.look, 400, 300),
                               (200 - 25, 150 + 40), atol=1e-9)


def test_pan_far_from_the_origin_follows_the_cursor():
    look = (1e6, -2e6, 1e6)
    camera = Camera(eye=(1e6 + 3.0, -2e6 + 1.0, 1e6 + 4.0), look=look, reversed_z=True,
                    near=0.01, far=1e3)
    orbit = OrbitCamera(camera)
    orbit.pan(5.0, -8.0, 480)
    np.testing.assert_allclose(window_position(orbit.camera, look, 640, 480),
                               (320 + 5, 240 - 8), atol=1e-4)


def test_pan_in_a_window_of_no_height_does_nothing():
    orbit = standard()
    orbit.pan(10.0, 10.0, 0)
    assert orbit.camera == standard().camera


# --------------------------------------------------------------------------- zoom

def test_zoom_perspective_scales_the_distance():
    """One step in: 5 · 0.9 = 4.5 along the same line; then two out: 4.5 / 0.81."""
    assert ZOOM_FACTOR == 0.9
    orbit = standard()
    orbit.zoom(1)
    np.testing.assert_allclose(orbit.camera.eye, (0.0, 0.0, 4.5), atol=1e-15)
    orbit.zoom(-2)
    np.testing.assert_allclose(orbit.camera.eye, (0.0, 0.0, 4.5 / 0.81), atol=1e-14)
    orbit.zoom(0.5)                                       # a trackpad's fraction of a step
    np.testing.assert_allclose(orbit.camera.eye, (0.0, 0.0, 4.5 / 0.81 * 0.9 ** 0.5),
                               atol=1e-14)
    assert orbit.camera.look == (0.0, 0.0, 0.0)


def test_zoom_perspective_stops_before_the_clip_planes():
    """near 0.1, far 100: the distance stays within [1.5 · 0.1, 0.9 · 100] = [0.15, 90]."""
    assert (NEAR_MARGIN, FAR_MARGIN) == (1.5, 0.9)
    orbit = standard(near=0.1, far=100.0)
    orbit.zoom(1000)
    np.testing.assert_allclose(orbit.camera.eye, (0.0, 0.0, 0.15), atol=1e-15)
    orbit.zoom(-1000)
    np.testing.assert_allclose(orbit.camera.eye, (0.0, 0.0, 90.0), atol=1e-12)


def test_zoom_from_outside_the_range_only_moves_back_towards_it():
    """A camera authored 200 units away with far 100 stays there zooming out, and zooming
    in moves it one step (180), not to the clamp (90)."""
    orbit = OrbitCamera(Camera(eye=(0.0, 0.0, 200.0), far=100.0))
    orbit.zoom(-1)
    assert orbit.camera.eye == (0.0, 0.0, 200.0)
    orbit.zoom(1)
    np.testing.assert_allclose(orbit.camera.eye, (0.0, 0.0, 180.0), atol=1e-12)


def test_zoom_parallel_scales_the_height_and_keeps_the_eye():
    """Height 2: one step in 1.8; a thousand steps stop at 2 / 1e4, a thousand out at 2e4."""
    orbit = OrbitCamera(Camera(eye=(1.0, 2.0, 3.0), projection="parallel", height=2.0))
    orbit.zoom(1)
    assert orbit.camera.height == pytest.approx(1.8, rel=1e-15)
    assert orbit.camera.eye == (1.0, 2.0, 3.0)
    orbit.zoom(1000)
    assert orbit.camera.height == pytest.approx(2.0 / PARALLEL_ZOOM_RANGE)
    orbit.zoom(-2000)
    assert orbit.camera.height == pytest.approx(2.0 * PARALLEL_ZOOM_RANGE)


def test_zoom_by_nothing_changes_nothing():
    orbit = standard()
    orbit.zoom(0)
    assert orbit.camera == standard().camera


# --------------------------------------------------------------------------- reset

def test_reset_returns_to_the_initial_camera():
    camera = load_scene(builtin.resolve_scene("orthographic")).camera
    orbit = OrbitCamera(camera)
    orbit.orbit(30.0, 20.0)
    orbit.pan(5.0, 5.0, 300)
    orbit.zoom(3)
    assert orbit.camera != camera
    orbit.reset()
    assert orbit.camera == camera
    orbit.camera.height = 99.0                # whoever changes the current camera in place ...
    orbit.reset()
    assert orbit.camera == replace(camera)    # ... does not change what reset returns to
