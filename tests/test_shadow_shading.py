"""Shadows on receivers of every shading mode (docs/conventions.md, "Shadows"): flat and Gouraud
receivers keep the lighting equation's terms apart (the ambient term, each light's term, per
face or per vertex) and the fragment stage weighs each light's term by its visibility at the
fragment, as Phong does (glsl/vertex.glsl, glsl/geometry.glsl, glsl/fragment.glsl and their
twins). Hand-checked on the floor under a sphere (tests/test_shadow_gpu.py's scene), then GPU
against the reference (textured receivers too, their terms in two parts); and the varying
budget that refuses a receiver with too many lights (renderer/core/gl_rules.py,
too_many_varyings)."""

from dataclasses import replace

import numpy as np
import pytest

import reference
from renderer.checks.compare import compare_frames
from renderer.checks.tolerance import PIPELINE_TOLERANCE
from renderer.core.gl_rules import check_light_count, light_term_slots, too_many_varyings
from renderer.core.scene import DirectionalLight, PointLight
from renderer.core.shadow_settings import Shadow
from renderer.core.textures import MaterialTexture, checkerboard
from renderer.errors import SceneError
from renderer.gpu.pipeline import GpuRenderer
from renderer.gpu.shaders import ALL_FEATURES_LIGHTS

from test_shadow_gpu import (FAR_FROM_IT, LIGHT, SPHERE_CENTRE, UNDER_SPHERE, H, W, floor_colour,
                             pixel_of, sphere_over_plane)

POINT_LIGHT = PointLight((0.3, 3.0, 0.2), LIGHT.intensity, shadow=Shadow(resolution=128))


# A texture for textured receivers: 4 x 4 checks of two colours, modulating k_a and k_d.
CHECKS = MaterialTexture(checkerboard(4, ((1.0, 0.9, 0.6), (0.4, 0.5, 0.9)), 16), uv_scale=(0.5, 0.5),
                         modulate=("ka", "kd"))


def shaded(shading: str, two_sided: bool = False, point: bool = False, ball_too: bool = False,
           textured: bool = False):
    """The sphere over the floor, the floor (and the ball: `ball_too`) in `shading`; under
    test_shadow_gpu's directional light, or a point light above the sphere (`point`);
    `textured`: with CHECKS."""
    scene = sphere_over_plane()
    for obj in scene.objects[:2 if ball_too else 1]:
        obj.material = replace(obj.material, shading=shading, two_sided=two_sided,
                               texture=CHECKS if textured else None)
    if point:
        scene.directional_lights, scene.point_lights = [], [POINT_LIGHT]
    return scene


@pytest.mark.parametrize("shading", ["flat", "gouraud"])
@pytest.mark.parametrize("two_sided", [False, True], ids=["one-sided", "two-sided"])
def test_the_floor_under_the_sphere_keeps_only_its_ambient_term(gl_contexts, shading, two_sided):
    """By hand (test_shadow_gpu.floor_colour): I_a k_a under the sphere, I_a k_a + I_l k_d N.L
    far from it; the same from the reference."""
    scene = shaded(shading, two_sided)
    with GpuRenderer(scene, W, H, context=gl_contexts["egl"]) as gpu:
        gpu_image = gpu.render(depth=False).rgba8
        assert {v.shading: v.shadows for v in gpu.programs} == {shading: True, "phong": True}
    reference_image = reference.render(scene, W, H).rgba8
    for image in (gpu_image, reference_image):
        assert image[pixel_of(scene, UNDER_SPHERE)][:3].tolist() == floor_colour(lit=False).tolist()
        assert image[pixel_of(scene, FAR_FROM_IT)][:3].tolist() == floor_colour(lit=True).tolist()


@pytest.mark.parametrize("shading", ["flat", "gouraud"])
def test_under_a_point_light_too(gl_contexts, shading):
    position = np.array(POINT_LIGHT.position)
    under = position + 1.5 * (SPHERE_CENTRE - position)                 # y = 0 on that ray
    scene = shaded(shading, point=True)
    with GpuRenderer(scene, W, H, context=gl_contexts["egl"]) as gpu:
        image = gpu.render(depth=False).rgba8
    assert image[pixel_of(scene, under)][:3].tolist() == floor_colour(lit=False).tolist()
    unshadowed = shaded(shading, point=True)
    unshadowed.objects[0].receives_shadows = False
    with GpuRenderer(unshadowed, W, H, context=gl_contexts["egl"]) as gpu:
        lit = gpu.render(depth=False).rgba8
    assert lit[pixel_of(scene, under)][:3].tolist() != floor_colour(lit=False).tolist()
    # Away from the shadow the split terms add up to what the unsplit lighting gives.
    far = pixel_of(scene, FAR_FROM_IT)
    assert np.abs(image[far].astype(int) - lit[far]).max() <= 1


def _cases():
    """Each mode, one- and two-sided, on both contexts, directional and point; the default
    run keeps the directional light on EGL and one point-light case."""
    cases = []
    for shading in ("flat", "gouraud", "phong"):
        for two_sided in (False, True):
            for kind in ("egl", "osmesa"):
                for point in (False, True):
                    fast = kind == "egl" and (not point or (shading == "gouraud" and not two_sided))
                    cases.append(pytest.param(shading, two_sided, kind, point,
                                              marks=[] if fast else [pytest.mark.slow],
                                              id=f"{shading}-{'two' if two_sided else 'one'}-sided-"
                                                 f"{kind}-{'point' if point else 'directional'}"))
    return cases


@pytest.mark.parametrize("shading, two_sided, context_kind, point", _cases())
def test_gpu_matches_reference(gl_contexts, shading, two_sided, context_kind, point):
    """The ball in the mode too: Gouraud's terms interpolated over a curved receiver, its lit
    side next to its own shadowed side (where the term is 0 no lookup is made)."""
    scene = shaded(shading, two_sided, point, ball_too=True)
    with GpuRenderer(scene, W, H, context=gl_contexts[context_kind]) as gpu:
        frame = gpu.render(depth=True)
    expected = reference.render(scene, W, H, subpixel_bits=gpu.subpixel_bits)
    result = compare_frames(frame.rgba8, expected.rgba8, frame.depth, expected.depth,
                            reference_tie=expected.rgba8_tie)
    assert PIPELINE_TOLERANCE.passes(result), (PIPELINE_TOLERANCE.failures(result), result.as_dict())
    # The shadow is in the picture: the floor shows its ambient-only colour somewhere.
    assert (frame.rgba8[..., :3] == floor_colour(lit=False)).all(axis=-1).any()


@pytest.mark.parametrize("shading, two_sided, point", [
    pytest.param("gouraud", False, False, id="gouraud-one-sided-directional"),
    pytest.param("flat", True, False, id="flat-two-sided-directional", marks=pytest.mark.slow),
    pytest.param("gouraud", True, True, id="gouraud-two-sided-point", marks=pytest.mark.slow),
    pytest.param("phong", False, True, id="phong-one-sided-point", marks=pytest.mark.slow)])
def test_textured_receivers_match_the_reference(gl_contexts, shading, two_sided, point):
    """Textured floor and ball: each light's term in two parts (the texture's coefficients and
    the others), added up at the fragment's texel before its visibility weighs it."""
    scene = shaded(shading, two_sided, point, ball_too=True, textured=True)
    with GpuRenderer(scene, W, H, context=gl_contexts["egl"]) as gpu:
        frame = gpu.render(depth=True)
        assert all(variant.texture and variant.shadows for variant in gpu.programs)
    expected = reference.render(scene, W, H, subpixel_bits=gpu.subpixel_bits)
    result = compare_frames(frame.rgba8, expected.rgba8, frame.depth, expected.depth,
                            reference_tie=expected.rgba8_tie)
    assert PIPELINE_TOLERANCE.passes(result), (PIPELINE_TOLERANCE.failures(result), result.as_dict())


# -- the varying budget -------------------------------------------------------------------------

def test_the_varying_budget_by_hand():
    """(1 + lights) terms a side, and position and normal: Gouraud within GL's 16 vertex output
    slots, flat within 32 fragment input slots; Phong hands on no terms."""
    assert light_term_slots(13, 0, False) == 16 and light_term_slots(3, 3, True) == 16
    assert light_term_slots(7, 0, True) == 18 and light_term_slots(10, 4, True) == 32
    assert too_many_varyings("gouraud", 13, 0, False) is None
    assert too_many_varyings("gouraud", 3, 3, True) is None
    assert too_many_varyings("flat", 10, 4, True) is None
    assert too_many_varyings("phong", 28, 0, True) is None
    message = too_many_varyings("gouraud", 7, 0, True)
    assert message.startswith("too many lights for a two-sided gouraud object that receives shadows: "
                              "with 7 directional and 0 point lights its varyings take 18 vec4 slots")
    assert "the limit is 16 (GL's guaranteed 64 vertex output components)" in message
    assert message.endswith("set `shadows = false` on the lights, `receives_shadows = false` on "
                            "the object, or use phong shading")
    assert "limit is 32 (GL's guaranteed 128 fragment input" in too_many_varyings("flat", 15, 0, True)


def test_the_varying_budget_of_a_textured_receiver_by_hand():
    """Each term in two parts, and the UV: (1 + lights) x sides x 2 + 3 slots."""
    assert light_term_slots(5, 0, False, textured=True) == 15
    assert light_term_slots(2, 0, True, textured=True) == 15
    assert light_term_slots(13, 0, False, textured=True) == 31
    assert light_term_slots(6, 0, True, textured=True) == 31
    assert too_many_varyings("gouraud", 5, 0, False, textured=True) is None
    assert too_many_varyings("flat", 6, 0, True, textured=True) is None
    assert too_many_varyings("gouraud", 6, 0, False) is None          # untextured: 9 slots
    message = too_many_varyings("gouraud", 6, 0, False, textured=True)
    assert message.startswith("too many lights for a textured gouraud object that receives "
                              "shadows: with 6 directional and 0 point lights its varyings take "
                              "17 vec4 slots ((1 + 6) terms x 1 side x 2 parts")
    assert "limit is 32" in too_many_varyings("flat", 7, 0, True, textured=True)


def test_a_receiver_over_the_budget_is_refused_before_drawing(gl_contexts):
    scene = shaded("gouraud", two_sided=True)
    scene.directional_lights = [LIGHT] * 7
    for draw in (lambda: reference.render(scene, 8, 6),
                 lambda: GpuRenderer(scene, 8, 6, context=gl_contexts["egl"])):
        with pytest.raises(SceneError, match="object 'floor': too many lights for a two-sided gouraud"):
            draw()
    # Each of the ways out the message names passes.
    ways_out = [replace(scene), replace(scene), replace(scene)]
    ways_out[0].directional_lights = [replace(LIGHT, shadow=Shadow(enabled=False))] * 7
    ways_out[1].objects = [replace(scene.objects[0], receives_shadows=False), scene.objects[1]]
    ways_out[2].objects = [replace(scene.objects[0], material=replace(scene.objects[0].material,
                                                                        shading="phong")),
                           scene.objects[1]]
    for way_out in ways_out:
        check_light_count(way_out)


@pytest.mark.slow                       # a map per light, 3 programs on 2 contexts
@pytest.mark.parametrize("shading, two_sided, lights, textured", [
    ("gouraud", False, 13, False), ("gouraud", True, 6, False), ("flat", True, 14, False),
    ("gouraud", False, 5, True), ("flat", True, 6, True)])
def test_receivers_at_the_budget_compile_and_render(gl_contexts, shading, two_sided, lights, textured):
    scene = shaded(shading, two_sided, ball_too=True, textured=textured)
    scene.directional_lights = [DirectionalLight((0.1 * i, -1.0, 0.2), (0.05, 0.05, 0.05),
                                                 Shadow(resolution=64)) for i in range(lights)]
    # At the limit (a textured receiver's count is odd: one slot short of it)
    assert light_term_slots(lights, 0, two_sided, textured) == (16 if shading == "gouraud" else 32) - int(textured)
    builds = (True, False) if lights <= ALL_FEATURES_LIGHTS else (True,)      # its arrays' size
    for ctx in gl_contexts.values():
        for specialise in builds:
            with GpuRenderer(scene, 16, 12, context=ctx, specialise=specialise) as gpu:
                assert gpu.render().rgba8[..., 3].any()
                assert all(variant.shadows for variant in gpu.programs)
