"""What the camera pass draws (renderer/core/drawn.py): an analytic plane as its polygon in the
camera's view volume, made each update() into buffers made once, the same in both pipelines at
every sample offset, and texturing. (The nothing-drawn warning for a plane that misses the
view: tests/test_nothing_in_view.py.)"""

from dataclasses import replace

import numpy as np

import reference
from renderer.checks.compare import compare_frames
from renderer.core.drawn import IDENTITY, camera_volume, drawn_meshes
from renderer.core.plane_clip import MAX_POLYGON_VERTICES
from renderer.core.scene import Camera, DirectionalLight, Plane, PointLight, Scene, SceneObject, Transform
from renderer.core.scene_file import scene_from_dict
from renderer.core.shapes import plane_mesh
from renderer.gpu import GpuRenderer

SIZE = (64, 48)


def floor_and_box(camera=None):
    from renderer.core.primitives import cube
    camera = camera or Camera(eye=(0.0, 1.6, 5.5), look=(0.0, 0.6, 0.0), fov_y=45.0)
    return Scene(camera, [SceneObject("floor", plane_mesh(Plane()), shape=Plane()),
                          SceneObject("box", cube(1.0), transform=Transform(translate=(0.0, 0.5, 0.0)))],
                 [DirectionalLight((-0.3, -1.0, -0.5))], [PointLight((1.0, 2.0, 1.0))], name="floor_and_box")


def test_the_camera_pass_draws_the_polygon_of_the_widened_view_the_same_at_every_offset():
    scene = floor_and_box()
    volume = scene.matrices(*SIZE)
    drawn = drawn_meshes(scene, volume)
    assert drawn[0].matrices is IDENTITY and drawn[1].mesh is scene.objects[1].mesh
    polygon = drawn[0].mesh
    assert 3 <= len(polygon.positions) <= MAX_POLYGON_VERTICES
    # one pixel beyond each side of the view: x_ndc = +-(1 + 2/64) at the polygon's side edges
    clip = np.c_[polygon.positions, np.ones(len(polygon.positions))] @ (volume.projection @ volume.view).T
    assert np.isclose(np.abs(clip[:, 0] / clip[:, 3]).max(), 1 + 2 / SIZE[0])
    jittered = scene.matrices(*SIZE, sample_offset=(0.4, -0.3))
    assert np.array_equal(drawn_meshes(scene, jittered)[0].mesh.positions, polygon.positions)
    assert np.array_equal(camera_volume(jittered), camera_volume(volume))


def test_update_writes_the_polygon_into_buffers_made_once(gl_contexts):
    """Moving the camera makes no GL object: the plane's buffers and vertex arrays stay, their
    contents and the count drawn change; a plane that leaves the view is not drawn."""
    scene = floor_and_box()
    with GpuRenderer(scene, *SIZE, context=gl_contexts["egl"]) as gpu:
        first = gpu.render()
        item = gpu._objects[0]
        buffers, arrays = item.drawn_buffers, list(item.vertex_arrays.values())
        before = item.polygon.vbo.read()
        scene.camera = Camera(eye=(3.0, 2.5, 4.0), look=(0.0, 0.3, 0.0), fov_y=50.0)
        gpu.update()
        moved = gpu.render()
        assert item.drawn_buffers == buffers and list(item.vertex_arrays.values()) == arrays
        assert item.polygon.vbo.read() != before and gpu.drawn_objects == ["floor", "box"]
        assert (first.rgba8 != moved.rgba8).any()
        scene.camera = Camera(eye=(0.0, 1.0, 5.0), look=(0.0, 9.0, 4.0))     # up at the sky
        gpu.update()
        assert item.polygon.count == 0 and gpu.drawn_objects == []


def test_both_pipelines_draw_the_same_polygon_at_sample_offsets(gl_contexts):
    """Flat and Gouraud light a plane at its polygon's vertices: the twins agree only if they
    draw the same one, also when the GPU moves only the projection for a sample offset."""
    for mode in ("flat", "gouraud", "phong"):
        scene = floor_and_box().with_shading(mode)
        with GpuRenderer(scene, *SIZE, context=gl_contexts["osmesa"]) as gpu:
            for offset in ((0.0, 0.0), (0.45, -0.5), (-0.5, 0.3)):
                frame = gpu.render(sample_offset=offset)
                expected = reference.render(scene, *SIZE, sample_offset=offset,
                                            subpixel_bits=gpu.subpixel_bits)
                result = compare_frames(frame.rgba8, expected.rgba8, frame.depth, expected.depth,
                                        reference_tie=expected.rgba8_tie)
                assert result.mismatched_pixels == 0 and result.raw_mismatched_pixels <= 2, \
                    (mode, offset, result.as_dict())
                drawn = frame.rgba8[..., 3] == 255
                assert drawn[-1].all() and drawn[SIZE[1] // 2:, [0, -1]].all()  # the floor to the edges


def test_a_textured_plane_is_textured_as_its_square_was(gl_contexts):
    """The checkerboard on the analytic floor (its polygon's UVs) against the same floor as a
    square of the plane rule's UVs (shapes.plane_mesh, as planes were drawn before: 250 units,
    beyond the far plane, 100, all round): the same texels, but for rounding."""
    texture = {"checker": {"squares": 8, "resolution": 64}, "uv_scale": [0.5, 0.5], "filter": "bilinear"}
    analytic = scene_from_dict({
        "camera": {"eye": [0.3, 1.2, 3.0], "look": [0.0, 0.0, -1.0]}, "ambient": [1.0, 1.0, 1.0],
        "materials": {"checks": {"ka": [1.0, 1.0, 1.0], "kd": [0.0, 0.0, 0.0], "texture": texture}},
        "objects": [{"name": "floor", "material": "checks", "rotate": [10.0, 30.0, 0.0],
                     "shape": {"type": "plane", "normal": [0.0, 2.0, 0.0], "offset": 1.0}}]})
    floor = analytic.objects[0]
    square = replace(analytic, objects=[replace(floor, shape=None, mesh=plane_mesh(floor.shape, 250.0))])
    frames = []
    for scene in (analytic, square):
        with GpuRenderer(scene, *SIZE, context=gl_contexts["egl"]) as gpu:
            frames.append(gpu.render())
    result = compare_frames(frames[0].rgba8, frames[1].rgba8)
    assert result.mismatched_pixels == 0 and result.max_abs <= 2, result.as_dict()
