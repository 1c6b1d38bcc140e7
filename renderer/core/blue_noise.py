"""The blue-noise dither mask: Ulichney's void-and-cluster method (R. Ulichney, "The
void-and-cluster method for dither array generation", Proc. SPIE 1913, 1993), made once in
NumPy and read by both twins of the output stage (glsl/output/dither.glsl, reference/output/
dither.py): each of size^2 pixels gets a distinct rank, and the pixels of ranks below any k
are spread as evenly as a void-and-cluster search can spread them (few low frequencies: the
mask's spectrum is "blue").

The method, on a torus (the mask tiles the image, so its energy wraps around):
- energy(p) = sum over the pattern's 1s q of exp(-d(p, q)^2 / (2 sigma^2)), d toroidal,
  sigma = SIGMA pixels; the "tightest cluster" is the 1 of highest energy, the "largest
  void" the 0 of lowest;
- an initial pattern: INITIAL_FRACTION of the pixels chosen at random from the fixed SEED,
  then made homogeneous by moving the tightest cluster's 1 to the largest void until the
  move would put it back;
- phase 1 ranks the initial 1s by removing the tightest cluster, one at a time, from the
  highest rank down; phases 2 and 3 rank the 0s by filling the largest void, one at a time,
  up to size^2 - 1. (Ulichney's phase 3 seeks the tightest cluster of 0s under the inverted
  pattern; on a torus that energy is sum(kernel) - energy, so it is the largest void too.)
Ties go to the first pixel in row-major order (np.argmin / np.argmax), so the mask is the
same on every run. Made in about 0.1 s at 64 x 64 (benchmarks/bench_output.py prints it).
"""

from __future__ import annotations

from functools import lru_cache

import numpy as np

SIZE = 64                  # pixels a side: 4096 ranks, 12 bits of threshold
SIGMA = 1.5                # pixels: the energy filter's width (Ulichney's choice)
INITIAL_FRACTION = 0.1     # of the pixels set in the initial pattern
SEED = 1993                # the initial pattern's random choice


def _torus_kernel(size: int, sigma: float) -> np.ndarray:
    """(2 size, 2 size) float64: the toroidal Gaussian centred on (0, 0), tiled twice in each
    direction, so that the kernel centred on (y, x) is the view [size - y:, size - x:][:size, :size]."""
    d = np.minimum(np.arange(size), size - np.arange(size)).astype(np.float64)
    kernel = np.exp(-(d[:, None] ** 2 + d[None, :] ** 2) / (2.0 * sigma * sigma))
    return np.tile(kernel, (2, 2))


class _Energy:
    """The pattern's energy field, updated by one shifted kernel per pixel set or cleared."""

    def __init__(self, size: int, sigma: float):
        self.size = size
        self.kernel = _torus_kernel(size, sigma)
        self.field = np.zeros((size, size), dtype=np.float64)

    def change(self, index: int, sign: float) -> None:
        y, x = divmod(int(index), self.size)
        self.field += sign * self.kernel[self.size - y:2 * self.size - y,
                                         self.size - x:2 * self.size - x]

    def tightest_cluster(self, pattern: np.ndarray) -> int:
        return int(np.argmax(np.where(pattern, self.field.reshape(-1), -np.inf)))

    def largest_void(self, pattern: np.ndarray) -> int:
        return int(np.argmin(np.where(pattern, np.inf, self.field.reshape(-1))))


@lru_cache(maxsize=4)
def blue_noise_ranks(size: int = SIZE) -> np.ndarray:
    """(size, size) uint16, read-only: a permutation of 0 .. size^2 - 1, indexed [y, x] with y
    the image row from the top; the dither threshold of pixel (x, y) is
    (ranks[y % size, x % size] + 0.5) / size^2 (reference/output/dither.py)."""
    count = size * size
    energy = _Energy(size, SIGMA)
    pattern = np.zeros(count, dtype=bool)
    initial = np.random.default_rng(SEED).choice(count, int(INITIAL_FRACTION * count), replace=False)
    for index in initial:
        pattern[index] = True
        energy.change(index, +1.0)

    def move(index: int, value: bool) -> None:
        pattern[index] = value
        energy.change(index, +1.0 if value else -1.0)

    while True:                                        # the homogeneous initial pattern
        cluster = energy.tightest_cluster(pattern)
        move(cluster, False)
        void = energy.largest_void(pattern)
        move(void, True)
        if void == cluster:
            break
    ranks = np.zeros(count, dtype=np.uint16)
    initial_pattern = pattern.copy()
    initial_field = energy.field.copy()
    ones = int(pattern.sum())
    for rank in range(ones - 1, -1, -1):               # phase 1: clusters, from the top rank down
        cluster = energy.tightest_cluster(pattern)
        move(cluster, False)
        ranks[cluster] = rank
    pattern[:] = initial_pattern
    energy.field[:] = initial_field
    for rank in range(ones, count):                    # phases 2 and 3: voids, upwards
        void = energy.largest_void(pattern)
        move(void, True)
        ranks[void] = rank
    ranks = ranks.reshape(size, size)
    ranks.flags.writeable = False
    return ranks
