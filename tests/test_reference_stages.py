"""The reference pipeline stage by stage, each case worked out by hand.

Clipping (reference/clipping.py), rasterisation (reference/rasterizer.py), depth test
(reference/depth_buffer.py), output conversion (reference/framebuffer.py) and the whole draw
(reference/pipeline.py). The llvmpipe comparisons of the fill rule and snapping are in
tests/test_rasterizer.py; the lighting equation in tests/test_lighting.py.
"""

from __future__ import annotations

import math

import numpy as np
import pytest

from reference import render
from reference.clipping import clip_triangles
from reference.depth_buffer import DEPTH_TIE_TOLERANCE, DepthBuffer
from reference.fragment import interpolate
from renderer.core.gl_rules import to_unorm8
from reference.rasterizer import is_drawn, rasterize, setup_triangles
from reference.vertex import shade_vertices
from renderer.core import primitives
from renderer.core import transforms
from renderer.core.scene import (Camera, DirectionalLight, Material, Mesh, Scene, SceneObject,
                            Transform)

# A camera at the origin looking down -z, 90 degree field of view, square image, near 1:
# NDC y of a floor point at height -1 and distance d is -1/d.
FLOOR_CAMERA = Camera(eye=(0, 0, 0), look=(0, 0, -1), up=(0, 1, 0), fov_y=90.0, near=1.0, far=100.0)
PROJECTION = transforms.perspective(math.pi / 2, 1.0, 1.0, 100.0)
EMISSIVE = Material(ka=(1, 1, 1), kd=(0, 0, 0), ks=(0, 0, 0), shading="flat")


def coverage(window_triangles, width, height, cull="none"):
    """Cover count per pixel (GL rows, bottom first) of triangles in window coordinates."""
    xy = np.asarray(window_triangles, dtype=np.float64).reshape(-1, 3, 2)
    ndc = xy / [width, height] * 2.0 - 1.0
    gl_Position = np.concatenate([ndc, np.zeros(xy.shape[:2] + (1,)), np.ones(xy.shape[:2] + (1,))], -1)
    tris = setup_triangles(gl_Position, width, height)
    tris = tris.select(is_drawn(tris.area2, cull))
    count = np.zeros((height, width), dtype=int)
    for fragments in rasterize(tris, width, height):
        np.add.at(count, (fragments.y, fragments.x), 1)
    return count


def centres(width, height):
    """Pixel centre coordinates (GL rows, bottom first)."""
    return np.meshgrid(np.arange(width) + 0.5, np.arange(height) + 0.5)


# --- clipping -------------------------------------------------------------------------

def test_clip_one_vertex_inside_near_plane():
    """v0 inside (z + w = 1), v1 and v2 outside the near plane (z + w = -2): the edges
    are cut at t = 1/3 from v0, leaving one triangle (v0, 2/3 v0 + 1/3 v1, 2/3 v0 + 1/3 v2)."""
    triangle = np.array([[[0, 0, 0, 1], [0.5, 0, -3, 1], [0, 0.5, -3, 1]]], dtype=float)
    clipped = clip_triangles(triangle)
    assert len(clipped) == 1
    assert clipped.gl_Position[0] == pytest.approx(
        np.array([[0, 0, 0, 1], [1 / 6, 0, -1, 1], [0, 1 / 6, -1, 1]]))
    assert clipped.weights[0] == pytest.approx(np.array([[1, 0, 0], [2 / 3, 1 / 3, 0], [2 / 3, 0, 1 / 3]]))


def test_clip_two_vertices_inside_near_plane_gives_a_fan_of_two():
    """v0, v1 inside, v2 outside: the quad (v0, v1, v1 + (v2 - v1)/3, v0 + (v2 - v0)/3) is
    fanned from v0 into two triangles that keep the winding."""
    triangle = np.array([[[0, 0, 0, 1], [0.5, 0, 0, 1], [0, 0.5, -3, 1]]], dtype=float)
    clipped = clip_triangles(triangle)
    p12, p20 = [1 / 3, 1 / 6, -1, 1], [0, 1 / 6, -1, 1]
    assert len(clipped) == 2
    assert clipped.gl_Position[0] == pytest.approx(np.array([[0, 0, 0, 1], [0.5, 0, 0, 1], p12]))
    assert clipped.gl_Position[1] == pytest.approx(np.array([[0, 0, 0, 1], p12, p20]))
    assert list(clipped.source) == [0, 0]


def test_clip_inside_passes_and_outside_vanishes():
    """Inside all planes: unchanged, identity weights. Outside one plane: nothing.
    Order is kept (source indices ascending)."""
    inside = [[0, 0, 0, 1], [0.5, 0, 0, 1], [0, 0.5, 0, 1]]
    outside = [[2, 0, 0, 1], [3, 0, 0, 1], [2, 1, 0, 1]]                # x > w for all three
    clipped = clip_triangles(np.array([outside, inside, inside], dtype=float))
    assert list(clipped.source) == [1, 2]
    assert clipped.gl_Position[0] == pytest.approx(np.array(inside))
    assert clipped.weights[0] == pytest.approx(np.eye(3))


def test_clip_triangle_partly_behind_the_eye():
    """Eye space a = (-1, -1, -2), b = (1, -1, -2) in front, c = (0, -1, 1) behind the eye
    (w_clip = -1). Near plane z_eye = -1 cuts a-c and b-c at 1/3 of the way to c:
    (-2/3, -1, -1) and (2/3, -1, -1). In NDC the clipped quad is (-0.5, -0.5), (0.5, -0.5),
    (2/3, -1), (-2/3, -1), the new vertices on the near plane (z_ndc = -1)."""
    eye_space = np.array([[-1, -1, -2, 1], [1, -1, -2, 1], [0, -1, 1, 1]], dtype=float)
    clipped = clip_triangles((eye_space @ PROJECTION.T)[None])
    ndc = clipped.gl_Position[..., :3] / clipped.gl_Position[..., 3:]
    assert len(clipped) == 2
    xy = {tuple(np.round(v[:2], 9)) for v in ndc.reshape(-1, 3)}
    assert xy == {(-0.5, -0.5), (0.5, -0.5), (round(2 / 3, 9), -1.0), (round(-2 / 3, 9), -1.0)}
    near_vertices = ndc.reshape(-1, 3)[np.isclose(ndc.reshape(-1, 3)[:, 1], -1.0)]
    assert near_vertices[:, 2] == pytest.approx(-1.0)
    # the new vertex on b-c carries weights 2/3 b + 1/3 c
    on_bc = np.isclose(ndc[..., 0], 2 / 3)
    assert clipped.weights[on_bc][0] == pytest.approx([0, 2 / 3, 1 / 3])
    assert (clipped.gl_Position[..., 3] > 0).all()


def test_render_floor_reaching_behind_the_eye():
    """A floor triangle (y = -1) from z = 5 behind the eye to z = -20. The pixel centre at
    NDC (x, y) with y < 0 sees the floor at distance d = -1/y, where the triangle is
    2 (20 - d) / 25 wide either side: covered exactly where |x| d < 2 (20 - d) / 25,
    with depth d; nothing above the horizon."""
    floor = Mesh(np.array([[-2.0, -1, 5], [2, -1, 5], [0, -1, -20]]), np.tile([0.0, 1, 0], (3, 1)),
                 np.array([[0, 1, 2]]))
    scene = Scene(camera=FLOOR_CAMERA, objects=[SceneObject("floor", floor, EMISSIVE)], ambient=(1, 1, 1))
    frame = render(scene, 16, 16)
    x_w, y_w = centres(16, 16)
    x_ndc, y_ndc = x_w / 8 - 1, y_w / 8 - 1
    with np.errstate(divide="ignore"):
        d = np.where(y_ndc < 0, -1 / y_ndc, np.inf)
    margin = 2 * (20 - d) / 25 - np.abs(x_ndc) * d
    expected = (y_ndc < 0) & (margin > 0)
    assert np.abs(margin[y_ndc < 0]).min() > 1e-3                      # no pixel is a tie
    drawn = frame.rgba8[::-1, :, 3] == 255
    assert np.array_equal(drawn, expected)
    assert frame.depth[::-1][expected] == pytest.approx(d[expected], rel=1e-6)
    assert np.isinf(frame.depth[::-1][~expected]).all()


# --- rasterisation ----------------------------------------------------------------------

def test_two_triangles_sharing_an_edge_cover_each_pixel_once():
    """A quad split along an arbitrary diagonal, and along one through pixel centres:
    no pixel is covered twice, none inside is missed."""
    for a, b, c, d in ([(1.3, 0.7), (14.2, 2.1), (13.6, 15.1), (0.4, 12.9)],
                       [(0.5, 0.5), (14.5, 0.5), (14.5, 14.5), (0.5, 14.5)]):
        count = coverage([[a, b, c], [a, c, d]], 16, 16)
        assert count.max() == 1
        x, y = centres(16, 16)
        inside = np.ones_like(x, dtype=bool)
        for (x0, y0), (x1, y1) in zip((a, b, c, d), (b, c, d, a)):
            inside &= (x1 - x0) * (y - y0) - (y1 - y0) * (x - x0) > 1e-6
        assert (count[inside] == 1).all()


def test_fan_around_a_point_covers_each_pixel_once():
    """A fan of 37 thin triangles around an off-grid point: every pixel centre strictly
    inside the fan's polygon is covered exactly once, nothing outside is covered."""
    rng = np.random.default_rng(3)
    angles = np.sort(rng.uniform(0, 2 * np.pi, 37))
    centre = np.array([7.3, 6.8])
    ring = centre + 6.2 * np.stack([np.cos(angles), np.sin(angles)], -1)
    fan = [[centre, ring[k], ring[(k + 1) % 37]] for k in range(37)]
    count = coverage(fan, 16, 16)
    assert count.max() == 1
    x, y = centres(16, 16)
    signed = np.stack([(r1[0] - r0[0]) * (y - r0[1]) - (r1[1] - r0[1]) * (x - r0[0])
                       for r0, r1 in zip(ring, np.roll(ring, -1, axis=0))])
    assert (count[(signed > 1e-6).all(axis=0)] == 1).all()
    assert (count[(signed < -1e-6).any(axis=0)] == 0).all()


def test_zero_area_and_culling():
    """Zero-area triangles draw nothing; cull 'back' drops clockwise, 'front' counter-clockwise."""
    ccw = [(1.2, 1.1), (6.7, 1.3), (2.2, 6.9)]
    cw = ccw[::-1]
    assert coverage([[(1, 1), (3, 3), (5, 5)]], 8, 8).sum() == 0
    assert coverage([ccw], 8, 8, cull="back").sum() > 0
    assert coverage([cw], 8, 8, cull="back").sum() == 0
    assert coverage([ccw], 8, 8, cull="front").sum() == 0
    assert np.array_equal(coverage([cw], 8, 8, cull="front"), coverage([ccw], 8, 8))


def test_batches_and_bands_do_not_change_fragments():
    """Rasterising in tiny batches (large triangles split into row bands) gives the same
    fragments as one batch."""
    gl_Position = np.array([[[-1, -1, 0, 1], [1, -1, 0.5, 1], [0.2, 1, -0.5, 2]],
                            [[-0.3, -0.9, 0, 1], [0.9, 0.1, 0, 1], [-0.8, 0.7, 0, 1]]], dtype=float)
    tris = setup_triangles(gl_Position, 40, 30)

    def fragments(limit):
        parts = list(rasterize(tris, 40, 30, max_candidates=limit))
        key = np.concatenate([(p.triangle * 10000 + p.y * 100 + p.x) for p in parts])
        z = np.concatenate([p.z_w for p in parts])
        order = np.argsort(key)
        return len(parts), key[order], z[order]

    n_one, key_one, z_one = fragments(1 << 20)
    n_many, key_many, z_many = fragments(64)
    assert n_one == 1 and n_many > 10
    assert np.array_equal(key_one, key_many) and np.array_equal(z_one, z_many)


def test_perspective_correct_interpolation_on_a_receding_quad():
    """A floor quad 4 wide from z = -1 to z = -9 (y = -1) under the 90 degree camera, 8 x 8.
    At pixel column 4, row j (from the bottom) the centre's NDC y is (j + 1/2)/4 - 1 and
    the floor point it sees lies at z = 1 / y_ndc. Interpolating the world position with
    the rasteriser's weights gives exactly that, where screen-space (affine) interpolation
    would give z = -1 - 2.25 (j + 1/2). On a checker of unit cells along z the two
    disagree at row 1: perspective -1.6 (odd cell), affine -4.375 (even cell)."""
    positions = np.array([[-2.0, -1, -1], [2, -1, -1], [2, -1, -9], [-2, -1, -9]])
    faces = np.array([[0, 1, 2], [0, 2, 3]])
    vertices = shade_vertices(positions, np.tile([0.0, 1, 0], (4, 1)), u_model=np.eye(4),
                              u_normal_matrix=np.eye(3), u_view=FLOOR_CAMERA.view(),
                              u_projection=PROJECTION, u_eye=np.zeros(3), material=EMISSIVE,
                              lights=None)
    clipped = clip_triangles(vertices.gl_Position[faces])
    tris = setup_triangles(clipped.gl_Position, 8, 8)
    world_z = {}
    for f in rasterize(tris.select(is_drawn(tris.area2, "none")), 8, 8):
        weights = np.einsum("nk,nkj->nj", f.barycentric, clipped.weights[f.triangle])
        z = interpolate(vertices.v_world_position, faces, clipped.source[f.triangle], weights)[:, 2]
        world_z.update({(int(x), int(y)): value for x, y, value in zip(f.x, f.y, z)})
    for j in range(4):
        perspective = 1.0 / ((j + 0.5) / 4 - 1)
        affine = -1 - 2.25 * (j + 0.5)
        assert world_z[(4, j)] == pytest.approx(perspective, rel=1e-12)
        if j > 0:
            assert abs(world_z[(4, j)] - affine) > 0.5
    checker = lambda z: int(math.floor(-z)) % 2                       # noqa: E731
    assert checker(world_z[(4, 1)]) == 1 and checker(-1 - 2.25 * 1.5) == 0
    assert (4, 4) not in world_z                                       # above the horizon


# --- depth test ------------------------------------------------------------------------

def test_depth_buffer_keeps_nearest_and_first_of_ties():
    """GL_LESS against a buffer cleared to 1.0, fragments in draw order:
    pixel 0: z 0.5 (order 0) beats the later tie (order 1) and z 0.7; a later batch's tie
    (order 2) loses, its z 0.4 (order 3) wins. Pixel 1: z = 1.0 fails against the clear."""
    depth = DepthBuffer(2, 1)
    depth.test_and_write(np.array([0, 0, 0, 1]), np.array([0.5, 0.5, 0.7, 1.0]),
                         np.array([0, 1, 2, 3]), tag=np.array([10, 11, 12, 13]))
    assert depth.order[0] == 0 and depth.payload["tag"][0] == 10
    assert not depth.drawn[1]
    depth.test_and_write(np.array([0]), np.array([0.5]), np.array([2]), tag=np.array([20]))
    assert depth.payload["tag"][0] == 10
    depth.test_and_write(np.array([0]), np.array([0.4]), np.array([3]), tag=np.array([30]))
    assert depth.payload["tag"][0] == 30 and depth.z[0] == 0.4


def test_depth_buffer_keeps_the_runner_up_and_flags_depth_ties():
    """Per pixel the nearest losing fragment is kept too, across batches; a pixel is a depth
    tie when it lies within DEPTH_TIE_TOLERANCE (4 float32 units at 1.0) of the winner.
    Pixel 0: 0.5 wins, 0.5 + 1e-7 is runner-up (a tie). Pixel 1: 0.5 beats 0.6 (no tie).
    Pixel 2: a lone fragment has no runner-up; the clear value is never one."""
    depth = DepthBuffer(3, 1)
    depth.test_and_write(np.array([0, 1, 2]), np.array([0.5 + 1e-7, 0.6, 0.3]),
                         np.array([0, 1, 2]), tag=np.array([10, 11, 12]))
    depth.test_and_write(np.array([0, 0, 1]), np.array([0.7, 0.5, 0.5]),
                         np.array([3, 4, 5]), tag=np.array([20, 21, 22]))
    assert list(depth.payload["tag"]) == [21, 22, 12]
    assert list(depth.payload_second["tag"][:2]) == [10, 11]
    assert list(depth.order_second) == [0, 1, -1]
    assert list(depth.depth_ties()) == [True, False, False]
    assert DEPTH_TIE_TOLERANCE == 4 * 2.0 ** -23
    assert not depth.depth_ties(tolerance=0.5e-7)[0]


def test_a_fragment_that_lost_to_the_clear_is_the_runner_up_of_a_later_winner():
    depth = DepthBuffer(1, 1)
    depth.test_and_write(np.array([0]), np.array([1.0]), np.array([0]), tag=np.array([10]))
    assert not depth.drawn[0]
    depth.test_and_write(np.array([0]), np.array([0.5]), np.array([1]), tag=np.array([11]))
    assert (depth.order[0], depth.order_second[0], depth.z_second[0]) == (1, 0, 1.0)
    assert depth.payload_second["tag"][0] == 10


def test_depth_buffer_matches_testing_fragments_one_by_one():
    """Random batches with many exact ties, some fragments on the far plane (z_w = 1.0): the
    batched buffer keeps the winner GL would keep and, where something was drawn, the
    nearest other fragment, exactly as sorting all of a pixel's fragments by (z_w, order)."""
    rng = np.random.default_rng(7)
    depth = DepthBuffer(5, 1)
    fragments = {pixel: [] for pixel in range(5)}
    order = 0
    for batch in range(30):
        n = int(rng.integers(1, 5))
        pixel = rng.integers(0, 5, n)
        z = rng.choice([0.25, 0.5, 0.75, 1.0], n)
        orders = order + rng.permutation(n)            # any order within a batch
        order += n
        depth.test_and_write(pixel, z, orders, tag=orders * 10)
        for p, zz, o in zip(pixel, z, orders):
            fragments[int(p)].append((zz, o))
    for pixel, seen in fragments.items():
        ranked = sorted(seen)
        winners = [f for f in ranked if f[0] < 1.0]
        if not winners:
            assert not depth.drawn[pixel]
            continue
        assert (depth.z[pixel], depth.order[pixel]) == winners[0]
        assert depth.payload["tag"][pixel] == winners[0][1] * 10
        others = [f for f in ranked if f != winners[0]]
        expected = others[0] if others else (np.inf, -1)
        assert (depth.z_second[pixel], depth.order_second[pixel]) == expected
        if others:
            assert depth.payload_second["tag"][pixel] == others[0][1] * 10


def test_reference_offers_the_other_surface_where_two_meet_within_depth_precision():
    """Two coincident planes: GL may show either, so the reference's rgba8_tie shows the
    second drawn where rgba8 shows the first (which GL_LESS keeps on an exact tie)."""
    red, blue = (1, 0, 0), (0, 0, 1)
    frame = render(Scene(objects=[facing_plane("first", red, 4), facing_plane("second", blue, 4)],
                         ambient=(1, 1, 1)), 16, 16)
    assert tuple(frame.rgba8[8, 8]) == (255, 0, 0, 255)
    assert tuple(frame.rgba8_tie[8, 8]) == (0, 0, 255, 255)
    apart = render(Scene(objects=[facing_plane("near", red, 3.9), facing_plane("far", blue, 4)],
                         ambient=(1, 1, 1)), 16, 16)
    assert apart.rgba8_tie is None


def facing_plane(name, colour, distance):
    """A 2 x 2 plane facing the default camera (eye at z = 5) at the given distance."""
    return SceneObject(name, primitives.plane(2.0),
                       Material(ka=colour, kd=(0, 0, 0), ks=(0, 0, 0), shading="flat"),
                       Transform(rotate=(90, 0, 0), translate=(0, 0, 5.0 - distance)))


def test_depth_test_in_the_scene_keeps_nearest_then_first_drawn():
    red, blue = (1, 0, 0), (0, 0, 1)
    for objects in ([facing_plane("far", blue, 5), facing_plane("near", red, 3)],
                    [facing_plane("near", red, 3), facing_plane("far", blue, 5)],
                    [facing_plane("first", red, 4), facing_plane("second", blue, 4)]):
        frame = render(Scene(objects=objects, ambient=(1, 1, 1)), 16, 16)
        assert tuple(frame.rgba8[8, 8]) == (255, 0, 0, 255)


@pytest.mark.parametrize("projection", ["perspective", "parallel"])
def test_depth_output_is_the_plane_distance(projection):
    """A plane facing the camera 3.5 units away: depth 3.5 wherever it is drawn (both
    projections), +inf elsewhere."""
    scene = Scene(camera=Camera(projection=projection, height=4.0),
                  objects=[facing_plane("plane", (1, 1, 1), 3.5)], ambient=(1, 1, 1))
    frame = render(scene, 24, 16)
    drawn = frame.rgba8[..., 3] == 255
    assert drawn.sum() > 20 and (~drawn).sum() > 20
    assert frame.depth.dtype == np.float32
    assert frame.depth[drawn] == pytest.approx(3.5, rel=1e-6)
    assert np.isinf(frame.depth[~drawn]).all()


# --- output -----------------------------------------------------------------------------

def test_unorm8_rounds_at_half_steps():
    """u = floor(clamp(c, 0, 1) * 255 + 0.5): (k + 0.5)/255 is the first value of k + 1."""
    c = np.array([-0.5, 0.0, 0.5 / 255 - 1e-9, 0.5 / 255, 1.5 / 255 - 1e-9, 1.5 / 255,
                  127.5 / 255, 254.5 / 255 - 1e-9, 254.5 / 255, 1.0, 7.0])
    assert to_unorm8(c).tolist() == [0, 0, 0, 1, 1, 2, 128, 254, 255, 255, 255]
    assert to_unorm8(c).dtype == np.uint8


def test_frame_layout_background_and_rows():
    """Row 0 is the top: a plane above the view axis lands in the top half. The background
    is the scene's colour with alpha 0 (linear alpha 0, drawn pixels alpha 1)."""
    plane = facing_plane("high", (0.25, 0.5, 1.0), 3)
    plane.transform.scale = (0.5, 0.5, 0.5)
    plane.transform.translate = (0.0, 0.8, 2.0)
    scene = Scene(objects=[plane], ambient=(1, 1, 1), background=(0.2, 0.4, 0.6))
    frame = render(scene, 20, 20, linear=True)
    rows = np.nonzero((frame.rgba8[..., 3] == 255).any(axis=1))[0]
    assert len(rows) and rows.max() < 10
    assert tuple(frame.rgba8[19, 0]) == (51, 102, 153, 0)
    assert tuple(frame.rgba8[rows[0], 10]) == (64, 128, 255, 255)
    assert frame.linear[19, 0] == pytest.approx([0.2, 0.4, 0.6, 0.0])
    assert frame.linear[rows[0], 10] == pytest.approx([0.25, 0.5, 1.0, 1.0])
    assert frame.size == (20, 20) and frame.milliseconds > 0


def test_float32_matches_float64():
    """The whole pipeline in float32 agrees with float64 to within 1/255 but for a handful
    of pixels (snapping and depth ties can round the other way)."""
    scene = Scene(objects=[SceneObject("ball", primitives.icosphere(subdivisions=3),
                                       Material(ks=(0.5, 0.5, 0.5), shading="phong"),
                                       Transform(rotate=(10, 20, 30)))],
                  directional_lights=[DirectionalLight((-1, -1, -1))])
    a = render(scene, 64, 48).rgba8.astype(int)
    b = render(scene, 64, 48, dtype=np.float32).rgba8.astype(int)
    assert (np.abs(a - b).max(axis=-1) > 1).sum() <= 3
