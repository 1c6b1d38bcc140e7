"""renderer/core/radiosity_elements.py: the scene's surfaces cut into radiosity's elements
(issue 33). By hand: a triangle split k x k keeps its area and its side, each piece similar to
it; a mesh's front is the side its normals point to, whatever its winding; the elements of a
scene come in the objects' order with their materials' reflectances."""

import numpy as np

from renderer.core.radiosity_elements import Elements, mesh_elements, mesh_triangles, scene_elements, split_triangle
from renderer.core.scene import Scene, SceneObject, Transform
from renderer.core import primitives
from tests.radiosity_scenes import closed_box


def area(t):
    return 0.5 * np.linalg.norm(np.cross(t[..., 1, :] - t[..., 0, :], t[..., 2, :] - t[..., 0, :]), axis=-1)


def test_a_triangle_split_k_by_k_keeps_its_area_and_side_in_similar_pieces():
    triangle = np.array([[[0.0, 0, 0], [2, 0, 0], [0.5, 1, 0]]])
    for k in (1, 2, 3, 5):
        pieces = split_triangle(triangle, k)
        assert len(pieces) == k * k
        assert np.allclose(area(pieces), area(triangle)[0] / k ** 2, rtol=1e-12)
        assert np.all(np.cross(pieces[:, 1] - pieces[:, 0], pieces[:, 2] - pieces[:, 0])[:, 2] > 0)
        # similar: the sorted edge lengths scale by 1 / k (the downward pieces are the source turned half a turn)
        edges = np.sort(np.linalg.norm(pieces - np.roll(pieces, 1, axis=1), axis=2), axis=1)
        source = np.sort(np.linalg.norm(triangle - np.roll(triangle, 1, axis=1), axis=2), axis=1)
        assert np.allclose(edges, source / k, rtol=1e-12)


def test_elements_are_no_longer_than_the_size_and_cover_the_surface():
    box = closed_box(2.0)
    corners, obj = mesh_elements(box, np.arange(12) // 2, 0.3)
    edges = np.linalg.norm(corners - np.roll(corners, 1, axis=1), axis=2)
    assert edges.max() <= 0.3 and np.isclose(area(corners).sum(), 24.0, rtol=1e-14)
    # a face's hypotenuse 2 sqrt 2 needs k = 10 pieces along it: 100 a triangle, in the sources' order
    assert len(corners) == 1200 and np.array_equal(obj, np.repeat(np.arange(6), 200))


def test_the_front_is_where_the_normals_point_whatever_the_winding():
    positions = np.array([[0.0, 0, 0], [1, 0, 0], [0, 1, 0]])
    up = np.tile([0.0, 0, 1], (3, 1))
    clockwise = np.array([[0, 2, 1]])
    for faces in (np.array([[0, 1, 2]]), clockwise):
        for normals, side in ((up, 1), (-up, -1)):
            corners, normal = mesh_triangles(positions, faces, normals, np.eye(4))
            assert np.allclose(normal, [[0, 0, side]])
            cross = np.cross(corners[:, 1] - corners[:, 0], corners[:, 2] - corners[:, 0])
            assert cross[0, 2] * side > 0             # counter-clockwise seen from the front
    mirror = np.diag([-1.0, 1, 1, 1])                 # a mirroring model matrix keeps the side
    _, normal = mesh_triangles(positions, np.array([[0, 1, 2]]), up, mirror)
    assert np.allclose(normal, [[0, 0, 1]])


def test_the_frames_are_right_handed_with_n_the_front():
    elements = Elements(closed_box(1.0), np.zeros(12, np.int64), np.zeros((12, 3)), np.zeros((12, 3)))
    frames = elements.frames()
    assert np.allclose(frames @ np.swapaxes(frames, 1, 2), np.eye(3), atol=1e-15)
    assert np.allclose(np.linalg.det(frames), 1.0)
    assert np.allclose(frames[:, 2], elements.normals)
    inward = np.full(3, 0.5) - elements.centres
    assert np.all((inward * elements.normals).sum(axis=1) > 0)


def test_a_scene_gives_its_objects_elements_with_their_reflectance():
    scene = Scene(objects=[SceneObject("floor", primitives.plane(2.0), transform=Transform(translate=(0, -1, 0))),
                           SceneObject("box", primitives.cube(1.0))])
    scene.objects[0].material.kd = (0.2, 0.4, 0.6)
    elements = scene_elements(scene, 0.5)
    assert np.isclose(elements.areas[elements.obj == 0].sum(), 4.0) and np.isclose(elements.areas[elements.obj == 1].sum(), 6.0)
    assert np.allclose(elements.reflectance[elements.obj == 0], (0.2, 0.4, 0.6))
    assert np.all(elements.emission == 0)
    floor = elements.normals[elements.obj == 0]
    assert np.allclose(floor, [0, 1, 0])
    box = elements.obj == 1                       # the cube's normals point out
    assert np.all((elements.centres[box] * elements.normals[box]).sum(axis=1) > 0)
