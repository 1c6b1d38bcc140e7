"""Sample patterns for supersampling (notes 2.2, "forms of anti-aliasing"; Mitchell 1996).

Each pattern is a pure function of the sample count N (and a seed) returning an (N, 2)
float64 array of offsets (dx, dy) in pixels from the pixel centre, every one in
[-0.5, 0.5), in GL window coordinates (x right, y up): docs/conventions.md, "Sample
positions". The same offsets serve every pixel of an image (one projection jitter per pass).

    regular_grid(16)        the pixel's (k + 0.5) / 4 - 0.5 positions; N a perfect square
    random_samples(8)       uniform, independent
    jittered(8)             one uniform sample in each of a x b strata (a*b = N, near square)
    poisson_disk(8)         dart throwing: no two samples closer than poisson_radius(8)
"""

from __future__ import annotations

import math

import numpy as np

DEFAULT_SEED = 1996          # Mitchell's year; any fixed seed makes the patterns repeatable


def regular_grid(n: int) -> np.ndarray:
    """The n = k*k sub-pixel centres ((a + 0.5) / k - 0.5, (b + 0.5) / k - 0.5), row by row."""
    k = math.isqrt(n)
    if n < 1 or k * k != n:
        raise ValueError(f"a regular grid needs a perfect square sample count, got {n}")
    centres = (np.arange(k) + 0.5) / k - 0.5
    y, x = np.meshgrid(centres, centres, indexing="ij")
    return np.stack([x.ravel(), y.ravel()], axis=1)


def random_samples(n: int, seed: int = DEFAULT_SEED) -> np.ndarray:
    """n offsets uniform in [-0.5, 0.5)^2, independent."""
    _check_count(n)
    return np.random.default_rng(seed).random((n, 2)) - 0.5


def strata(n: int) -> tuple[int, int]:
    """(columns, rows) of the most nearly square grid with columns * rows = n, columns >= rows."""
    _check_count(n)
    rows = max(d for d in range(1, math.isqrt(n) + 1) if n % d == 0)
    return n // rows, rows


def jittered(n: int, seed: int = DEFAULT_SEED) -> np.ndarray:
    """Stratified: the pixel cut into strata(n) cells, one uniform sample in each, row by row."""
    columns, rows = strata(n)
    y, x = np.meshgrid(np.arange(rows), np.arange(columns), indexing="ij")
    u = np.random.default_rng(seed).random((n, 2))
    cells = np.stack([(x.ravel() + u[:, 0]) / columns, (y.ravel() + u[:, 1]) / rows], axis=1)
    return np.minimum(cells, np.nextafter(1.0, 0.0)) - 0.5      # (c - 1 + u) / c may round to 1


def poisson_radius(n: int) -> float:
    """Minimum distance for n Poisson-disk samples in the unit square: 0.7 of the spacing of
    n hexagonally packed disks, sqrt(2 / (sqrt(3) n)), a density dart throwing always reaches."""
    return 0.7 * math.sqrt(2.0 / (math.sqrt(3.0) * n))


def poisson_disk(n: int, seed: int = DEFAULT_SEED, max_tries: int = 100_000) -> np.ndarray:
    """Dart throwing: uniform candidates, kept when at least poisson_radius(n) from every kept
    one, until n are kept (the candidates come in vectorised batches)."""
    _check_count(n)
    radius2 = poisson_radius(n) ** 2
    rng = np.random.default_rng(seed)
    kept = np.empty((0, 2))
    tries = 0
    while len(kept) < n:
        if tries >= max_tries:
            raise RuntimeError(f"dart throwing found only {len(kept)} of {n} samples")
        candidates = rng.random((256, 2))
        tries += len(candidates)
        for point in candidates:                       # at most a few hundred per pattern
            if len(kept) == 0 or np.min(np.sum((kept - point) ** 2, axis=1)) >= radius2:
                kept = np.vstack([kept, point])
                if len(kept) == n:
                    break
    return kept - 0.5


PATTERNS = {
    "regular": lambda n, seed=DEFAULT_SEED: regular_grid(n),
    "random": random_samples,
    "jittered": jittered,
    "poisson": poisson_disk,
}


def pattern(name: str, n: int, seed: int = DEFAULT_SEED) -> np.ndarray:
    """The (n, 2) offsets of pattern `name` (a key of PATTERNS)."""
    if name not in PATTERNS:
        raise ValueError(f"sample pattern must be one of {', '.join(PATTERNS)}, got {name!r}")
    return PATTERNS[name](n, seed)


def _check_count(n: int) -> None:
    if n < 1:
        raise ValueError(f"sample count must be at least 1, got {n}")
