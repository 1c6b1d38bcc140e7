"""Sample patterns (renderer/core/sampling.py): offsets from the pixel centre in [-0.5, 0.5)^2."""

import math

import numpy as np
import pytest

from renderer.core.sampling import (PATTERNS, jittered, pattern, poisson_disk, poisson_radius,
                               random_samples, regular_grid, strata)

COUNTS = (1, 2, 3, 4, 8, 16, 32, 64)


def inside_pixel(offsets):
    return bool(np.all(offsets >= -0.5) and np.all(offsets < 0.5))


def test_regular_grid_is_the_pixels_sub_pixel_centres():
    # A 2x2 grid: the centres of the four quarter-pixels, row by row.
    assert regular_grid(4).tolist() == [[-0.25, -0.25], [0.25, -0.25], [-0.25, 0.25], [0.25, 0.25]]
    assert regular_grid(1).tolist() == [[0.0, 0.0]]
    offsets = regular_grid(64)
    assert sorted(set(offsets[:, 0])) == [(k + 0.5) / 8 - 0.5 for k in range(8)]


def test_regular_grid_needs_a_perfect_square():
    with pytest.raises(ValueError, match="perfect square"):
        regular_grid(8)


@pytest.mark.parametrize("n", COUNTS)
@pytest.mark.parametrize("name", ["random", "jittered", "poisson"])
def test_patterns_give_n_offsets_inside_the_pixel_repeatably(name, n):
    offsets = pattern(name, n)
    assert offsets.shape == (n, 2)
    assert inside_pixel(offsets)
    assert np.array_equal(offsets, pattern(name, n))             # a fixed seed
    if n > 1:
        assert not np.array_equal(offsets, pattern(name, n, seed=7))


def test_strata_are_the_most_nearly_square_factorisation():
    assert [strata(n) for n in (1, 2, 4, 8, 12, 32, 64, 7)] == \
        [(1, 1), (2, 1), (2, 2), (4, 2), (4, 3), (8, 4), (8, 8), (7, 1)]


@pytest.mark.parametrize("n", COUNTS)
def test_jittered_puts_one_sample_in_each_stratum(n):
    columns, rows = strata(n)
    offsets = jittered(n) + 0.5
    cells = set(zip(np.floor(offsets[:, 0] * columns).astype(int),
                    np.floor(offsets[:, 1] * rows).astype(int)))
    assert cells == {(c, r) for c in range(columns) for r in range(rows)}


@pytest.mark.parametrize("n", COUNTS)
def test_poisson_disk_keeps_its_minimum_distance(n):
    offsets = poisson_disk(n)
    distances = np.linalg.norm(offsets[:, None] - offsets[None], axis=-1)
    np.fill_diagonal(distances, np.inf)
    assert distances.min() >= poisson_radius(n)
    # The radius is 0.7 of hexagonal packing's spacing: for 64 samples about 0.094 pixels.
    assert poisson_radius(64) == pytest.approx(0.7 * math.sqrt(2 / (math.sqrt(3) * 64)))


def test_random_samples_are_not_stratified():
    # 64 uniform samples leave some of the 8x8 strata empty (jittered never does).
    offsets = random_samples(64) + 0.5
    cells = set(map(tuple, np.floor(offsets * 8).astype(int)))
    assert len(cells) < 64


def test_unknown_pattern_and_count_are_refused():
    with pytest.raises(ValueError, match="one of regular, random, jittered, poisson"):
        pattern("halton", 4)
    with pytest.raises(ValueError, match="at least 1"):
        jittered(0)
    assert set(PATTERNS) == {"regular", "random", "jittered", "poisson"}
