"""An analytic plane as the rasteriser draws it (renderer/core/plane_clip.py): the convex polygon
where the infinite plane meets a view volume, by hand on boxes and frusta whose polygon can be
written down, then as properties over random planes and cameras, and at the extreme cameras the
fuzzer makes. (Both pipelines drawing it: tests/test_drawn.py.)"""

import math
import warnings

import numpy as np
import pytest

from renderer.core import transforms
from renderer.core.gl_rules import REVERSED_Z_DEPTH, STANDARD_DEPTH
from renderer.core.plane_clip import (MAX_POLYGON_VERTICES, object_plane_polygon, plane_polygon,
                                      view_volume_corners)
from renderer.core.scene import Plane, WorldPlane
from renderer.core.shapes import plane_mesh
from renderer.core.uv_rules import plane_uv

# Looking down -z from the origin: x right, y up (the view matrix is the identity).
VIEW = np.eye(4)


def box(near=1.0, far=3.0, height=2.0, aspect=1.0):
    """A parallel projection's volume: |x| <= height aspect / 2, |y| <= height / 2,
    -far <= z <= -near."""
    return transforms.orthographic(height, aspect, near, far) @ VIEW


def frustum(fov_deg=90.0, aspect=1.0, near=1.0, far=10.0, reversed_z=False):
    return transforms.perspective(math.radians(fov_deg), aspect, near, far, reversed_z) @ VIEW


def vertex_set(mesh):
    return sorted(tuple(np.round(p, 9) + 0.0) for p in mesh.positions)


def assert_ccw_from_normal(mesh):
    """Every fan triangle counter-clockwise seen from the side the normal points to."""
    p = mesh.positions[mesh.faces]
    cross = np.cross(p[:, 1] - p[:, 0], p[:, 2] - p[:, 0])
    assert (cross @ mesh.normals[0] > 0).all()
    assert np.array_equal(mesh.faces, [[0, k, k + 1] for k in range(1, len(mesh.positions) - 1)])


def test_a_box_cut_across_is_the_rectangle_of_the_cut():
    """y = 0.5 through the box x in [-1, 1], y in [-1, 1], z in [-3, -1]."""
    mesh = plane_polygon(WorldPlane(np.array([0.0, 1.0, 0.0]), -0.5), box())
    assert vertex_set(mesh) == [(-1.0, 0.5, -3.0), (-1.0, 0.5, -1.0), (1.0, 0.5, -3.0), (1.0, 0.5, -1.0)]
    assert np.array_equal(mesh.normals, np.tile([0.0, 1.0, 0.0], (4, 1)))
    assert_ccw_from_normal(mesh)
    flipped = plane_polygon(WorldPlane(np.array([0.0, -1.0, 0.0]), 0.5), box())
    assert vertex_set(flipped) == vertex_set(mesh)
    assert_ccw_from_normal(flipped)


def test_a_floor_in_a_frustum_is_the_trapezoid_from_near_to_far():
    """fov 90 degrees, near 1, far 10: the floor y = -0.5 meets the near plane (z = -1) from
    x = -1 to 1 and the far plane (z = -10) from x = -10 to 10; the bottom plane y = z meets
    it at z = -0.5, nearer than near."""
    expected = [(-10.0, -0.5, -10.0), (-1.0, -0.5, -1.0), (1.0, -0.5, -1.0), (10.0, -0.5, -10.0)]
    floor = WorldPlane(np.array([0.0, 1.0, 0.0]), 0.5)
    assert vertex_set(plane_polygon(floor, frustum())) == expected
    # Reversed-Z keeps 0 <= z <= w: the same volume, near to far.
    assert vertex_set(plane_polygon(floor, frustum(reversed_z=True), REVERSED_Z_DEPTH)) == expected


def test_a_plane_along_a_face_is_the_face_and_a_hexagon_through_the_middle():
    on_near_face = plane_polygon(WorldPlane(np.array([0.0, 0.0, -1.0]), -1.0), box())
    assert vertex_set(on_near_face) == [(x, y, -1.0) for x in (-1.0, 1.0) for y in (-1.0, 1.0)]
    # x + y + z = -2 through the centre (0, 0, -2) of the box [-1, 1]^2 x [-3, -1]: six vertices
    # where it crosses six of the twelve edges, at their middles.
    n = np.array([1.0, 1.0, 1.0]) / math.sqrt(3.0)
    hexagon = plane_polygon(WorldPlane(n, 2.0 / math.sqrt(3.0)), box())
    assert len(hexagon.positions) == MAX_POLYGON_VERTICES
    centred = hexagon.positions - [0.0, 0.0, -2.0]
    assert np.allclose(np.sort(np.abs(centred), axis=1), [0.0, 1.0, 1.0])
    assert_ccw_from_normal(hexagon)


@pytest.mark.parametrize("normal, offset", [
    ((0.0, 1.0, 0.0), -1.5),        # above the box
    ((0.0, 1.0, 0.0), -1.0),        # along its top face: a face, drawn (next test)
    ((1.0, 1.0, 0.0), -2.0),        # touching one edge only (x = y = 1)
    ((1.0, 1.0, -1.0), -5.0),       # touching one corner only (1, 1, -3)
])
def test_a_plane_that_meets_the_volume_in_less_than_a_polygon_draws_nothing(normal, offset):
    n = np.asarray(normal) / np.linalg.norm(normal)
    mesh = plane_polygon(WorldPlane(n, offset / np.linalg.norm(normal)), box())
    if normal == (0.0, 1.0, 0.0) and offset == -1.0:
        assert len(mesh.positions) == 4          # the top face itself
    else:
        assert mesh is None


def test_random_planes_give_convex_polygons_in_the_plane_and_the_volume():
    """For random planes through random perspective and parallel views: each vertex on the
    plane (float64) and on the volume's boundary, the polygon convex and counter-clockwise
    from N, and every point of the plane inside the volume inside the polygon (random rays
    through the volume hitting the plane)."""
    rng = np.random.default_rng(28)
    polygons = 0
    for _ in range(300):
        rotation = transforms.rotate_z(rng.uniform(-3, 3)) @ transforms.rotate_x(rng.uniform(-3, 3))
        projection = (transforms.perspective(rng.uniform(0.2, 2.5), rng.uniform(0.3, 3), 0.1, 50.0)
                      if rng.random() < 0.7 else
                      transforms.orthographic(rng.uniform(1, 20), rng.uniform(0.3, 3), -5.0, 30.0))
        clip_from_world = projection @ rotation
        n = rng.normal(size=3)
        n /= np.linalg.norm(n)
        plane = WorldPlane(n, float(rng.uniform(-20, 20)))
        mesh = plane_polygon(plane, clip_from_world)
        corners = view_volume_corners(clip_from_world)
        size = np.abs(corners).max()
        if mesh is None:
            side = corners @ n + plane.offset
            assert (side > 0).all() or (side < 0).all()
            continue
        polygons += 1
        p = mesh.positions
        assert np.abs(p @ n + plane.offset).max() <= 1e-12 * size
        clip = np.c_[p, np.ones(len(p))] @ clip_from_world.T
        ndc = clip[:, :3] / clip[:, 3:]
        assert (np.abs(ndc) <= 1 + 1e-9).all() and (np.abs(ndc) >= 1 - 1e-9).any(axis=1).all()
        edges = np.roll(p, -1, axis=0) - p
        turns = np.cross(edges, np.roll(edges, -1, axis=0)) @ n
        assert (turns > 0).all()                                  # convex, CCW from N
        # points of the plane in the volume: inside every edge's half-plane
        inside = rng.uniform(-1, 1, size=(200, 3))
        h = np.linalg.solve(clip_from_world, np.c_[inside, np.ones(200)].T).T
        a, b = h[:100, :3] / h[:100, 3:], h[100:, :3] / h[100:, 3:]
        sa, sb = a @ n + plane.offset, b @ n + plane.offset
        across = (sa < 0) != (sb < 0)
        q = a[across] + (sa[across] / (sa[across] - sb[across]))[:, None] * (b[across] - a[across])
        for start, edge in zip(p, edges):
            assert (np.cross(edge, q - start) @ n >= -1e-9 * size * size).all()
    assert polygons > 100


def test_extreme_cameras_break_nothing():
    """Near planes of 1e-300 and far/near ratios whose far plane float64 puts at infinity
    give a finite polygon or None, and no warning; a singular matrix gives None."""
    floor = WorldPlane(np.array([0.0, 1.0, 0.0]), 1.0)
    with warnings.catch_warnings():
        warnings.simplefilter("error")
        for near, far in ((1e-300, 1.0), (1e-300, 1e-299), (1e-7, 1e18), (0.1, 1e18), (1e-300, 1e18)):
            for reversed_z in (False, True):
                mesh = plane_polygon(floor, frustum(60.0, 1.5, near, far, reversed_z),
                                     REVERSED_Z_DEPTH if reversed_z else STANDARD_DEPTH)
                assert mesh is None or np.isfinite(mesh.positions).all()
        assert plane_polygon(floor, np.zeros((4, 4))) is None


def test_a_far_plane_at_infinity_in_float64_ends_where_float32_depth_does():
    """near 1e-7, far 1e18: GL's default depth row is then an infinite far plane's in
    float64. The floor 1 below the eye is drawn to z_w = 1 - 2^-24, where GL's float32 depth
    meets its clear value (z = 2 near / 2^-23, about 1.7 units). Reversed-Z's row keeps its far
    plane: the floor reaches it."""
    floor = WorldPlane(np.array([0.0, 1.0, 0.0]), 1.0)
    mesh = plane_polygon(floor, frustum(90.0, 1.0, 1e-7, 1e18))
    assert np.isclose(-mesh.positions[:, 2].min(), 2e-7 * 2.0 ** 23, rtol=1e-6)
    reversed_mesh = plane_polygon(floor, frustum(90.0, 1.0, 1e-7, 1e18, True), REVERSED_Z_DEPTH)
    assert np.isclose(-reversed_mesh.positions[:, 2].min(), 1e18)


def test_an_objects_plane_keeps_its_uvs_and_its_transform():
    """object_plane_polygon: the object's plane through its model matrix, each vertex's UV the
    plane rule's at the object-space point the model maps there (as the square's were)."""
    shape = Plane((0.0, 2.0, 0.0), -1.0)                      # y = 0.5 in the object
    model = transforms.model_matrix((2.0, 3.0, 0.5), {"xz": 0.3}, (0.2, 0.9, -0.4), (1.0, -2.0, 0.5))
    mesh = object_plane_polygon(shape, model, frustum(70.0, 1.3, 0.5, 40.0))
    local = (mesh.positions - model[:3, 3]) @ np.linalg.inv(model[:3, :3]).T
    assert np.allclose(local[:, 1], 0.5)
    assert np.allclose(mesh.uvs, plane_uv(local, shape.normal))
    square = plane_mesh(shape)                                 # the same plane, the same rule
    assert np.allclose(square.uvs, plane_uv(square.positions, shape.normal))
