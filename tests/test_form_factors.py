"""Radiosity's form factors (issue 33): renderer/core/form_factors.py summing the hemicubes' item
buffers (renderer/gpu/item_buffers.py) with the delta form factors (renderer/core/hemicube.py),
held to what does not share them: Howell's closed forms (renderer/checks/form_factor_closed_forms.py).

The rate, derived: a hemicube's form factor to a polygon is its pixels' delta form factors
where their centres see it. (1) Where the polygon's projected edges fall on pixel boundaries,
the pixels are whole and only the midpoint rule errs: O(1/N^2) (hemicube.py), seen below as
err N^2 constant. (2) Elsewhere the pixels cut by a projected edge count wholly or not at all:
each edge of length L (face units) crosses L N / 2 pixels of side 2/N, each off by at most the
part of its delta form factor w (2/N)^2 on the wrong side, and along a straight edge parallel
to the pixel rows all by the same fraction (at most 1/2): at most (1/N) times the integral of
the density w = 1 / (pi (x^2 + y^2 + 1)^2) along the edges, O(1/N)."""

import numpy as np
import pytest

from renderer.checks.form_factor_closed_forms import element_to_rectangle, parallel_rectangles, perpendicular_rectangles
from renderer.core.form_factors import FormFactors, form_factors, rows_from_items
from renderer.core.hemicube import ITEM_BACK_BIT, weights
from renderer.gpu.item_buffers import ItemBuffers
from reference.radiosity.item_buffer import draw
from tests.radiosity_scenes import closed_box, elements_of, parallel_squares, perpendicular_squares, quad


def gpu_form_factors(ctx, elements, resolution) -> FormFactors:
    buffers = ItemBuffers(ctx, elements, resolution)
    try:
        return form_factors(len(elements), resolution, buffers.draw, buffers.batch)
    finally:
        buffers.release()


def between_objects(elements, matrix: FormFactors) -> np.ndarray:
    """(O, O): A_a F(a -> b), the elements' A_i F_ij summed over the objects' elements."""
    objects = elements.obj.max() + 1
    flux = np.zeros((objects, objects))
    np.add.at(flux, (elements.obj[matrix.rows], elements.obj[matrix.columns]),
              elements.areas[matrix.rows] * matrix.values)
    return flux


def test_a_row_is_its_pixels_weights_by_hand():
    """N = 2: one hemicube seeing element 3 through the top's first row, element 1 from behind
    through its second, element 2 on every side's upper row and nothing below."""
    n = 2
    items = np.zeros((1, 5, n, n), np.uint32)
    items[0, 0, 0] = 4
    items[0, 0, 1] = 2 | ITEM_BACK_BIT
    items[0, 1:, 0] = 3
    table = weights(n)
    row, column, value, unseen, backs = rows_from_items(items, n, elements=5)
    assert row.tolist() == [0, 0] and column.tolist() == [2, 3]
    assert np.isclose(value[0], table[1:, 0].sum()) and np.isclose(value[1], table[0, 0].sum())
    assert np.isclose(backs[0], table[0, 1].sum()) and np.isclose(unseen[0], table[1:, 1].sum())
    assert np.isclose(value.sum() + backs[0] + unseen[0], 1.0, rtol=1e-15)
    assert unseen[0] == 0 or np.all(table[1:, 1] == 0)         # a side's lower half weighs nothing


def point_and_square(shift):
    """A tiny element at the origin facing +z (its centroid there) under the square
    [shift - 1/2, shift + 1/2] x [-1/2, 1/2] at z = 1 facing down; the exact form factor by
    superposing B-3 over the four rectangles with a corner above the element."""
    h = 1e-3
    point = np.array([[[-h, -h, 0], [2 * h, -h, 0], [-h, 2 * h, 0]]])
    square = quad((shift - 0.5, -0.5, 1), (0, 1, 0), (1, 0, 0))
    exact = 2 * (element_to_rectangle(0.5 - shift, 0.5, 1) + element_to_rectangle(0.5 + shift, 0.5, 1))
    return elements_of(np.concatenate([point, square]), np.array([0, 1, 1]), 100.0), exact


def edge_integral(shift, samples=20001):
    """The integral of w along the square's edges projected on the top face (the square lies
    in the face's plane z = 1)."""
    w = lambda x, y: 1 / (np.pi * (x * x + y * y + 1) ** 2)
    t = np.linspace(0, 1, samples)
    x, y = shift - 0.5 + t, -0.5 + t
    return (2 * np.trapezoid(w(x, 0.5), x) + np.trapezoid(w(shift - 0.5, y), y)
            + np.trapezoid(w(shift + 0.5, y), y))


def point_error(ctx, shift, n):
    elements, exact = point_and_square(shift)
    buffers = ItemBuffers(ctx, elements, n)
    try:
        _, column, value, _, _ = rows_from_items(buffers.draw([0]), n, len(elements))
    finally:
        buffers.release()
    return value[column > 0].sum() - exact


def test_edges_on_pixel_boundaries_leave_the_midpoint_rules_one_over_n_squared(gl_contexts):
    errors = {n: point_error(gl_contexts["egl"], 0.0, n) for n in (32, 64, 128, 256)}
    scaled = np.array([errors[n] * n * n for n in errors])
    assert np.all(scaled > 0) and np.ptp(scaled) < 0.01 * scaled.mean(), scaled
    assert abs(errors[256]) < 1e-6


def test_edges_across_pixels_stay_within_their_pixels_bound(gl_contexts):
    shift = 0.123
    bound_per_n = edge_integral(shift)
    for n in (8, 32, 128, 512):
        error = point_error(gl_contexts["egl"], shift, n)
        assert abs(error) <= bound_per_n / n + 0.06 / n ** 2, (n, error, bound_per_n / n)


def test_squares_facing_each_other_and_at_right_angles_approach_c11_and_c14(gl_contexts):
    """Area to area: the source cut into elements (the centroid rule, O(h^2)) and each
    element's hemicube; both squares of side 1, elements of 0.25, N = 64."""
    ctx = gl_contexts["egl"]
    for triangles, exact in ((parallel_squares(), parallel_rectangles(1, 1, 1)),
                             (perpendicular_squares(), perpendicular_rectangles(1, 1, 1))):
        elements = elements_of(triangles, np.array([0, 0, 1, 1]), 0.25)
        flux = between_objects(elements, gpu_form_factors(ctx, elements, 64))
        assert abs(flux[0, 1] - exact) < 0.015 * exact, (flux[0, 1], exact)
        assert abs(flux[1, 0] - exact) < 0.015 * exact       # reciprocity: equal areas, equal F


@pytest.mark.slow
def test_finer_elements_and_hemicubes_come_closer(gl_contexts):
    ctx = gl_contexts["egl"]
    for triangles, exact, limit in ((parallel_squares(), parallel_rectangles(1, 1, 1), 0.002),
                                    (perpendicular_squares(), perpendicular_rectangles(1, 1, 1), 0.0005)):
        elements = elements_of(triangles, np.array([0, 0, 1, 1]), 0.1)
        flux = between_objects(elements, gpu_form_factors(ctx, elements, 256))
        assert abs(flux[0, 1] - exact) < limit * exact, (flux[0, 1], exact)


def test_a_closed_box_sums_to_one_and_is_reciprocal_within_the_hemicubes_error(gl_contexts):
    elements = elements_of(closed_box(1.0), np.arange(12) // 2, 0.25)
    matrix = gpu_form_factors(gl_contexts["egl"], elements, 64)
    assert np.abs(matrix.row_sums() - 1).max() < 1e-13
    assert not matrix.unseen.any() and not matrix.backs.any()
    assert np.all(matrix.columns != matrix.rows)                   # a flat element does not see itself
    flux = between_objects(elements, matrix)                       # faces of area 1: A F = F
    assert np.abs(flux - flux.T).max() < 0.005 * flux.max()
    opposite, adjacent = parallel_rectangles(1, 1, 1), perpendicular_rectangles(1, 1, 1)
    for a in range(6):
        for b in range(6):
            if a != b:
                exact = opposite if b == a ^ 1 else adjacent
                assert abs(flux[a, b] - exact) < 0.015 * exact, (a, b, flux[a, b], exact)


def test_the_gpu_and_the_twin_give_the_same_matrix(gl_contexts):
    elements = elements_of(closed_box(1.0), np.arange(12) // 2, 0.5)
    gpu = gpu_form_factors(gl_contexts["osmesa"], elements, 16)
    twin = form_factors(len(elements), 16, lambda indices: draw(elements, 16, indices).items, 64)
    for name in ("indptr", "columns", "values", "unseen", "backs"):
        assert np.array_equal(getattr(gpu, name), getattr(twin, name)), name


def test_the_sparse_matrix_multiplies_and_transposes_as_the_dense_one():
    rng = np.random.default_rng(3)
    dense = np.where(rng.random((7, 7)) < 0.4, rng.random((7, 7)), 0.0)
    rows, columns = np.nonzero(dense)
    indptr = np.concatenate([[0], np.cumsum(np.bincount(rows, minlength=7))])
    matrix = FormFactors(indptr, columns, dense[rows, columns], np.zeros(7), np.zeros(7))
    b = rng.random((7, 3))
    assert np.allclose(matrix.times(b), dense @ b) and np.allclose(matrix.times(b[:, 0]), dense @ b[:, 0])
    colptr, by_row, values = matrix.by_column()
    rebuilt = np.zeros((7, 7))
    rebuilt[by_row, np.repeat(np.arange(7), np.diff(colptr))] = values
    assert np.array_equal(rebuilt, dense) and np.array_equal(matrix.dense(), dense)
