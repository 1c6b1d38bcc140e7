"""renderer/gpu/pipeline.py: what a frame holds, where things land in it, and tiny hand-checked oracles."""

import numpy as np
import pytest

from renderer.core.gl_rules import SUBPIXEL_BITS
from renderer.gpu import GpuRenderer
from renderer.core.primitives import icosphere, plane
from renderer.core.scene import (Camera, DirectionalLight, Material, PointLight, Scene, SceneObject,
                            Transform)

W, H = 64, 48
FACING_CAMERA = (90.0, 0.0, 0.0)        # rotate_x(90°) turns the plane's +y normal to +z
FACING_AWAY = (-90.0, 0.0, 0.0)


def unorm8(value: float) -> int:
    """GL's float -> unorm8 conversion (docs/conventions.md)."""
    return int(np.floor(np.clip(value, 0.0, 1.0) * 255 + 0.5))


def sphere_scene(**scene_options) -> Scene:
    return Scene(objects=[SceneObject("sphere", icosphere(subdivisions=3),
                                      Material(ks=(0.5, 0.5, 0.5), shading="phong"))],
                 directional_lights=[DirectionalLight(direction=(-1.0, -1.0, -1.0))],
                 point_lights=[PointLight(position=(2.0, 2.0, 4.0))], **scene_options)


def plane_scene(material=None, rotate=FACING_CAMERA, z=-2.0, cull="none", camera=None, size=4.0,
                **options):
    """A square plane centred on the view axis at world z, lit straight on by a white light."""
    obj = SceneObject("plane", plane(size=size), material or Material(),
                      Transform(rotate=rotate, translate=(0.0, 0.0, z)), cull=cull)
    options.setdefault("directional_lights", [DirectionalLight(direction=(0.0, 0.0, -1.0))])
    return Scene(camera=camera or Camera(eye=(0.0, 0.0, 5.0)), objects=[obj], **options)


@pytest.fixture
def egl(gl_contexts):
    return gl_contexts["egl"]


def render(scene, ctx, **options):
    with GpuRenderer(scene, W, H, context=ctx) as gpu:
        return gpu.render(**options)


@pytest.mark.parametrize("kind", ("egl", "osmesa"))
def test_sphere_frame_shapes_and_types(gl_contexts, kind):
    frame = render(sphere_scene(), gl_contexts[kind], linear=True)
    assert frame.size == (W, H)
    assert frame.rgba8.shape == (H, W, 4) and frame.rgba8.dtype == np.uint8
    assert frame.linear.shape == (H, W, 4) and frame.linear.dtype == np.float32
    assert frame.depth.shape == (H, W) and frame.depth.dtype == np.float32
    assert all(a.flags.c_contiguous for a in (frame.rgba8, frame.linear, frame.depth))
    drawn = frame.rgba8[..., 3] == 255
    assert 0.1 < drawn.mean() < 0.9
    assert set(np.unique(frame.rgba8[..., 3])) == {0, 255}
    assert np.isfinite(frame.depth[drawn]).all() and np.isinf(frame.depth[~drawn]).all()
    assert frame.depth[drawn].min() > 3.9 and frame.depth[drawn].max() < 5.0  # sphere r=1 at 5
    assert frame.milliseconds > 0


def test_outputs_are_only_read_when_asked(egl):
    frame = render(sphere_scene(), egl, depth=False)
    assert frame.linear is None and frame.depth is None


def test_row_zero_is_the_top(egl):
    scene = sphere_scene()
    scene.objects[0].transform = Transform(scale=(0.5, 0.5, 0.5), translate=(0.0, 1.2, 0.0))
    covered_rows = np.flatnonzero((render(scene, egl).rgba8[..., 3] == 255).any(axis=1))
    assert covered_rows.size > 0 and covered_rows.max() < H // 2


def test_background_has_alpha_zero(egl):
    background = (0.2, 0.4, 0.6)
    frame = render(sphere_scene(background=background), egl, linear=True)
    assert tuple(frame.rgba8[0, 0]) == (*map(unorm8, background), 0)
    np.testing.assert_allclose(frame.linear[0, 0], (*background, 0.0), rtol=1e-6)
    assert frame.depth[0, 0] == np.inf


@pytest.mark.parametrize("camera, z", [
    (Camera(eye=(0.0, 0.0, 5.0)), -2.0),                               # 7 units away
    (Camera(eye=(0.0, 0.0, 5.0), near=0.1, far=100.0), -90.0),         # near the far plane
    (Camera(eye=(0.0, 0.0, 5.0), projection="parallel", height=3.0), -2.0),
], ids=("perspective", "perspective-far", "parallel"))
def test_depth_of_a_plane_facing_the_camera_is_its_distance(egl, camera, z):
    frame = render(plane_scene(camera=camera, z=z, size=(5.0 - z) / 2), egl)
    drawn = frame.rgba8[..., 3] == 255
    assert drawn.sum() > 20
    distance = 5.0 - z
    np.testing.assert_allclose(frame.depth[drawn], distance, rtol=1e-4)


def test_depth_precision_is_that_of_float32_window_depth(egl):
    """z_w is stored as a float32 near 1, so one unit in its last place is about
    2^-24 * distance / near of the distance (when far >> near): 2.7e-4 here."""
    camera = Camera(eye=(0.0, 0.0, 5.0), near=0.01, far=1000.0)
    frame = render(plane_scene(camera=camera, z=-40.0, size=22.5), egl)
    drawn = frame.rgba8[..., 3] == 255
    one_ulp = 2.0 ** -24 * 45.0 / 0.01
    np.testing.assert_allclose(frame.depth[drawn], 45.0, rtol=one_ulp)


def test_resources_are_made_once_and_reused(egl):
    with GpuRenderer(sphere_scene(), W, H, context=egl) as gpu:
        first = gpu.render()
        made = (gpu.framebuffer, dict(gpu.programs), list(gpu.vertex_arrays))
        glos = (gpu.framebuffer.glo, sorted(p.glo for p in gpu.programs.values()))
        second = gpu.render()
        assert gpu.framebuffer is made[0]
        assert gpu.programs == made[1] and all(gpu.programs[v] is p for v, p in made[1].items())
        assert len(gpu.vertex_arrays) == len(made[2])
        assert all(a is b for a, b in zip(gpu.vertex_arrays, made[2]))
        assert (gpu.framebuffer.glo, sorted(p.glo for p in gpu.programs.values())) == glos
    np.testing.assert_array_equal(first.rgba8, second.rgba8)
    np.testing.assert_array_equal(first.depth, second.depth)
    assert first.rgba8 is not second.rgba8                      # each frame owns its arrays


@pytest.mark.parametrize("shading", ("flat", "gouraud", "phong"))
def test_each_shading_variant_compiles_and_draws(egl, shading):
    scene = sphere_scene()
    scene.objects[0].material = Material(ks=(0.5, 0.5, 0.5), shading=shading, two_sided=True)
    with GpuRenderer(scene, W, H, context=egl) as gpu:
        frame = gpu.render()
        (variant, program), = gpu.programs.items()
    assert variant.shading == shading and variant.two_sided
    assert bool(program.geometry_vertices) == (shading == "flat")
    assert (frame.rgba8[..., 3] == 255).mean() > 0.1


def test_gouraud_and_phong_differ_on_a_coarse_highlight(egl):
    images = {}
    for shading in ("gouraud", "phong"):
        scene = sphere_scene()
        scene.objects[0].mesh = icosphere(subdivisions=1)
        scene.objects[0].material = Material(ks=(1.0, 1.0, 1.0), n=60.0, shading=shading)
        images[shading] = render(scene, egl).rgba8.astype(int)
    assert np.abs(images["gouraud"] - images["phong"]).max() > 20


@pytest.mark.parametrize("shading", ("flat", "gouraud", "phong"))
def test_plane_lit_head_on_matches_the_lighting_equation(egl, shading):
    # I = I_a k_a + I_l k_d max(N.L, 0) with N = L = +z, and no specular term (k_s = 0).
    material = Material(ka=(0.2, 0.4, 0.6), kd=(0.5, 0.25, 0.125), ks=(0, 0, 0), shading=shading)
    frame = render(plane_scene(material, ambient=(0.1, 0.1, 0.1)), egl)
    expected = [unorm8(0.1 * ka + kd) for ka, kd in zip(material.ka, material.kd)]
    drawn = frame.rgba8[..., 3] == 255
    assert drawn.mean() > 0.3
    assert (np.abs(frame.rgba8[drawn][:, :3].astype(int) - expected) <= 1).all()


@pytest.mark.parametrize("shading", ("flat", "gouraud", "phong"))
def test_a_scene_without_lights_shows_the_ambient_term(egl, shading):
    material = Material(ka=(0.5, 1.0, 3.0), ks=(1, 1, 1), shading=shading, two_sided=True)
    frame = render(plane_scene(material, directional_lights=[], ambient=(0.4, 0.4, 0.4)), egl)
    drawn = frame.rgba8[..., 3] == 255
    assert drawn.mean() > 0.3
    assert (frame.rgba8[drawn][:, :3] == [unorm8(0.2), unorm8(0.4), 255]).all()


def test_point_light_attenuation_on_a_plane(egl):
    # A point light on the view axis 3 units in front of the plane: at the centre pixel
    # d = 3, N.L = 1, att = 1 / (1 + 0.5 d) and I = att k_d.
    scene = plane_scene(Material(ka=(0, 0, 0), kd=(1, 1, 1), ks=(0, 0, 0), shading="phong"),
                        directional_lights=[], ambient=(0, 0, 0),
                        point_lights=[PointLight(position=(0.0, 0.0, 1.0), attenuation=(1.0, 0.5, 0.0))])
    frame = render(scene, egl)
    centre = frame.rgba8[H // 2 - 1:H // 2 + 1, W // 2 - 1:W // 2 + 1, 0].astype(int)
    assert (np.abs(centre - unorm8(1.0 / 2.5)) <= 1).all()


@pytest.mark.parametrize("shading", ("flat", "gouraud", "phong"))
@pytest.mark.parametrize("two_sided", (False, True))
def test_back_face_is_lit_only_when_two_sided(egl, shading, two_sided):
    material = Material(ka=(1, 1, 1), kd=(0.5, 0.5, 0.5), shading=shading, two_sided=two_sided)
    frame = render(plane_scene(material, rotate=FACING_AWAY, ambient=(0.2, 0.2, 0.2)), egl)
    drawn = frame.rgba8[..., 3] == 255
    assert drawn.mean() > 0.3
    expected = unorm8(0.2 + 0.5) if two_sided else unorm8(0.2)   # one-sided: ambient only
    assert (np.abs(frame.rgba8[drawn][:, :3].astype(int) - expected) <= 1).all()


@pytest.mark.parametrize("rotate, cull, visible", [
    (FACING_CAMERA, "back", True), (FACING_CAMERA, "front", False),
    (FACING_AWAY, "back", False), (FACING_AWAY, "front", True), (FACING_AWAY, "none", True),
])
def test_culling_follows_the_object(egl, rotate, cull, visible):
    frame = render(plane_scene(rotate=rotate, cull=cull), egl)
    assert (frame.rgba8[..., 3] == 255).any() == visible


def test_linear_output_is_unclamped(egl):
    material = Material(ka=(3.0, 0.5, 0.0), kd=(0, 0, 0), ks=(0, 0, 0), shading="flat")
    frame = render(plane_scene(material, ambient=(1.0, 1.0, 1.0)), egl, linear=True)
    drawn = frame.rgba8[..., 3] == 255
    assert np.allclose(frame.linear[drawn], [3.0, 0.5, 0.0, 1.0], rtol=1e-6, atol=0)
    assert (frame.rgba8[drawn] == [255, unorm8(0.5), 0, 255]).all()


def test_update_picks_up_a_moved_camera(egl):
    scene = plane_scene()
    with GpuRenderer(scene, W, H, context=egl) as gpu:
        before = gpu.render().depth
        scene.camera.eye = (0.0, 0.0, 9.0)
        assert np.array_equal(gpu.render().depth, before)        # uniforms are precomputed
        gpu.update()
        after = gpu.render().depth
    drawn = np.isfinite(after)
    np.testing.assert_allclose(after[drawn], 11.0, rtol=1e-4)


def test_gl_info_and_subpixel_bits(egl):
    with GpuRenderer(sphere_scene(), W, H, context=egl) as gpu:
        info = gpu.gl_info
        assert info["context"] == "egl" and "llvmpipe" in info["GL_RENDERER"]
        assert info["GL_VERSION"] and info["depth_format"] == "DEPTH_COMPONENT32F"
        assert gpu.subpixel_bits == SUBPIXEL_BITS == 8        # the rule both pipelines read


def test_release_is_idempotent_and_final(egl):
    gpu = GpuRenderer(sphere_scene(), W, H, context=egl)
    gpu.render()
    gpu.release()
    gpu.release()
    with pytest.raises(RuntimeError, match="released"):
        gpu.render()


def test_renderer_made_without_a_context_owns_one():
    with GpuRenderer(sphere_scene(), W, H, context_kind="osmesa") as gpu:
        assert gpu.gl_info["context"] == "osmesa"
        assert (gpu.render().rgba8[..., 3] == 255).any()
    assert gpu.ctx.mglo.__class__.__name__ == "InvalidObject"     # released with the renderer


def test_render_into_an_earlier_frame_reuses_its_arrays(gl_contexts):
    with GpuRenderer(sphere_scene(), 48, 32, context=gl_contexts["egl"]) as gpu:
        first = gpu.render(linear=True)
        kept = first.rgba8.copy(), first.linear.copy(), first.depth.copy()
        second = gpu.render(linear=True, out=first)
        assert second.rgba8 is first.rgba8 and second.linear is first.linear and second.depth is first.depth
        for a, b in zip(kept, (second.rgba8, second.linear, second.depth)):
            assert np.array_equal(a, b)
        third = gpu.render()                                # without out: new arrays
        assert third.rgba8 is not first.rgba8 and np.array_equal(third.rgba8, kept[0])


def test_resize_renders_as_a_renderer_made_at_that_size(egl):
    scene = sphere_scene()
    with GpuRenderer(scene, W, H, context=egl) as gpu:
        gpu.render(samples=4)                        # a multisample target to remake too
        gpu.resize(2 * W, H)                         # another aspect ratio
        resized = gpu.render(linear=True)
        resized_msaa = gpu.render(samples=4)
    with GpuRenderer(scene, 2 * W, H, context=egl) as fresh:
        expected = fresh.render(linear=True)
        expected_msaa = fresh.render(samples=4)
    assert resized.size == (2 * W, H)
    assert np.array_equal(resized.rgba8, expected.rgba8)
    assert np.array_equal(resized.depth, expected.depth)
    assert np.array_equal(resized_msaa.rgba8, expected_msaa.rgba8)


def test_draw_is_render_without_the_read_back(egl):
    with GpuRenderer(sphere_scene(), W, H, context=egl) as gpu:
        fbo = gpu.draw()
        drawn = np.frombuffer(fbo.read(components=4, alignment=1), np.uint8).reshape(H, W, 4)
        assert np.array_equal(drawn[::-1], gpu.render().rgba8)


def test_wireframe_draws_edges_only(egl):
    """A square of two triangles, as edges: its outline and one diagonal, one pixel wide."""
    with GpuRenderer(plane_scene(size=2.0, z=0.0), W, H, context=egl) as gpu:
        solid = gpu.render().rgba8[..., 3] == 255
        gpu.wireframe = True
        edges = gpu.render().rgba8[..., 3] == 255
        gpu.wireframe = False
        again = gpu.render().rgba8[..., 3] == 255
    side = np.sqrt(solid.sum())                      # the square's side in pixels
    # Four sides and a diagonal, give or take the corners and GL's line rule at the ends.
    assert 0.8 * (4 + np.sqrt(2)) * side < edges.sum() < 1.2 * (4 + np.sqrt(2)) * side
    assert np.array_equal(again, solid)
