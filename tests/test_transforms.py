"""renderer/core/transforms.py against the notes' matrices, hand-checked points, and pyrr.

Column vectors throughout: a point is transformed as p' = M p (docs/conventions.md), and
pyrr's row-vector matrices equal our M.T.
"""

import math

import numpy as np
import pyrr
import pytest

from renderer.core import transforms as tf

C30, S30 = math.cos(math.radians(30)), math.sin(math.radians(30))


def apply(m, point):
    """p' = M p for a 3D point (w = 1), returned as a 3-vector after the divide by w."""
    p = m @ np.array([*point, 1.0])
    return p[:3] / p[3]


# --------------------------------------------------------------------------- the notes' matrices

def test_scale_matrix_and_point():
    m = tf.scale(2.0, 3.0, 4.0)
    np.testing.assert_array_equal(m, [[2, 0, 0, 0], [0, 3, 0, 0], [0, 0, 4, 0], [0, 0, 0, 1]])
    np.testing.assert_allclose(apply(m, (1, 1, 1)), (2, 3, 4))
    np.testing.assert_allclose(apply(m, (-1, 0.5, 2)), (-2, 1.5, 8))


def test_translate_matrix_and_point():
    m = tf.translate(1.0, -2.0, 3.0)
    np.testing.assert_array_equal(m, [[1, 0, 0, 1], [0, 1, 0, -2], [0, 0, 1, 3], [0, 0, 0, 1]])
    np.testing.assert_allclose(apply(m, (4, 5, 6)), (5, 3, 9))
    # a direction (w = 0) is not moved by a translation
    np.testing.assert_allclose(m @ [1, 0, 0, 0], [1, 0, 0, 0])


def test_rotate_x_is_the_notes_matrix():
    np.testing.assert_allclose(tf.rotate_x(math.radians(30)),
                               [[1, 0, 0, 0], [0, C30, -S30, 0], [0, S30, C30, 0], [0, 0, 0, 1]])
    # +y turns towards +z
    np.testing.assert_allclose(apply(tf.rotate_x(math.pi / 2), (0, 1, 0)), (0, 0, 1), atol=1e-15)
    np.testing.assert_allclose(apply(tf.rotate_x(math.pi / 2), (0, 0, 1)), (0, -1, 0), atol=1e-15)


def test_rotate_y_is_the_notes_matrix_with_minus_sin_in_row_0():
    np.testing.assert_allclose(tf.rotate_y(math.radians(30)),
                               [[C30, 0, -S30, 0], [0, 1, 0, 0], [S30, 0, C30, 0], [0, 0, 0, 1]])
    # the notes' sense: a positive angle turns +x towards +z (and +z towards -x)
    np.testing.assert_allclose(apply(tf.rotate_y(math.pi / 2), (1, 0, 0)), (0, 0, 1), atol=1e-15)
    np.testing.assert_allclose(apply(tf.rotate_y(math.pi / 2), (0, 0, 1)), (-1, 0, 0), atol=1e-15)
    np.testing.assert_allclose(apply(tf.rotate_y(math.radians(30)), (2, 7, 0)),
                               (2 * C30, 7, 2 * S30))


def test_rotate_z_is_the_notes_matrix():
    np.testing.assert_allclose(tf.rotate_z(math.radians(30)),
                               [[C30, -S30, 0, 0], [S30, C30, 0, 0], [0, 0, 1, 0], [0, 0, 0, 1]])
    np.testing.assert_allclose(apply(tf.rotate_z(math.pi / 2), (1, 0, 0)), (0, 1, 0), atol=1e-15)
    np.testing.assert_allclose(apply(tf.rotate_z(math.radians(30)), (0, 2, 5)),
                               (-2 * S30, 2 * C30, 5))


def test_rotations_keep_lengths_and_are_proper():
    for rot in (tf.rotate_x, tf.rotate_y, tf.rotate_z):
        r = rot(0.7)[:3, :3]
        np.testing.assert_allclose(r @ r.T, np.eye(3), atol=1e-15)
        assert np.linalg.det(r) == pytest.approx(1.0)


def test_shear_is_the_notes_x_shear():
    # notes: shear parallel to the x axis by factor a: x' = x + a y, y' = y, z' = z
    a = 2.0
    np.testing.assert_array_equal(tf.shear(xy=a),
                                  [[1, a, 0, 0], [0, 1, 0, 0], [0, 0, 1, 0], [0, 0, 0, 1]])
    np.testing.assert_allclose(apply(tf.shear(xy=a), (1, 3, 5)), (7, 3, 5))
    # points on the x axis (y = 0) do not move
    np.testing.assert_allclose(apply(tf.shear(xy=a), (4, 0, -1)), (4, 0, -1))


@pytest.mark.parametrize("name, point, expected", [
    ("xy", (1, 2, 3), (1 + 0.5 * 2, 2, 3)),
    ("xz", (1, 2, 3), (1 + 0.5 * 3, 2, 3)),
    ("yx", (1, 2, 3), (1, 2 + 0.5 * 1, 3)),
    ("yz", (1, 2, 3), (1, 2 + 0.5 * 3, 3)),
    ("zx", (1, 2, 3), (1, 2, 3 + 0.5 * 1)),
    ("zy", (1, 2, 3), (1, 2, 3 + 0.5 * 2)),
])
def test_shear_factor_ab_adds_factor_times_b_to_a(name, point, expected):
    np.testing.assert_allclose(apply(tf.shear(**{name: 0.5}), point), expected)


# --------------------------------------------------------------------------- composition

def test_model_matrix_order_is_scale_then_rotate_then_translate():
    # (1, 0, 0) scaled by 2 in x -> (2, 0, 0); rotated 90 degrees about z -> (0, 2, 0);
    # translated by (10, 0, 0) -> (10, 2, 0)
    m = tf.model_matrix((2, 1, 1), None, (0, 0, math.pi / 2), (10, 0, 0))
    np.testing.assert_allclose(apply(m, (1, 0, 0)), (10, 2, 0), atol=1e-12)
    # written out: M = T Rz Ry Rx H S
    expected = (tf.translate(10, 0, 0) @ tf.rotate_z(math.pi / 2) @ tf.rotate_y(0)
                @ tf.rotate_x(0) @ tf.shear() @ tf.scale(2, 1, 1))
    np.testing.assert_allclose(m, expected)
    # any other order gives another point: translate first, then rotate, then scale
    other = tf.scale(2, 1, 1) @ tf.rotate_z(math.pi / 2) @ tf.translate(10, 0, 0)
    assert not np.allclose(apply(other, (1, 0, 0)), (10, 2, 0))


def test_model_matrix_rotates_about_x_first_then_y_then_z():
    # (0, 1, 0): Rx(90) -> (0, 0, 1); the notes' Ry(90) takes +z to -x -> (-1, 0, 0);
    # Rz(0) leaves it.
    m = tf.model_matrix((1, 1, 1), None, (math.pi / 2, math.pi / 2, 0), (0, 0, 0))
    np.testing.assert_allclose(apply(m, (0, 1, 0)), (-1, 0, 0), atol=1e-12)


def test_model_matrix_shears_after_scaling():
    # (0, 1, 0): S = scale(1, 3, 1) -> (0, 3, 0); H = shear(xy=1) -> (3, 3, 0)
    m = tf.model_matrix((1, 3, 1), {"xy": 1.0}, (0, 0, 0), (0, 0, 0))
    np.testing.assert_allclose(apply(m, (0, 1, 0)), (3, 3, 0))


def test_column_vector_convention_chain_reads_right_to_left():
    p = np.array([1.0, 2.0, 3.0, 1.0])
    # translation sits in the last column, so p' = M p adds it
    np.testing.assert_allclose(tf.translate(1, 2, 3) @ np.array([0, 0, 0, 1.0]), [1, 2, 3, 1])
    # T S p: scale first, then translate
    np.testing.assert_allclose((tf.translate(1, 0, 0) @ tf.scale(2, 2, 2)) @ p, [3, 4, 6, 1])
    np.testing.assert_allclose((tf.scale(2, 2, 2) @ tf.translate(1, 0, 0)) @ p, [4, 4, 6, 1])


def test_to_glsl_is_column_major():
    m = np.arange(16, dtype=float).reshape(4, 4)
    floats = np.frombuffer(tf.to_glsl(m), dtype=np.float32)
    np.testing.assert_array_equal(floats[:4], m[:, 0])          # first column first
    np.testing.assert_array_equal(floats.reshape(4, 4).T, m)


# --------------------------------------------------------------------------- normals

@pytest.mark.parametrize("model", [
    tf.scale(4.0, 1.0, 0.5),
    tf.model_matrix((3.0, 0.5, 1.0), {"xy": 0.7, "zx": -0.4}, (0.3, -1.1, 0.6), (5, -2, 1)),
])
def test_normal_matrix_keeps_normals_perpendicular_under_nonuniform_scale(model):
    # the plane x + y + 2z = 0: two tangents and the normal
    tangents = np.array([[1.0, -1.0, 0.0], [2.0, 0.0, -1.0]])
    normal = np.cross(tangents[0], tangents[1])
    linear = model[:3, :3]
    n_world = tf.normal_matrix(model) @ normal
    for t in tangents:
        assert np.dot(n_world, linear @ t) == pytest.approx(0.0, abs=1e-12)
    # the naive transform of the normal is not perpendicular any more
    assert abs(np.dot(linear @ normal, linear @ tangents[0])) > 1e-3


def test_normal_matrix_of_a_rotation_is_the_rotation():
    r = tf.rotate_z(0.4) @ tf.rotate_x(1.0)
    np.testing.assert_allclose(tf.normal_matrix(r), r[:3, :3], atol=1e-15)


# --------------------------------------------------------------------------- camera and pyrr

LOOK_AT_CASES = [
    ((0.0, 0.0, 5.0), (0.0, 0.0, 0.0), (0.0, 1.0, 0.0)),
    ((1.0, 2.0, 3.0), (0.0, 0.0, 0.0), (0.0, 1.0, 0.0)),
    ((-4.0, 3.0, -2.0), (1.0, -1.0, 0.5), (0.0, 1.0, 0.0)),
    ((0.0, 6.0, 4.0), (0.0, 0.0, 0.0), (0.3, 1.0, 0.2)),     # up not perpendicular
    ((2.0, 0.0, 0.0), (0.0, 0.0, 0.0), (0.0, 0.0, 1.0)),     # z up
]


@pytest.mark.parametrize("eye, look, up", LOOK_AT_CASES)
def test_look_at_matches_pyrr(eye, look, up):
    ours = tf.look_at(eye, look, up)
    theirs = pyrr.matrix44.create_look_at(np.array(eye), np.array(look), np.array(up))
    np.testing.assert_allclose(ours, np.asarray(theirs).T, atol=1e-12)


@pytest.mark.parametrize("eye, look, up", LOOK_AT_CASES)
def test_look_at_sends_eye_to_origin_and_look_down_minus_z(eye, look, up):
    v = tf.look_at(eye, look, up)
    np.testing.assert_allclose(apply(v, eye), (0, 0, 0), atol=1e-12)
    distance = np.linalg.norm(np.subtract(look, eye))
    np.testing.assert_allclose(apply(v, look), (0, 0, -distance), atol=1e-12)
    # up (made perpendicular to the view) lands in the +y half of the y-z plane
    up_view = v[:3, :3] @ np.asarray(up)
    assert up_view[0] == pytest.approx(0.0, abs=1e-12) and up_view[1] > 0


@pytest.mark.parametrize("fov_deg, aspect, near, far", [
    (45.0, 4 / 3, 0.1, 100.0), (90.0, 1.0, 1.0, 10.0), (30.0, 16 / 9, 0.5, 2000.0),
    (120.0, 0.5, 0.01, 5.0),
])
def test_perspective_matches_pyrr(fov_deg, aspect, near, far):
    ours = tf.perspective(math.radians(fov_deg), aspect, near, far)
    theirs = pyrr.matrix44.create_perspective_projection(fov_deg, aspect, near, far)
    np.testing.assert_allclose(ours, np.asarray(theirs).T, rtol=1e-12, atol=1e-12)


def test_perspective_maps_near_and_far_to_minus_and_plus_one():
    p = tf.perspective(math.radians(60), 4 / 3, 0.5, 20.0)
    np.testing.assert_allclose(apply(p, (0, 0, -0.5)), (0, 0, -1), atol=1e-12)
    np.testing.assert_allclose(apply(p, (0, 0, -20.0)), (0, 0, 1), atol=1e-12)
    # the top edge of the view at distance d is at y = d tan(fov/2) -> y_ndc = 1
    d = 3.0
    np.testing.assert_allclose(apply(p, (0, d * math.tan(math.radians(30)), -d))[1], 1.0)
    # clip w is the distance along the view axis
    assert (p @ [0, 0, -7.0, 1])[3] == pytest.approx(7.0)


@pytest.mark.parametrize("height, aspect, near, far", [
    (2.0, 4 / 3, 0.1, 100.0), (5.5, 1.0, -3.0, 40.0), (10.0, 16 / 9, 1.0, 2.0),
])
def test_orthographic_matches_pyrr(height, aspect, near, far):
    ours = tf.orthographic(height, aspect, near, far)
    half_h, half_w = height / 2, height * aspect / 2
    theirs = pyrr.matrix44.create_orthogonal_projection(-half_w, half_w, -half_h, half_h,
                                                        near, far)
    np.testing.assert_allclose(ours, np.asarray(theirs).T, atol=1e-12)


def test_orthographic_view_volume():
    p = tf.orthographic(4.0, 2.0, 1.0, 11.0)
    # the corner (w/2, h/2) at the near plane and (-w/2, -h/2) at the far plane
    np.testing.assert_allclose(apply(p, (4.0, 2.0, -1.0)), (1, 1, -1))
    np.testing.assert_allclose(apply(p, (-4.0, -2.0, -11.0)), (-1, -1, 1))
    # parallel: the size on screen does not depend on the distance
    np.testing.assert_allclose(apply(p, (1, 1, -2))[:2], apply(p, (1, 1, -9))[:2])
