"""RayTracer.update and resize (renderer/gpu/raytracer.py), the viewer's way to follow a moving
camera and its keys without building the BVH again: after each change the tracer made once
gives, bit for bit, the frame of a RayTracer made afresh for the changed scene (the BVH's tree
does not depend on the eye, so its refit is what a new build gives: renderer/core/
raytrace_scene.py). On EGL, at 48 x 36.

The scene is the classic one (planes, spheres, a mirror and a glass sphere, a directional and
a point light) with a torus of triangles added, so that every part of the tracer moves."""

import tomllib
from dataclasses import replace
from pathlib import Path

import pytest

from renderer.core.scene_file import scene_from_dict
from renderer.gpu.raytracer import RayTracer
from renderer.viewer.controls import ViewState, apply_view, working_copy
from renderer.viewer.orbit import OrbitCamera

SIZE = (48, 36)
CLASSIC = Path(__file__).resolve().parent.parent / "assets" / "scenes" / "classic.toml"


def classic_with_a_torus():
    data = tomllib.loads(CLASSIC.read_text())
    data["objects"].append({"name": "torus", "material": "red", "translate": [0.0, 1.8, -1.5],
                            "rotate": [60.0, 0.0, 0.0],
                            "mesh": {"primitive": "torus", "major_radius": 0.6,
                                     "minor_radius": 0.2, "major_segments": 24,
                                     "minor_segments": 12}})
    return scene_from_dict(data)


def fresh(scene, ctx, size=SIZE):
    with RayTracer(replace(scene, objects=list(scene.objects)), *size, context=ctx) as tracer:
        return tracer.render()


def assert_same(frame, expected):
    assert frame.linear.tobytes() == expected.linear.tobytes()
    assert frame.depth.tobytes() == expected.depth.tobytes()
    assert (frame.rgba8 == expected.rgba8).all()


@pytest.fixture
def egl(gl_contexts):
    return gl_contexts["egl"]


def test_update_and_resize_give_the_frame_of_a_new_tracer(egl):
    authored = classic_with_a_torus()
    shown, state = working_copy(authored), ViewState(lights_on=[True, True])
    with RayTracer(shown, *SIZE, context=egl) as tracer:
        first = tracer.render()
        assert len(tracer.ray_scene.triangles) > 0 and len(tracer.ray_scene.sphere_radius) == 3
        orbit = OrbitCamera(authored.camera)
        orbit.orbit(25.0, 10.0)
        orbit.zoom(1.0)
        apply_view(state, authored, shown, orbit.camera)
        tracer.update()
        moved = tracer.render()
        assert (moved.rgba8 != first.rgba8).any(axis=-1).mean() > 0.2
        assert_same(moved, fresh(shown, egl))

        state.lights_on, state.two_sided = [False, True], True     # a new program
        apply_view(state, authored, shown, orbit.camera)
        tracer.update()
        assert tracer.defines["NUM_DIRECTIONAL_LIGHTS"] == 0
        assert_same(tracer.render(), fresh(shown, egl))

        tracer.resize(40, 30)
        assert tracer.render().rgba8.shape == (30, 40, 4)
        assert_same(tracer.render(), fresh(shown, egl, (40, 30)))


def test_update_refuses_other_objects(egl):
    shown = working_copy(classic_with_a_torus())
    with RayTracer(shown, 8, 6, context=egl) as tracer:
        shown.objects = [replace(obj) for obj in shown.objects]
        with pytest.raises(ValueError, match="make a new one"):
            tracer.update()


@pytest.mark.parametrize("pattern", ["random", "poisson"])    # poisson: its table is the seed's
def test_reseed_gives_the_frame_of_a_tracer_made_with_that_seed(egl, pattern):
    scene = classic_with_a_torus()
    options = {"samples": 4, "pattern": pattern, "context": egl}
    with RayTracer(scene, 24, 18, seed=1, **options) as tracer:
        first = tracer.render()
        tracer.reseed(7)
        reseeded = tracer.render()
        with pytest.raises(ValueError, match="the seed must be a whole number"):
            tracer.reseed(-1)
    with RayTracer(scene, 24, 18, seed=7, **options) as fresh_tracer:
        expected = fresh_tracer.render()
    assert (reseeded.linear != first.linear).any()
    assert_same(reseeded, expected)
