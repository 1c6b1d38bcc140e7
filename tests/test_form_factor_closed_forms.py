"""renderer/checks/form_factor_closed_forms.py: Howell's closed forms C-11 (parallel, opposed
rectangles) and C-14 (perpendicular rectangles sharing an edge), the references the radiosity
method's hemicube form factors will be held to (issue 33). Each is checked by something that
does not share it: C-11 by the defining double integral (smooth there, so quadrature converges
fast); C-14, whose integrand is singular on the shared edge, by the closure of a box (the six
faces enclose the bottom one, so its form factors to them sum to 1, which ties C-14 to C-11)
and by reciprocity; both by the values the tables print and by their limits."""

import math

import pytest

from renderer.checks.form_factor_closed_forms import (parallel_rectangles, perpendicular_rectangles,
                                                      rectangles_by_quadrature)


@pytest.mark.parametrize("a, b, c", [(1, 1, 1), (2, 0.5, 1), (1, 3, 0.7), (0.2, 0.3, 2)])
def test_parallel_rectangles_are_their_integral(a, b, c):
    integral = rectangles_by_quadrature((0, 0, 0), (a, 0, 0), (0, b, 0), (0, 0, c), (0, b, 0), (a, 0, 0),
                                        points=32)
    assert parallel_rectangles(a, b, c) == pytest.approx(integral, rel=1e-11)


@pytest.mark.parametrize("a, b, c", [(1, 1, 1), (1, 2, 3), (0.1, 5, 2), (10, 0.5, 0.01), (3, 3, 40)])
def test_a_box_bottom_sees_its_five_other_faces_whole(a, b, c):
    """The bottom a × b face of an a × b × c box: to the top (C-11), to the two a × c sides along
    its edges of length a and the two b × c sides along its edges of length b (C-14): sum 1."""
    total = (parallel_rectangles(a, b, c) + 2 * perpendicular_rectangles(a, b, c)
             + 2 * perpendicular_rectangles(b, a, c))
    assert total == pytest.approx(1.0, abs=1e-12)


@pytest.mark.parametrize("l, w, h", [(1, 1, 1), (1, 2, 3), (0.5, 4, 0.1), (7, 0.2, 0.3)])
def test_perpendicular_rectangles_are_reciprocal(l, w, h):
    """A_1 F_12 = A_2 F_21: (l w) F(l, w, h) = (l h) F(l, h, w)."""
    assert w * perpendicular_rectangles(l, w, h) == pytest.approx(h * perpendicular_rectangles(l, h, w), rel=1e-13)


def test_the_unit_cube_as_the_tables_print_it():
    """Opposite faces of a cube 0.19982, adjacent faces 0.20004 (Howell's tables, Siegel and
    Howell's figures), and the two close the cube."""
    opposite, adjacent = parallel_rectangles(1, 1, 1), perpendicular_rectangles(1, 1, 1)
    assert round(opposite, 5) == 0.19982 and round(adjacent, 5) == 0.20004
    assert opposite + 4 * adjacent == pytest.approx(1.0, abs=1e-14)


def test_the_limits():
    """Far apart, the squares see each other as points: F -> A / (π c²) (a relative error of
    order (side / c)², which a naive logarithm in C-11 swamps: its argument is within rounding
    of 1 there); close together, each sees only the other: F -> 1; very long perpendicular
    rectangles are two strips in the plane, whose form factor Hottel's crossed strings give."""
    c = 1000.0
    assert parallel_rectangles(1, 1, c) == pytest.approx(1 / (math.pi * c * c), rel=1e-5)
    assert parallel_rectangles(1, 1, c) < 1 / (math.pi * c * c)       # r >= c: the bound
    assert parallel_rectangles(1, 1, 1e-6) == pytest.approx(1.0, abs=1e-5)
    # two infinitely long strips at right angles (Hottel's crossed strings, 2D): from the strip of
    # width w to the one of height h, F = (w + h - √(w² + h²)) / (2 w); rectangles 1e6 long
    w, h = 1.0, 2.0
    assert perpendicular_rectangles(1e6, w, h) == pytest.approx((w + h - math.hypot(w, h)) / (2 * w), rel=1e-5)


@pytest.mark.parametrize("sizes", [(0, 1, 1), (1, -1, 1), (1, 1, float("nan"))])
def test_sizes_that_are_not_positive_are_refused(sizes):
    with pytest.raises(ValueError, match="positive"):
        parallel_rectangles(*sizes)
    with pytest.raises(ValueError, match="positive"):
        perpendicular_rectangles(*sizes)
