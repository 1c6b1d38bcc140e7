"""Shadow maps on the GPU (issue 15 step 1): the depth pass fills a map with the casters'
depth seen from the light, and a Phong receiver keeps only its ambient term where a caster
hides the light. Hand-checked cases on a small scene: a sphere above a plane under a
directional light, maps of 256 texels (renderer/gpu/shadow_maps.py, glsl/shadow/*)."""

from dataclasses import replace

import numpy as np
import pytest

from renderer.core.gl_rules import (COMPONENTS_PER_DIRECTIONAL_SHADOW, COMPONENTS_PER_POINT_SHADOW,
                                    too_many_lights, to_unorm8)
from renderer.core.primitives import icosphere, plane
from renderer.core.scene import (Camera, DirectionalLight, Material, PointLight, Scene, SceneObject,
                                 Transform)
from renderer.core.shadow_settings import FILTERS, Shadow, shared_kernel
from renderer.core.shadows import has_shadow_maps, shadow_layout
from renderer.core.uniforms import SHADOW_UNIFORMS
from renderer.gpu.pipeline import GpuRenderer

W, H = 64, 48
LIGHT = DirectionalLight(direction=(0.3, -1.0, 0.2), intensity=(0.9, 0.8, 0.7),
                         shadow=Shadow(resolution=256))
FLOOR = Material(ka=(0.2, 0.3, 0.4), kd=(0.6, 0.5, 0.4))
AMBIENT = (0.25, 0.25, 0.25)
SPHERE_CENTRE = np.array([0.0, 1.0, 0.0])
UNDER_SPHERE = SPHERE_CENTRE + 1.0 * np.array(LIGHT.direction)      # where its shadow's centre falls
FAR_FROM_IT = np.array([-1.4, 0.0, 1.2])


def sphere_over_plane(light=LIGHT, floor_receives=True, reversed_z=False) -> Scene:
    floor = SceneObject("floor", plane(4.0), FLOOR, receives_shadows=floor_receives)
    ball = SceneObject("ball", icosphere(0.5, 2), Material(), Transform(translate=tuple(SPHERE_CENTRE)))
    return Scene(Camera(eye=(0.0, 4.0, 4.0), reversed_z=reversed_z), [floor, ball],
                 directional_lights=[light], ambient=AMBIENT)


def pixel_of(scene: Scene, point) -> tuple[int, int]:
    """(row from the top, column) of the pixel whose centre is nearest `point`'s image."""
    m = scene.matrices(W, H)
    clip = m.projection @ m.view @ np.append(m.relative(point), 1.0)
    x, y = clip[:2] / clip[3]
    return int((1.0 - y) / 2.0 * H), int((x + 1.0) / 2.0 * W)


def floor_colour(lit: bool) -> np.ndarray:
    """The floor's colour by hand: I_a k_a, plus I_l k_d (N.L) where the light reaches it."""
    colour = np.multiply(AMBIENT, FLOOR.ka)
    if lit:
        L = -np.array(LIGHT.direction) / np.linalg.norm(LIGHT.direction)
        colour = colour + np.multiply(LIGHT.intensity, FLOOR.kd) * L[1]          # N = +y
    return to_unorm8(colour)


@pytest.fixture(scope="module")
def ctx(gl_contexts):
    return gl_contexts["egl"]


def test_the_map_holds_the_planes_depth_seen_from_the_light(ctx):
    scene = sphere_over_plane()
    with GpuRenderer(scene, W, H, context=ctx) as gpu:
        gpu.render(depth=False)
        (shadow_pass,) = gpu.shadow_maps.plan.passes
        layer = gpu.shadow_maps.read_layer("directional", shadow_pass.tile.layer)
    matrices = scene.matrices(W, H)
    C = shadow_pass.clip_from_world
    tile = shadow_pass.tile
    # The map is fitted to where a shadow can fall: the sphere's box across the light (the floor,
    # which can shadow nothing above it, is not drawn). At texel centres near the middle the
    # nearest of the sphere's triangles, by hand: barycentric weights of the centre in each
    # triangle's light-clip (x, y) (an orthographic view: w = 1), z_w = (z_ndc + 1) / 2.
    ball = scene.objects[1]
    model = matrices.objects[1].model
    world = ball.mesh.positions @ model[:3, :3].T + model[:3, 3]
    clip = np.c_[world, np.ones(len(world))] @ C.T
    corners = clip[ball.mesh.faces]                                         # (F, 3, 4)
    for i, j in [(tile.size // 2 + di, tile.size // 2 + dj) for di in (-9, 0, 9) for dj in (-9, 0, 9)]:
        x, y = (np.array([i, j]) + 0.5) / tile.size * 2.0 - 1.0
        (x0, y0), (x1, y1), (x2, y2) = (corners[:, k, :2].T for k in range(3))
        area = (x1 - x0) * (y2 - y0) - (x2 - x0) * (y1 - y0)
        b1 = ((x - x0) * (y2 - y0) - (x2 - x0) * (y - y0)) / area
        b2 = ((x1 - x0) * (y - y0) - (x - x0) * (y1 - y0)) / area
        inside = (b1 >= 0) & (b2 >= 0) & (b1 + b2 <= 1)
        z = (1 - b1 - b2) * corners[:, 0, 2] + b1 * corners[:, 1, 2] + b2 * corners[:, 2, 2]
        expected = np.float32((z[inside].min() + 1.0) / 2.0)
        stored = layer[j, i]
        # llvmpipe evaluates the depth plane in float32 from the window origin: a few units of
        # 2^-24 absolute (float32's spacing just below 1), whatever the depth's own size.
        assert abs(float(stored) - float(expected)) <= 8 * 2.0 ** -24, (i, j, stored, expected)


@pytest.mark.parametrize("reversed_z", [False, True])
def test_the_floor_under_the_sphere_keeps_only_its_ambient_term(ctx, reversed_z):
    with GpuRenderer(sphere_over_plane(reversed_z=reversed_z), W, H, context=ctx) as gpu:
        image = gpu.render(depth=False).rgba8
    scene = sphere_over_plane()
    assert image[pixel_of(scene, UNDER_SPHERE)][:3].tolist() == floor_colour(lit=False).tolist()
    assert image[pixel_of(scene, FAR_FROM_IT)][:3].tolist() == floor_colour(lit=True).tolist()


def test_under_a_point_light_too(ctx):
    """Six cube faces, each a layer of its own; the one looking down holds the sphere. Away
    from its shadow the floor is as lit as with the light's shadows off."""
    position = np.array([0.3, 3.0, 0.2])
    under = position + 1.5 * (SPHERE_CENTRE - position)                 # y = 0 on that ray
    images = {}
    for enabled in (True, False):
        scene = sphere_over_plane()
        scene.directional_lights = []
        scene.point_lights = [PointLight(tuple(position), LIGHT.intensity,
                                         shadow=Shadow(enabled, resolution=256))]
        with GpuRenderer(scene, W, H, context=ctx) as gpu:
            images[enabled] = gpu.render(depth=False).rgba8
            if enabled:
                assert [p.tile.layer for p in gpu.shadow_maps.plan.passes] == [3]    # -y only
    assert images[True][pixel_of(scene, under)][:3].tolist() == floor_colour(lit=False).tolist()
    assert images[False][pixel_of(scene, under)][:3].tolist() != floor_colour(lit=False).tolist()
    far = pixel_of(scene, FAR_FROM_IT)
    assert images[True][far].tolist() == images[False][far].tolist()


@pytest.mark.parametrize("scene, shadowed_programs", [
    (sphere_over_plane(light=replace(LIGHT, shadow=Shadow(enabled=False))), 0),
    (sphere_over_plane(floor_receives=False), 0)], ids=["light-shadows-off", "floor-receives-none"])
def test_without_the_lights_shadow_or_the_floors_the_floor_is_lit_everywhere(ctx, scene,
                                                                             shadowed_programs):
    with GpuRenderer(scene, W, H, context=ctx) as gpu:
        image = gpu.render(depth=False).rgba8
        # No maps at all: with the floor not receiving, the only receiver is the ball, a convex
        # solid lit from outside, which nothing can shadow (renderer/core/shadow_casting.py).
        assert sum(variant.shadows for variant in gpu.programs) == shadowed_programs
    for point in (UNDER_SPHERE, FAR_FROM_IT):
        assert image[pixel_of(scene, point)][:3].tolist() == floor_colour(lit=True).tolist()


def test_a_scene_without_maps_compiles_no_shadow_code(ctx):
    scene = sphere_over_plane()
    assert has_shadow_maps(scene)
    for obj in scene.objects:
        obj.receives_shadows = False
    assert not has_shadow_maps(scene) and not shadow_layout(scene, W, H).any
    for specialise in (True, False):
        with GpuRenderer(scene, W, H, context=ctx, specialise=specialise) as gpu:
            gpu.render(depth=False)
            assert gpu.shadow_maps is None
            assert gpu.programs and not any(v.defines()["SHADOW_MAPS"] for v in gpu.programs)


@pytest.mark.parametrize("filter_name", ["pcf2x2", "hard", "pcf5x5"])
def test_the_all_features_build_looks_the_maps_up_too_and_draws_the_same(ctx, filter_name):
    """The specialised programs have the scene's one filter compiled in (SHADOW_KERNEL: the
    taps' loops have constant bounds); the all-features build reads each light's kernel from
    its uniform. Same pixels."""
    scene = sphere_over_plane(replace(LIGHT, shadow=Shadow(resolution=256, filter=filter_name)))
    images = {}
    for specialise in (True, False):
        with GpuRenderer(scene, W, H, context=ctx, specialise=specialise) as gpu:
            images[specialise] = gpu.render(depth=False).rgba8
            assert [v.shadows for v in gpu.programs] == [True]
            assert [v.defines().get("SHADOW_KERNEL") for v in gpu.programs] == [
                FILTERS[filter_name] if specialise else None]
    assert np.array_equal(images[True], images[False])


def test_a_kernel_is_compiled_in_only_when_every_light_with_shadows_shares_it():
    hard, pcf3 = Shadow(filter="hard"), Shadow(filter="pcf3x3")
    scene = Scene(directional_lights=[DirectionalLight(shadow=pcf3)],
                  point_lights=[PointLight(shadow=pcf3), PointLight(shadow=replace(hard, enabled=False))])
    assert shared_kernel(scene) == 3                   # a light without shadows has no say
    scene.point_lights[1].shadow = hard
    assert shared_kernel(scene) == 0                   # 1 and 3: each light's from its uniform
    assert shared_kernel(Scene(directional_lights=[DirectionalLight(shadow=Shadow(enabled=False))])) == 0


def test_update_keeps_the_maps_texture_programs_and_vertex_arrays(ctx):
    scene = sphere_over_plane()
    with GpuRenderer(scene, W, H, context=ctx) as gpu:
        gpu.render(depth=False)
        made = (gpu.shadow_maps, gpu.shadow_maps.texture("directional"), gpu.shadow_maps.program,
                dict(gpu.programs), gpu.shadow_maps.vertex_arrays)
        scene.directional_lights[0] = replace(LIGHT, direction=(-0.3, -1.0, 0.1))
        gpu.update()
        gpu.render(depth=False)
        again = (gpu.shadow_maps, gpu.shadow_maps.texture("directional"), gpu.shadow_maps.program,
                 dict(gpu.programs), gpu.shadow_maps.vertex_arrays)
    assert all(a is b for a, b in zip(made[:3], again[:3]))
    assert made[3] == again[3] and all(made[3][v] is again[3][v] for v in made[3])
    assert made[4] == again[4]


def test_shadows_off_draws_the_scene_without_shadows_and_on_again_the_same_image(ctx):
    """GpuRenderer.shadows (the viewer's O key): off is the image of the scene whose lights
    have shadows off, with no light view drawn and no shadow code; on again is the first
    image bit for bit; each program is compiled once."""
    scene = sphere_over_plane()
    unshadowed = sphere_over_plane(light=replace(LIGHT, shadow=Shadow(enabled=False)))
    with GpuRenderer(unshadowed, W, H, context=ctx) as gpu:
        expected_off = gpu.render(depth=False).rgba8
    with GpuRenderer(scene, W, H, context=ctx) as gpu:
        on = gpu.render(depth=False).rgba8
        assert gpu.shadows and gpu.drawn_shadow_plan is gpu.shadow_maps.plan
        images, programs = [], []
        for setting in (False, True, False, True):
            gpu.shadows = setting
            images.append(gpu.render(depth=False).rgba8)
            programs.append(dict(gpu.programs))
            assert (gpu.drawn_shadow_plan is not None) == setting
    assert not np.array_equal(on, expected_off)                  # the scene has a shadow
    assert np.array_equal(images[0], expected_off) and np.array_equal(images[2], expected_off)
    assert np.array_equal(images[1], on) and np.array_equal(images[3], on)
    assert sorted(v.shadows for v in programs[1]) == [False, True]      # one program each
    assert programs[3].keys() == programs[1].keys()
    assert all(programs[3][v] is program for v, program in programs[1].items())


def test_update_makes_new_maps_in_the_renderers_own_context(gl_contexts):
    """update() may run while another context is current (a viewer's window after a headless
    render): a new layout's texture is made in the renderer's context all the same."""
    from renderer.gpu.context import activate
    scene = sphere_over_plane()
    with GpuRenderer(scene, W, H, context=gl_contexts["egl"]) as gpu:
        gpu.render(depth=False)
        scene.directional_lights[0] = replace(LIGHT, shadow=Shadow(resolution=128))
        activate(gl_contexts["osmesa"])
        gpu.update()                                  # a new texture: 128 texels, not 256
        image = gpu.render(depth=False).rgba8
    with GpuRenderer(scene, W, H, context=gl_contexts["egl"]) as fresh:
        assert np.array_equal(image, fresh.render(depth=False).rgba8)


def test_the_light_budget_counts_the_shadow_uniforms():
    # The per-light arrays; a stack's sampler and size are one each per program, among the
    # OTHER_UNIFORM_COMPONENTS.
    sizes = {"vec4[]": 4, "mat4[]": 16}
    per_light = {kind: sum(sizes[t] * (6 if name.endswith("_tiles") else 1)
                           for name, t in SHADOW_UNIFORMS.items()
                           if name.startswith(f"u_{kind}_") and t.endswith("[]"))
                 for kind in ("directional", "point")}
    assert per_light == {"directional": COMPONENTS_PER_DIRECTIONAL_SHADOW,
                         "point": COMPONENTS_PER_POINT_SHADOW} == {"directional": 24, "point": 36}
    assert too_many_lights(28, 0, 28, 0) is None and too_many_lights(0, 18, 0, 18) is None
    message = too_many_lights(29, 0, 29, 0)
    assert "928 uniform components" in message and message.endswith("set `shadows = false` on some lights")
    assert "shadows" not in too_many_lights(113, 0)
