"""renderer/core/hemicube.py: the hemicube's faces, pixel centres and delta form factors
(Cohen and Greenberg 1985), the one definition radiosity's GPU path and twin will both weigh
their item buffers with (issue 33). Hand-checked: the delta form factors of the whole hemicube
sum to 1 as the midpoint rule does, its error falling as 1/N²; a pixel-centre coverage of a
parallel rectangle gives Howell's B-3 form factor, its error falling as 1/N."""

import numpy as np
import pytest

from renderer.checks.form_factor_closed_forms import element_to_rectangle
from renderer.core.hemicube import FACES, delta_form_factors, face_shape, pixel_centres


def total(resolution):
    return sum(delta_form_factors(face, resolution).sum() for face in FACES)


def test_the_faces_and_their_pixels():
    """Top: N × N pixels on z = 1, row 0 towards +v; a side: the upper N / 2 rows of its face,
    row 0 at the top (z near 1), the last row just above the horizon."""
    top, side = FACES[0], FACES[1]
    assert [face.name for face in FACES] == ["top", "+u", "+v", "-u", "-v"]
    assert face_shape(top, 8) == (8, 8) and face_shape(side, 8) == (4, 8)
    centres = pixel_centres(top, 8)
    assert np.all(centres[..., 2] == 1) and centres[0, 0, 1] == 1 - 1 / 8 and centres[-1, 0, 1] == -1 + 1 / 8
    sides = pixel_centres(side, 8)
    assert np.all(sides[..., 0] == 1)
    assert sides[0, :, 2].tolist() == [1 - 1 / 8] * 8 and sides[-1, :, 2].tolist() == [1 / 8] * 8
    # by hand at N = 2: the top's four pixels of area 1 centred at (±1/2, ±1/2, 1), r² = 3/2,
    # each ΔF = 1 / (π (3/2)²); a side's two pixels at (1, ±1/2, 1/2), z = 1/2, the same r²
    assert np.allclose(delta_form_factors(top, 2), 1 / (np.pi * 2.25), rtol=1e-15)
    assert np.allclose(delta_form_factors(side, 2), 0.5 / (np.pi * 2.25), rtol=1e-15)


def test_the_four_sides_weigh_alike_and_the_top_is_symmetric():
    tables = [delta_form_factors(face, 16) for face in FACES]
    for side in tables[2:]:
        assert np.array_equal(side, tables[1])
    assert np.allclose(tables[0], tables[0].T, rtol=0, atol=1e-18)
    assert np.array_equal(tables[1], tables[1][:, ::-1])


def test_the_delta_form_factors_sum_to_one_as_the_midpoint_rule_does():
    """Each ΔF is the midpoint rule on its pixel, so the whole hemicube's sum is 1 + C / N² + ...:
    the error times N² settles to a constant (about 0.542) and the sum stays above 1 (the
    integrand is convex on the faces)."""
    scaled = [(total(n) - 1) * n * n for n in (32, 64, 128, 256)]
    assert all(s > 0 for s in scaled)
    assert abs(scaled[-1] - scaled[-2]) < abs(scaled[-2] - scaled[-3]) < abs(scaled[-3] - scaled[0]) + 1e-12
    assert scaled[-1] == pytest.approx(0.542, abs=0.001)


def coverage(resolution, a, b, c):
    """The hemicube's form factor to the rectangle [0, a] × [0, b] on the plane z = c: the
    delta form factors of the pixels whose centre's line of sight meets it (as rasterising it
    with GL's pixel-centre rule would)."""
    found = 0.0
    for face in FACES:
        p = pixel_centres(face, resolution)
        with np.errstate(divide="ignore", invalid="ignore"):
            t = c / p[..., 2]
            x, y = t * p[..., 0], t * p[..., 1]
        seen = (p[..., 2] > 0) & (x >= 0) & (x <= a) & (y >= 0) & (y <= b)
        found += delta_form_factors(face, resolution)[seen].sum()
    return found


@pytest.mark.parametrize("a, b, c", [(1, 1, 1), (2, 0.5, 1), (3, 3, 0.5)])
def test_a_hemicube_sees_a_parallel_rectangle_as_howell_b3_does(a, b, c):
    """Pixel-centre coverage errs along the rectangle's projected edges, a band one pixel wide:
    the error falls as 1/N (its product with N stays bounded), and is small at 512."""
    exact = element_to_rectangle(a, b, c)
    errors = [abs(coverage(n, a, b, c) - exact) for n in (64, 128, 256, 512)]
    assert errors[-1] < 2e-3 * exact
    assert max(e * n for e, n in zip(errors, (64, 128, 256, 512))) < 2 * exact
    assert errors[-1] < errors[0]


def test_b3_itself():
    """A quadrant of an infinite plane is a quarter of the hemisphere's cosine-weighted view;
    four corner rectangles make a centred one; far away, a point: A / (π c²)."""
    assert element_to_rectangle(1e9, 1e9, 1) == pytest.approx(0.25, abs=1e-8)
    c = 1e3
    assert element_to_rectangle(1, 2, c) == pytest.approx(2 / (np.pi * c * c), rel=1e-5)


@pytest.mark.parametrize("resolution", [0, 3, -2])
def test_a_resolution_must_be_even_and_at_least_two(resolution):
    with pytest.raises(ValueError, match="even"):
        delta_form_factors(FACES[0], resolution)
