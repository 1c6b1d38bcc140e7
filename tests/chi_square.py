"""Pearson's chi-square goodness-of-fit test of samples against the density they should have,
as Mitsuba 3's test suite does it (src/python/python/chi2.py, ChiSquareTest; its pooling is
mitsuba::math::chi2): a histogram of the samples over a grid of cells in the warp's
parametrisation; each cell's expected count n * the integral of the density over it; cells
whose expected count is below POOL_THRESHOLD pooled in order of increasing expectation until
the pool's reaches it; the statistic's tail under chi-square with (cells - 1) degrees of
freedom is the p-value; the null hypothesis (the samples have the density) is rejected below a
significance level that Sidak's correction shares out over the tests run together.

Differences from Mitsuba's, both stated: the integral over a cell is Gauss-Legendre with
NODES x NODES points (exact for polynomials of degree 2 NODES - 1 in each coordinate; Mitsuba
uses the trapezoid rule on 4 x 4), and a grid's edges may be uneven (`Grid`), so that a peaked
density (a Phong lobe of exponent 1000) gets rows where its mass is. A sample outside the grid
is a failure (`assert_outside_none`), as Mitsuba's out-of-domain check; a sample in a cell of
expected count 0 makes the p-value 0.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

POOL_THRESHOLD = 5.0
NODES = 4
ALPHA = 0.01


@dataclass(frozen=True)
class Grid:
    """Cells of the parametrisation (x, y): x_edges (C + 1,), y_edges (R + 1,), increasing."""
    x_edges: np.ndarray
    y_edges: np.ndarray

    @staticmethod
    def even(x_range, y_range, columns: int, rows: int) -> "Grid":
        return Grid(np.linspace(*x_range, columns + 1), np.linspace(*y_range, rows + 1))


def histogram(x, y, grid: Grid) -> tuple[np.ndarray, int]:
    """(counts (R, C) of the points (x, y) in each cell, the number outside the grid); a point
    on a cell's upper edge counts in the cell above it, the grid's last edges included."""
    column = np.searchsorted(grid.x_edges, x, side="right") - 1
    row = np.searchsorted(grid.y_edges, y, side="right") - 1
    C, R = len(grid.x_edges) - 1, len(grid.y_edges) - 1
    column = np.where(x == grid.x_edges[-1], C - 1, column)
    row = np.where(y == grid.y_edges[-1], R - 1, row)
    inside = (column >= 0) & (column < C) & (row >= 0) & (row < R)
    counts = np.bincount(row[inside] * C + column[inside], minlength=R * C).reshape(R, C)
    return counts, int((~inside).sum())


def expected_counts(density, grid: Grid, n: int) -> np.ndarray:
    """n * the integral of density(x, y) (vectorised, in the grid's parametrisation: the
    Jacobian included) over each cell, (R, C), by Gauss-Legendre quadrature."""
    nodes, weights = np.polynomial.legendre.leggauss(NODES)

    def axis(edges):                       # (cells * NODES,) points, their weights
        lo, width = edges[:-1, None], np.diff(edges)[:, None]
        return (lo + width * (nodes + 1) / 2).ravel(), (width * weights / 2).ravel()

    x, wx = axis(np.asarray(grid.x_edges, np.float64))
    y, wy = axis(np.asarray(grid.y_edges, np.float64))
    values = density(x[None, :], y[:, None]) * wy[:, None] * wx[None, :]
    R, C = len(grid.y_edges) - 1, len(grid.x_edges) - 1
    return n * values.reshape(R, NODES, C, NODES).sum((1, 3))


def pooled_statistic(observed, expected) -> tuple[float, int]:
    """(Pearson's statistic, degrees of freedom) with Mitsuba's pooling: cells sorted by
    expected count; those of at least POOL_THRESHOLD count alone, the others are added up in
    that order into pools that close once their expected count exceeds the threshold (a last,
    unclosed pool is dropped, as Mitsuba's); dof = the terms - 1."""
    observed = np.asarray(observed, np.float64).ravel()
    expected = np.asarray(expected, np.float64).ravel()
    order = np.argsort(expected, kind="stable")
    observed, expected = observed[order], expected[order]
    alone = expected >= POOL_THRESHOLD
    statistic = float((((observed - expected) ** 2) / np.where(alone, expected, 1))[alone].sum())
    terms = int(alone.sum())
    low = ~alone & ((observed != 0) | (expected != 0))
    pool_o = pool_e = 0.0                  # a loop over the low cells (few), not the samples
    for o, e in zip(observed[low], expected[low]):
        pool_o, pool_e = pool_o + o, pool_e + e
        if pool_e > POOL_THRESHOLD:
            statistic += (pool_o - pool_e) ** 2 / pool_e
            terms += 1
            pool_o = pool_e = 0.0
    return statistic, terms - 1


def p_value(observed, expected) -> float:
    """The chance of a statistic at least this large were the density right; 0 where a
    sample lies in a cell the density gives nothing."""
    observed, expected = np.asarray(observed), np.asarray(expected)
    if ((expected == 0) & (observed != 0)).any():
        return 0.0
    statistic, dof = pooled_statistic(observed, expected)
    assert dof >= 1, "too few cells to test"
    from scipy.stats import chi2          # here: its import costs a second at collection
    return float(chi2.sf(statistic, dof))


def significance(tests: int, alpha: float = ALPHA) -> float:
    """Sidak's level for each of `tests` independent tests that together reject a right
    density with chance alpha."""
    return 1.0 - (1.0 - alpha) ** (1.0 / tests)
