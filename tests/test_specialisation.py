"""Leaving out what a scene does not need: shader variants specialised to each material,
frustum culling of whole objects, and the all-features build they are measured against.

The rule: each program has only what its material and scene use (the scene's lights as
compile-time counts, the specular term only where some k_s > 0, back-face code only for a
two-sided material, the shading mode's own stages); an object wholly outside the view
volume is not drawn, by the GPU path nor by the reference; none of this changes a pixel.
"""

import functools

import numpy as np
import pytest

import reference
import reference.pipeline
from renderer.core.builtin import builtin_scenes
from renderer.checks.compare import compare_frames
from renderer.gpu.context import activate
from renderer.gpu import GpuRenderer
from renderer.core.primitives import cube
from renderer.core.scene import Camera, DirectionalLight, Material, PointLight, Scene, SceneObject, Transform
from renderer.core.scene_file import load_scene
from renderer.gpu.shaders import ALL_FEATURES_LIGHTS, ProgramCache, ShaderVariant, program_sources
from renderer.core.visibility import outside_view_volume, visible_objects

from conftest import raster_scene_params

SIZE = (96, 72)


@functools.lru_cache(maxsize=None)
def scene_named(name):
    return load_scene(builtin_scenes()[name])


def defines_of(variant):
    """The #defines renderer/gpu/shaders.py put after the #version line of the variant's
    fragment shader (they end where the author's text resumes, at a #line directive)."""
    lines = program_sources(variant)["fragment_shader"].text.splitlines()
    start = next(i for i, line in enumerate(lines) if line.startswith("#version")) + 1
    defines = {}
    for line in lines[start:]:
        if line.startswith("#line"):
            return defines
        _, name, *value = line.split()
        defines[name] = value[0] if value else True
    raise AssertionError("no #line after the defines")


# --- the generated source, scene by scene -------------------------------------------------

@pytest.mark.parametrize("name", ["sphere", "flat_shading", "open_mesh_inside", "hierarchy",
                                  "near_plane", "point_light_plane"])
def test_each_material_gets_only_what_it_uses(name):
    scene = scene_named(name)
    modes = set()
    for obj in scene.objects:
        material = obj.material
        defines = defines_of(ShaderVariant.for_material(scene, material))
        modes |= {key for key in defines if key.startswith("SHADING_")}
        assert defines.get("SPECULAR", False) == any(k > 0 for k in material.ks), obj.name
        assert defines.get("TWO_SIDED", False) == material.two_sided, obj.name
        assert defines["NUM_DIRECTIONAL_LIGHTS"] == str(len(scene.directional_lights))
        assert defines["NUM_POINT_LIGHTS"] == str(len(scene.point_lights))
        assert "ALL_FEATURES" not in defines
    assert modes == {f"SHADING_{mode.upper()}" for mode in scene.shading_modes()}


def test_the_compiler_sees_no_specular_code_without_specular(gl_contexts):
    """Without SPECULAR the program has no k_s, n or eye uniform at all: the code that would
    read them is not there (with it, the same material's program has all three)."""
    ctx = gl_contexts["egl"]
    activate(ctx)
    cache = ProgramCache(ctx)
    try:
        for shading in ("flat", "gouraud", "phong"):
            matte = cache.get(ShaderVariant(shading, num_directional_lights=1, specular=False))
            glossy = cache.get(ShaderVariant(shading, num_directional_lights=1, specular=True))
            for uniform in ("u_ks", "u_n", "u_eye"):
                assert matte.get(uniform, None) is None, (shading, uniform)
                assert glossy.get(uniform, None) is not None, (shading, uniform)
    finally:
        cache.release()


def test_a_scene_without_lights_of_a_kind_has_no_array_for_them(gl_contexts):
    ctx = gl_contexts["egl"]
    activate(ctx)
    cache = ProgramCache(ctx)
    try:
        only_point = cache.get(ShaderVariant("phong", num_point_lights=2))
        assert only_point.get("u_directional_direction", None) is None
        assert only_point["u_point_position"].array_length == 2
        assert only_point.get("u_two_sided", None) is None
        general = cache.get(ShaderVariant("phong", all_features=True))
        assert general["u_point_position"].array_length == ALL_FEATURES_LIGHTS
        assert general["u_directional_direction"].array_length == ALL_FEATURES_LIGHTS
        for uniform in ("u_num_point_lights", "u_two_sided", "u_ks"):
            assert general.get(uniform, None) is not None, uniform
    finally:
        cache.release()


def test_variant_names_say_what_is_compiled_in():
    assert ShaderVariant("phong", True, 1, 2, specular=True).name == "phong-two-sided-specular-1dir-2point"
    assert ShaderVariant("gouraud", False, 1, 0).name == "gouraud-1dir-0point"
    assert ShaderVariant("flat", all_features=True, linear_output=True).name == "flat-all-features-linear"


def test_material_specular_is_any_nonzero_ks():
    assert not Material(ks=(0.0, 0.0, 0.0)).has_specular
    assert Material(ks=(0.0, 0.2, 0.0)).has_specular


# --- the all-features build draws the same pixels -----------------------------------------

@pytest.mark.parametrize("name", raster_scene_params(sorted(builtin_scenes())))
def test_all_features_build_gives_identical_images(name, gl_contexts):
    scene = scene_named(name)
    ctx = gl_contexts["egl"]
    with GpuRenderer(scene, *SIZE, context=ctx) as specialised, \
            GpuRenderer(scene, *SIZE, context=ctx, specialise=False) as general:
        a, b = specialised.render(linear=True), general.render(linear=True)
        assert all(v.all_features for v in general.programs)
        assert not any(v.all_features for v in specialised.programs)
        # Texture code (a sampler, UVs) only in the programs of textured materials, in both, and
        # of displaced objects (their height image, read at their UVs by the evaluation stage).
        textured = {obj.material.texture is not None for obj in scene.objects}
        for gpu in (specialised, general):
            assert {bool(v.texture) for v in gpu.programs} == textured
            for variant, program in gpu.programs.items():
                displaced = bool(variant.tessellation) and variant.surface == "displaced"
                assert ("u_texture" in program) == bool(variant.texture)
                assert ("u_height" in program) == displaced
                assert ("in_uv" in program) == (bool(variant.texture) or displaced)
    np.testing.assert_array_equal(a.rgba8, b.rgba8)
    np.testing.assert_array_equal(a.depth, b.depth)


def test_all_features_build_refuses_more_lights_than_it_has_room_for(gl_contexts):
    scene = Scene(objects=[SceneObject("box", cube())],
                  point_lights=[PointLight() for _ in range(ALL_FEATURES_LIGHTS + 1)])
    with pytest.raises(ValueError, match="room for"):
        GpuRenderer(scene, *SIZE, context=gl_contexts["egl"], specialise=False)


# --- frustum culling ----------------------------------------------------------------------

def box_scene(*translations, camera=None) -> Scene:
    """Unit-edge cubes at the given places, seen by a camera at z = 5 looking down -z."""
    return Scene(camera=camera or Camera(eye=(0, 0, 5), look=(0, 0, 0), near=1.0, far=20.0),
                 objects=[SceneObject(f"box{i}", cube(1.0), Material(ks=(0.3, 0.3, 0.3)),
                                      Transform(translate=t)) for i, t in enumerate(translations)],
                 directional_lights=[DirectionalLight(direction=(-1, -1, -1))])


@pytest.mark.parametrize("where, visible", [
    ((0, 0, 0), True),            # in the middle of the view
    ((20, 0, 0), False),          # far to the right (about 2 units fit at z = 0)
    ((0, -20, 0), False),         # far below
    ((0, 0, 10), False),          # behind the eye: every corner has w < 0
    ((0, 0, -30), False),         # beyond the far plane
    ((0, 0, 4.2), True),          # straddles the near plane (z_eye from -1.3 to -0.3)
    ((2.7, 0, 0), True),          # only its left face's edge reaches into the view
    ((0, 0, 5), False),           # around the eye, but all of it nearer than the near plane
])
def test_an_object_is_culled_only_when_wholly_outside(where, visible):
    scene = box_scene(where)
    assert visible_objects(scene, scene.matrices(*SIZE)) == [visible]


def test_parallel_projection_culls_by_its_box():
    camera = Camera(eye=(0, 0, 5), look=(0, 0, 0), projection="parallel", height=2.0, near=-1.0, far=10.0)
    scene = box_scene((0, 0, 0), (0, 3, 0), (0, 0, 5.4), camera=camera)
    # the third box is behind the eye but within the negative near distance: visible
    assert visible_objects(scene, scene.matrices(*SIZE)) == [True, False, True]


def test_an_empty_mesh_is_never_drawn():
    empty = cube()
    empty.faces = empty.faces[:0]
    assert outside_view_volume(np.eye(4), empty)


def test_both_pipelines_skip_the_same_objects_and_draw_the_same_image(gl_contexts, monkeypatch):
    scene = box_scene((0, 0, 0), (20, 0, 0), (0, 0, 10), (1.0, 0.6, -1.0))
    with GpuRenderer(scene, *SIZE, context=gl_contexts["egl"]) as gpu, \
            GpuRenderer(scene, *SIZE, context=gl_contexts["egl"], specialise=False) as general:
        assert gpu.drawn_objects == ["box0", "box3"]
        assert general.drawn_objects == ["box0", "box1", "box2", "box3"]
        frame, everything = gpu.render(), general.render()
        subpixel_bits = gpu.subpixel_bits
    np.testing.assert_array_equal(frame.rgba8, everything.rgba8)

    drawn = []
    original = reference.pipeline.prepare_object
    monkeypatch.setattr(reference.pipeline, "prepare_object",
                        lambda obj, *rest, **named: drawn.append(obj.name) or original(obj, *rest, **named))
    expected = reference.render(scene, *SIZE, subpixel_bits=subpixel_bits)
    assert drawn == ["box0", "box3"]
    result = compare_frames(frame.rgba8, expected.rgba8, frame.depth, expected.depth,
                            reference_tie=expected.rgba8_tie)
    assert result.mismatched_pixels == 0, result.as_dict()


def test_culling_follows_the_camera_after_update(gl_contexts):
    scene = box_scene((0, 0, 0), (20, 0, 0))
    with GpuRenderer(scene, *SIZE, context=gl_contexts["egl"]) as gpu:
        assert gpu.drawn_objects == ["box0"]
        scene.camera = Camera(eye=(20, 0, 5), look=(20, 0, 0), near=1.0, far=20.0)
        gpu.update()
        assert gpu.drawn_objects == ["box1"]
        assert (gpu.render().rgba8[..., 3] == 255).any()


def test_the_reference_leaves_out_the_specular_term_without_specular(monkeypatch):
    """A matte material never reaches the specular function in the reference either."""
    import reference.lighting as lighting
    calls = []
    original = lighting.specular_term
    monkeypatch.setattr(lighting, "specular_term", lambda *a: calls.append(1) or original(*a))
    matte = box_scene((0, 0, 0))
    matte.objects[0].material = Material(ks=(0.0, 0.0, 0.0))
    reference.render(matte, 16, 12)
    assert calls == []
    reference.render(box_scene((0, 0, 0)), 16, 12)
    assert calls
