"""Motion blur (issue 16; docs/conventions.md, "Motion blur"): objects with a velocity and an
angular velocity, a camera shutter [open, close], each camera sample at its own time.

The rule by hand (reference/raytrace/motion.py: an object's displacement at t, t = 0 exact bit
for bit, the inverse moves a point back, the moved plane; renderer/core/motion.py: each object's
motion from the scene); a moving scene at an instant [t, t] is the still scene posed at t
(spheres, planes, a turning mesh, shadows and reflections; float64 twin); the analytic case, a
blurred edge is a linear ramp over |v| (close - open); the limit, shutter [0, 0] is the still
image bit for bit (the twin, which runs the motion code wherever an object declares a motion,
and the GPU with every feature compiled in); then the GPU against the twin: small frames in the
default run, the built-in motion_blur scene at 320x240, 4 and 16 samples, on EGL and OSMesa in
the full run.
"""

import dataclasses
import math

import numpy as np
import pytest

from reference.raytrace.motion import (motion_at, motion_direction, motion_direction_back,
                                       motion_plane, motion_point, motion_point_back, motion_time)
from reference.raytrace.pipeline import render as reference_raytrace
from reference.raytrace.trace import sample_times
from renderer.checks.compare import compare_frames
from renderer.checks.tolerance import PIPELINE_TOLERANCE
from renderer.core.motion import declares_motion, moves, scene_motion
from renderer.core.ray_sampling import ray_sampling
from renderer.core.raytrace_scene import ray_scene
from renderer.core.scene_file import load_scene, scene_from_dict
from reference.raytrace.sampling import RaySamples

F32 = np.float32


def rows(centre=(0, 0, 0), velocity=(0, 0, 0), angular_velocity=(0, 0, 0), dtype=np.float64):
    """An object's motion rows (c, rate), (v, 0), (axis, 0) (SceneMotion.rows), w in degrees."""
    w = np.asarray(angular_velocity, np.float64)
    rate = float(np.linalg.norm(w))
    out = np.zeros((3, 4))
    out[0, :3], out[0, 3] = centre, math.radians(rate)
    out[1, :3] = velocity
    out[2, :3] = w / rate if rate else 0.0
    return out.astype(dtype)


# --------------------------------------------------------------------------- the rule by hand

def test_a_point_turns_about_the_axis_through_the_centre_and_shifts_with_the_velocity():
    """c = (1, 2, 3), w = 90 degrees per unit time about y, v = (0.5, 0, 0): at t = 1 the point
    c + (1, 0, 0) is at c + (0, 0, -1) + v; at t = 2, c + (-1, 0, 0) + 2v; the axis's own points
    only shift; a direction turns without shifting."""
    m1 = motion_at(rows((1, 2, 3), (0.5, 0, 0), (0, 90, 0)), np.float64(1.0))
    np.testing.assert_allclose(motion_point(m1, np.array([2.0, 2, 3])), [1.5, 2, 2], atol=1e-15)
    np.testing.assert_allclose(motion_point(m1, np.array([1.0, 7, 3])), [1.5, 7, 3], atol=1e-15)
    np.testing.assert_allclose(motion_direction(m1, np.array([0.0, 0, 1])), [1, 0, 0], atol=1e-15)
    m2 = motion_at(rows((1, 2, 3), (0.5, 0, 0), (0, 90, 0)), np.float64(2.0))
    np.testing.assert_allclose(motion_point(m2, np.array([2.0, 2, 3])), [1, 2, 3], atol=1e-15)
    # the moved plane y = 2 (N = (0, 1, 0), d = -2) of an object spinning about x by 90 degrees
    # about c = (0, 2, 0) and rising by 1: x = ... z = 0 through (0, 3, 0), N = (0, 0, 1)
    m = motion_at(rows((0, 2, 0), (0, 1, 0), (90, 0, 0)), np.float64(1.0))
    N, d = motion_plane(m, np.array([0.0, 1, 0]), np.float64(-2.0))
    np.testing.assert_allclose(N, [0, 0, 1], atol=1e-15)
    assert d == pytest.approx(0.0, abs=1e-15)


def test_time_zero_is_exact_bit_for_bit():
    """Every term of the displacement form is 0 at t = 0, so points, directions and planes come
    back bit for bit (float32, as the GLSL), and the shutter [0, 0] gives every sample t = 0."""
    rng = np.random.default_rng(1)
    X = rng.normal(size=(1000, 3)).astype(F32) * F32(100)
    for _ in range(20):
        m = motion_at(rows(rng.normal(size=3) * 50, rng.normal(size=3) * 100,
                           rng.normal(size=3) * 1000, F32), np.zeros(1000, F32))
        for moved in (motion_point(m, X), motion_point_back(m, X), motion_direction(m, X),
                      motion_direction_back(m, X)):
            assert moved.dtype == F32 and np.array_equal(moved, X)
        N, d = motion_plane(m, X, X[:, 0])
        assert np.array_equal(N, X) and np.array_equal(d, X[:, 0])
    u = rng.random(1000).astype(F32)
    assert np.array_equal(motion_time((0.0, 0.0), u), np.zeros(1000, F32))
    assert motion_time((0.25, 1.25), F32(0.0)) == F32(0.25)


def test_the_inverse_moves_a_point_back_and_the_moved_plane_holds_the_moved_points():
    rng = np.random.default_rng(2)
    X = rng.normal(size=(500, 3)) * 10
    t = rng.random(500) * 3
    m = motion_at(rows(rng.normal(size=3), rng.normal(size=3), (30, -70, 45)), t)
    np.testing.assert_allclose(motion_point_back(m, motion_point(m, X)), X, atol=1e-12)
    np.testing.assert_allclose(motion_direction_back(m, motion_direction(m, X)), X, atol=1e-12)
    # rigid at each time: distances between points are kept
    Y = motion_point(motion_at(rows(rng.normal(size=3), rng.normal(size=3), (30, -70, 45)),
                               np.float64(1.7)), X)
    np.testing.assert_allclose(np.linalg.norm(Y[1:] - Y[:-1], axis=-1),
                               np.linalg.norm(X[1:] - X[:-1], axis=-1), rtol=1e-12)
    N = np.array([0.6, 0.0, 0.8])
    on_plane = X - (X @ N + 2.0)[:, None] * N                    # P.N + 2 = 0
    N_t, d_t = motion_plane(m, N, np.full(500, 2.0))
    np.testing.assert_allclose((motion_point(m, on_plane) * N_t).sum(-1) + d_t, 0, atol=1e-12)


def test_each_objects_motion_is_read_from_the_scene():
    """c is the object's world origin relative to the eye, a parent's motion is not its
    child's, the axis is unit and the rate in radians; the motion code runs in the twin wherever
    an object declares a motion, on the GPU where something moves and the shutter is not
    [0, 0]."""
    scene = scene_from_dict({
        "camera": {"eye": [0, 0, 10], "shutter": [0, 2]},
        "objects": [{"name": "a", "mesh": {"primitive": "cube"}, "translate": [1, 2, 3],
                     "velocity": [1, 0, 0], "angular_velocity": [0, 0, 30]},
                    {"name": "b", "mesh": {"primitive": "cube"}, "parent": "a", "translate": [0, 1, 0]},
                    {"name": "c", "mesh": {"primitive": "cube"}, "angular_velocity": [0, 0, 0]}]})
    motion = scene_motion(scene)
    np.testing.assert_allclose(motion.centre, [[1, 2, -7], [1, 3, -7], [0, 0, -10]])
    np.testing.assert_array_equal(motion.velocity, [[1, 0, 0], [0, 0, 0], [0, 0, 0]])
    np.testing.assert_array_equal(motion.axis, [[0, 0, 1], [0, 0, 0], [0, 0, 0]])
    np.testing.assert_allclose(motion.rate, [math.pi / 6, 0, 0])
    assert motion.shutter == (0.0, 2.0)
    assert declares_motion(scene) and moves(scene)
    camera = scene.camera
    for shutter, expected in (((0.0, 0.0), False), ((0.5, 0.5), True), ((-1.0, 0.0), True)):
        scene.camera = dataclasses.replace(camera, shutter=shutter)
        assert moves(scene) == expected, shutter
    scene.objects[0].velocity = scene.objects[0].angular_velocity = None
    assert declares_motion(scene) and not moves(scene)           # c's zero angular velocity
    # each moving mesh object gets its own tree after the static triangles' tree
    rs = ray_scene(scene)
    assert rs.mesh_object.tolist() == [-1, 2] and len(rs.mesh_roots) == 2
    assert ray_scene(scene, motion=False).mesh_object.tolist() == [-1]


def test_a_pixels_sample_times_fill_the_shutter_stratified():
    """The N samples of a pixel (jittered) take one time in each of N strata of [open, close),
    in a shuffled order (decorrelated from the pixel positions)."""
    scene = scene_from_dict({"camera": {"shutter": [1.0, 3.0]},
                             "objects": [{"mesh": {"primitive": "cube"}, "velocity": [1, 0, 0]}]})
    rs = ray_scene(scene)
    n = 16
    samples = RaySamples(np.full(n, 5, np.uint32), np.full(n, 7, np.uint32), np.arange(n), 0,
                         ray_sampling("jittered", n))
    times = sample_times(rs, samples, n, np.float64)
    strata = np.floor((times - 1.0) / 2.0 * n).astype(int)
    assert sorted(strata) == list(range(n)) and strata.tolist() != list(range(n))


# --------------------------------------------------------------------------- whole images

MATERIALS = {"floor": {"ka": [0.5, 0.5, 0.45], "kd": [0.6, 0.6, 0.55]},
             "red": {"ka": [0.8, 0.15, 0.1], "kd": [0.75, 0.12, 0.08], "ks": [0.6, 0.6, 0.6], "n": 40.0},
             "blue": {"ka": [0.15, 0.25, 0.8], "kd": [0.15, 0.25, 0.8]},
             "mirror": {"ka": [0.05, 0.05, 0.05], "kd": [0.05, 0.05, 0.05], "kr": [0.85, 0.85, 0.85]}}
LIGHTS = [{"type": "directional", "direction": [0.5, -1.0, -0.4]},
          {"type": "point", "position": [3.0, 3.0, 3.0], "intensity": [0.4, 0.35, 0.3]}]


def posed_scene(t, moving):
    """A floor plane, a ball whose sphere lies off its object's origin, a cube and a mirror ball
    under two lights; `moving`: the floor rises, the ball flies and circles its origin and the
    cube spins, seen at the instant shutter [t, t]; else the still scene posed where those
    motions put them at t (Euler angles about y compose by adding; an angular velocity turns by
    the right-hand rule, the notes' y rotation the other way: rotate = -w t)."""
    v_floor, v_ball, w_ball, w_cube = 0.1, 1.2, 40.0, 60.0
    at = 0.0 if moving else t
    floor = {"name": "floor", "shape": {"type": "plane", "normal": [0, 1, 0]}, "material": "floor",
             "translate": [0, v_floor * at, 0]}
    ball = {"name": "ball", "shape": {"type": "sphere", "centre": [0.3, 0, 0], "radius": 0.45},
            "material": "red", "translate": [-2.3 + v_ball * at, 0.9, 0.6], "rotate": [0, -w_ball * at, 0]}
    cube = {"name": "cube", "mesh": {"primitive": "cube"}, "material": "blue",
            "translate": [1.3, 0.5, 0.2], "rotate": [0, 20 - w_cube * at, 0]}
    mirror = {"name": "mirror", "shape": {"type": "sphere", "centre": [0, 1, -1.6]}, "material": "mirror"}
    camera = {"eye": [0, 1.8, 5.5], "look": [0, 0.6, 0], "fov_y": 45.0}
    if moving:
        floor["velocity"], ball["velocity"], ball["angular_velocity"] = [0, v_floor, 0], [v_ball, 0, 0], [0, w_ball, 0]
        cube["angular_velocity"] = [0, w_cube, 0]
        camera["shutter"] = [t, t]
    return scene_from_dict({"background": [0.35, 0.45, 0.6], "camera": camera, "materials": MATERIALS,
                            "lights": LIGHTS, "objects": [floor, ball, cube, mirror]})


def test_a_moving_scene_at_an_instant_is_the_still_scene_posed_then():
    """Shutter [t, t]: every sample at time t (float64 twin): the floor, the ball (off its axis:
    it circles), the cube's turned faces and normals, the shadows on the floor and the mirror's
    reflections are where the still scene posed at t has them."""
    for t in (0.7, -1.3):
        moving = reference_raytrace(posed_scene(t, True), 64, 48, dtype=np.float64)
        still = reference_raytrace(posed_scene(t, False), 64, 48, dtype=np.float64)
        differing = (moving.rgba8 != still.rgba8).any(-1)
        assert differing.sum() <= 2, t                           # grazing rays may flip
        np.testing.assert_allclose(moving.linear[~differing], still.linear[~differing], atol=1e-9)
    assert not np.array_equal(moving.rgba8, reference_raytrace(posed_scene(0.0, False), 64, 48,
                                                               dtype=np.float64).rgba8)


def ramp_scene(pattern_shutter=(0.2, 1.2), speed=5.0, start=-4.0):
    """A white slab (ambient only, no lights) on black whose right edge, at x = start at time
    0, moves right at `speed`; a parallel camera sees x from -4 to 4 across 64 x 2 pixels."""
    return scene_from_dict({
        "ambient": [1, 1, 1],
        "camera": {"eye": [0, 0, 5], "look": [0, 0, 0], "projection": "parallel", "height": 0.25,
                   "shutter": list(pattern_shutter)},
        "objects": [{"mesh": {"primitive": "cube", "size": 1.0}, "scale": [10, 4, 0.2],
                     "translate": [start - 5, 0, 0], "velocity": [speed, 0, 0],
                     "material": {"ka": [1, 1, 1], "kd": [0, 0, 0]}}]})


def test_a_blurred_edge_is_a_linear_ramp_over_the_distance_it_moves():
    """The edge at x = -4 + 5t, the shutter [0.2, 1.2]: a point x is covered for the part of the
    shutter after t = (x + 4)/5, so the image falls linearly from 1 at x = -3 to 0 at x = 2,
    over |v| (close - open) = 5 units (40 pixels). Float64 twin, 256 jittered samples (the
    times in 256 strata, the pixel positions in 16 x 16): every pixel within 0.02 of the ramp
    (measured 0.0125, the one sample straddling the edge's time and the pixel's width); a line
    fitted inside it has slope -1/5 per unit within 1 % and meets 1 and 0 within 0.02 units of
    -3 and 2."""
    frame = reference_raytrace(ramp_scene(), 64, 2, samples=256, pattern="jittered", dtype=np.float64)
    x = (np.arange(64) + 0.5) / 8 - 4
    value = frame.linear[..., 0].astype(np.float64)
    expected = np.clip((2.0 - x) / 5.0, 0.0, 1.0)
    assert np.abs(value - expected).max() <= 0.02
    inside = (x > -2.8) & (x < 1.8)
    slope, intercept = np.polyfit(np.tile(x[inside], 2), value[:, inside].reshape(-1), 1)
    assert slope == pytest.approx(-0.2, rel=0.01)
    assert (1 - intercept) / slope == pytest.approx(-3.0, abs=0.02)
    assert -intercept / slope == pytest.approx(2.0, abs=0.02)


# --------------------------------------------------------------------------- the limit

def test_shutter_zero_is_the_still_image_bit_for_bit(gl_contexts):
    """Velocities declared, shutter [0, 0]: the twin (which then runs the motion code: moved
    spheres and planes, the cube in its own tree traced in its time-0 frame) and the GPU with
    every feature compiled in (MOTION too) draw the plain tracer's image of the scene without
    the velocities, bit for bit (rgba8, linear, depth)."""
    from renderer.gpu.raytracer import RayTracer
    moving, still = posed_scene(0.0, True), posed_scene(0.0, False)
    assert declares_motion(moving) and not moves(moving) and ray_scene(moving).motion is not None
    options = dict(samples=4, pattern="jittered")
    plain = reference_raytrace(still, 48, 36, **options)
    twin = reference_raytrace(moving, 48, 36, **options)
    ctx = gl_contexts["egl"]
    with RayTracer(still, 48, 36, context=ctx, **options) as tracer:
        gpu_plain = tracer.render()
    with RayTracer(moving, 48, 36, context=ctx, specialise=False, **options) as tracer:
        assert tracer.defines["MOTION"] and tracer.defines["NUM_MOVING_MESHES"] == 1
        gpu = tracer.render()
    for a, b in ((twin, plain), (gpu, gpu_plain)):
        for name in ("rgba8", "linear", "depth"):
            assert np.array_equal(getattr(a, name), getattr(b, name)), name


# --------------------------------------------------------------------------- GPU against twin

def assert_within_tolerance(frame, reference):
    result = compare_frames(frame.rgba8, reference.rgba8, frame.depth, reference.depth,
                            PIPELINE_TOLERANCE.threshold, PIPELINE_TOLERANCE.deviation)
    assert PIPELINE_TOLERANCE.passes(result), (PIPELINE_TOLERANCE.failures(result), result.as_dict())


@pytest.mark.parametrize("name", ["motion_blur", "ramp"])
def test_the_gpu_traces_the_twins_motion_small(name, gl_contexts):
    """The built-in motion_blur scene (a flying ball, a spinning cube in its own tree, a mirror)
    and the ramp (a moving mesh and no static triangles: the GPU's placeholder tree at root 0),
    4 jittered samples (each its own time), EGL."""
    from renderer.gpu.raytracer import RayTracer
    scene = load_scene("motion_blur") if name == "motion_blur" else ramp_scene()
    size = (48, 36) if name == "motion_blur" else (64, 2)
    reference = reference_raytrace(scene, *size, samples=4, pattern="jittered")
    with RayTracer(scene, *size, context=gl_contexts["egl"], samples=4, pattern="jittered") as tracer:
        assert tracer.defines["MOTION"] and tracer.defines["NUM_MOVING_MESHES"] == 1
        frame = tracer.render()
    assert_within_tolerance(frame, reference)


def test_a_moving_scenes_tracer_follows_a_new_eye(gl_contexts):
    """RayTracer.update (the viewer's orbit): the forest of trees refitted, the centres of the
    motions relative to the new eye, the frame bit for bit a new tracer's; switching the motion
    on or off needs a new tracer."""
    from renderer.gpu.raytracer import RayTracer
    scene = load_scene("motion_blur")
    options = dict(context=gl_contexts["egl"], samples=4, pattern="jittered")
    with RayTracer(scene, 48, 36, **options) as tracer:
        scene.camera = dataclasses.replace(scene.camera, eye=(0.5, 2.0, 5.0))
        tracer.update()
        moved = tracer.render()
        with RayTracer(scene, 48, 36, **options) as fresh:
            expected = fresh.render()
        assert moved.linear.tobytes() == expected.linear.tobytes()
        assert np.array_equal(moved.rgba8, expected.rgba8)
        scene.camera = dataclasses.replace(scene.camera, shutter=(0.0, 0.0))
        with pytest.raises(ValueError, match="motion blur switched"):
            tracer.update()


@pytest.fixture(scope="module")
def motion_blur_references():
    """The twin's motion_blur frames at 320x240, 4 and 16 jittered samples, made once."""
    scene = load_scene("motion_blur")
    return scene, {n: reference_raytrace(scene, 320, 240, samples=n, pattern="jittered") for n in (4, 16)}


@pytest.mark.slow
@pytest.mark.parametrize("context_kind", ("egl", "osmesa"))
@pytest.mark.parametrize("samples", (4, 16))
def test_the_gpu_traces_the_twins_motion_blur_scene(samples, context_kind, gl_contexts,
                                                    motion_blur_references):
    """Issue 16's rule: 0 mismatched pixels after the +-1 px allowance, 320x240."""
    from renderer.gpu.raytracer import RayTracer
    scene, references = motion_blur_references
    with RayTracer(scene, 320, 240, context=gl_contexts[context_kind], samples=samples,
                   pattern="jittered") as tracer:
        frame = tracer.render()
    assert frame.gl_info["context"] == context_kind
    assert_within_tolerance(frame, references[samples])
