"""Where the ray tracer samples a pixel (docs/conventions.md, "Sample positions"): the constants
both twins read, glsl/raytrace/sampling.glsl (as #defines, renderer/gpu/defines.py, and uniforms,
renderer/gpu/raytracer.py) and reference/raytrace/sampling.py.

Sample k (0 .. N-1) of a frame is sample index first_sample + k, the counter of the PCG
random numbers (glsl/raytrace/random.glsl), so successive frames draw new samples:

    regular, poisson   a table: offset k of renderer/core/sampling.py's pattern, the same in
                       every pixel and every frame (first_sample changes nothing)
    random             one 1 x 1 stratum: (u0, u1) - 0.5
    jittered           sample k in cell k of the strata(N) grid, row by row
    adaptive           samples 0..3 in the cells of a 2 x 2 grid (the first set, every pixel);
                       where their clamped colours differ by more than the threshold, samples
                       4..N-1 in the cells of the strata(N - 4) grid

with u0, u1 the random numbers of dimensions 0 and 1 of random_stream(pixel x, pixel y,
first_sample + k, bounce 0, seed). N is at most MAX_SAMPLES (the GLSL's uniform array).

Distributed dimensions (docs/conventions.md, "Distributed sampling"; Cook, Porter and Carpenter
1984): besides its pixel position, sample k carries a point of each other dimension it needs
(the lens, the time; at a hit, the glossy lobe and M = light_samples points of each area light),
drawn by glsl/raytrace/sampling.glsl's `distributed_2d` / `distributed_1d` (twin:
reference/raytrace/sampling.py). Each dimension's points over a pixel's samples follow the
pixel's pattern (stratified over the n * per_sample points of a set: the strata grid of
`dimension_grid`), shuffled by a hash permutation keyed per pixel, frame, ray and dimension, so
that the dimensions are stratified each and decorrelated from one another. The numbers come from
the stream of slot 0 (camera-level dimensions) or slot 1 + r (at the hit of ray r of the
sample's tree: the camera ray is r = 0, the reflected child of r is 2r + 1, the transmitted
2r + 2), dimension d's m-th point from that stream's numbers 2 (DIMENSION_STRIDE d + m) and
2 (DIMENSION_STRIDE d + m) + 1.
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np

from renderer.errors import OptionError
from renderer.core.sampling import DEFAULT_SEED, pattern as table_pattern, strata

RAY_PATTERNS = ("regular", "random", "jittered", "poisson", "adaptive")
TABLE_PATTERNS = ("regular", "poisson")
MAX_SAMPLES = 256            # also keeps a stratum's fixed-point numerator in 32 bits (sampling.glsl)
UINT32_LIMIT = 1 << 32       # seeds and sample indices are uint32 (the PCG counter)
FIRST_SET = 4                # adaptive: the samples every pixel gets, a 2 x 2 grid
# Adaptive: refine where the first samples' clamped linear colours spread over more than two
# 8-bit steps in some channel, i.e. where some sample lies more than a step from the middle of
# their range. One step refines 1.7 to 2.5 times as many pixels (smooth shading's gradients)
# for an RMS error 1 to 3 % lower (benchmarks/bench_adaptive.py, docs/conventions.md).
DEFAULT_ADAPTIVE_THRESHOLD = 2.0 / 255.0
# Distributed dimensions: camera-level (slot 0) and at a hit (slot 1 + the ray's key).
PIXEL_DIMENSION, LENS_DIMENSION, TIME_DIMENSION = 0, 1, 2
GLOSSY_DIMENSION = 0
LIGHT_DIMENSION = 1          # point light i's area samples: dimension LIGHT_DIMENSION + i
DIMENSION_STRIDE = 64        # numbers 2 (stride d + m), +1: a dimension's m-th point
MAX_LIGHT_SAMPLES = DIMENSION_STRIDE   # area-light points per hit and light
MAX_STRATA_SIDE = 256        # a strata grid's columns (stratum_offset's 32-bit numerators)
# The permutations' streams are those of seed ^ PERMUTATION_SALT (sampling.glsl), so that a
# permutation key is never one of the numbers that place the points.
PERMUTATION_SALT = 0x5BD1E995


@dataclass(frozen=True)
class RaySampling:
    """One frame's sampling rule (module docstring); made by ray_sampling()."""
    pattern: str
    samples: int                             # N; adaptive: the most a pixel gets
    seed: int
    first_set: int                           # samples every pixel gets (N but for adaptive)
    first_strata: tuple[int, int]            # (columns, rows) of samples 0 .. first_set - 1
    rest_strata: tuple[int, int]             # of samples first_set .. N - 1 (adaptive)
    table: np.ndarray | None                 # (N, 2) float32 offsets: regular, poisson
    threshold: float | None                  # adaptive: the refinement threshold
    light_samples: int = 1                   # M: each area light's points per hit

    @property
    def set_sizes(self) -> tuple[int, int]:
        """The samples of the first set and of the rest (adaptive: 4 and N - 4; else N, 0)."""
        return self.first_set, self.samples - self.first_set

    def dimension_grid(self, which_set: int, per_sample: int = 1) -> tuple[int, int]:
        """(columns, rows) of the strata grid of a distributed dimension's n * per_sample
        points of set `which_set` (n its samples): strata(n * per_sample), (1, 1) when empty."""
        n = self.set_sizes[which_set] * per_sample
        return strata(n) if n > 0 else (1, 1)

    @property
    def dimension_mode(self) -> str:
        """How a distributed dimension places its points: "random" (the stream's numbers),
        "jittered" (jittered, adaptive: uniform in a cell), "centres" (regular: the cells'
        centres) or "table" (poisson: the pixel's table at the permuted index when
        per_sample is 1; jittered cells otherwise, and in 1D)."""
        return {"random": "random", "jittered": "jittered", "adaptive": "jittered",
                "regular": "centres", "poisson": "table"}[self.pattern]

    @property
    def adaptive(self) -> bool:
        return self.threshold is not None

    def uniforms(self) -> dict[str, np.ndarray]:
        """The per-tracer uniforms (u_first_sample is per frame)."""
        values = {"u_seed": np.uint32(self.seed)}
        if self.table is not None:
            values["u_sample_offsets"] = self.table
        if self.adaptive:
            values["u_adaptive_threshold"] = np.float32(self.threshold)
        return values


def ray_sampling(pattern: str = "regular", samples: int = 1, seed: int = DEFAULT_SEED,
                 adaptive_threshold: float | None = None, light_samples: int = 1) -> RaySampling:
    """The rule of `pattern` with N = `samples` and M = `light_samples` points per area light
    and hit; OptionError (a ValueError naming the fields, its reason in one line) for an unknown pattern, N outside
    1..MAX_SAMPLES, a regular N that is not a perfect square, adaptive N < FIRST_SET, a seed
    that is not a uint32, a threshold with another pattern (adaptive: default
    DEFAULT_ADAPTIVE_THRESHOLD, finite and >= 0) or M outside 1..MAX_LIGHT_SAMPLES."""
    if pattern not in RAY_PATTERNS:
        raise OptionError("pattern", f"sample pattern must be one of {', '.join(RAY_PATTERNS)}, got {pattern!r}")
    n = int(samples)
    if not 1 <= n <= MAX_SAMPLES:
        raise OptionError("samples", f"samples per pixel must be between 1 and {MAX_SAMPLES}, got {samples}")
    if not (isinstance(seed, (int, np.integer)) and 0 <= seed < UINT32_LIMIT):
        raise OptionError("seed", f"the seed must be a whole number from 0 to {UINT32_LIMIT - 1}, got {seed!r}")
    if pattern != "adaptive" and adaptive_threshold is not None:
        raise OptionError(("adaptive_threshold", "pattern"), f"an adaptive threshold is for the adaptive "
                                                             f"pattern, not {pattern}")
    table, threshold = None, None
    first, first_strata, rest_strata = n, (1, 1), (1, 1)
    if pattern == "regular" and math.isqrt(n) ** 2 != n:
        raise OptionError(("samples", "pattern"), f"a regular grid needs a perfect square sample count, got {n}")
    if pattern in TABLE_PATTERNS:
        table = np.asarray(table_pattern(pattern, n, int(seed)), np.float32)
    elif pattern == "jittered":
        first_strata = strata(n)
    elif pattern == "adaptive":
        if n < FIRST_SET:
            raise OptionError(("samples", "pattern"), f"adaptive sampling needs at least {FIRST_SET} samples per pixel "
                             f"(its first set), got {n}")
        threshold = DEFAULT_ADAPTIVE_THRESHOLD if adaptive_threshold is None else float(adaptive_threshold)
        if not (math.isfinite(threshold) and threshold >= 0):
            raise OptionError("adaptive_threshold", f"the adaptive threshold must be a finite number >= 0, got {adaptive_threshold!r}")
        first, first_strata = FIRST_SET, strata(FIRST_SET)
        rest_strata = strata(n - FIRST_SET) if n > FIRST_SET else (1, 1)
    if not (isinstance(light_samples, (int, np.integer)) and 1 <= light_samples <= MAX_LIGHT_SAMPLES):
        raise OptionError("light_samples", f"light samples per hit must be a whole number from 1 to {MAX_LIGHT_SAMPLES}, "
                         f"got {light_samples!r}")
    # Every N <= MAX_SAMPLES and M <= MAX_LIGHT_SAMPLES makes strata grids at most
    # MAX_STRATA_SIDE wide (tests/test_raytrace_distributed.py tries them all).
    return RaySampling(pattern, n, int(seed), first, first_strata, rest_strata, table, threshold,
                       int(light_samples))


def check_first_sample(first_sample: int, samples: int) -> int:
    """first_sample as an int; ValueError unless the frame's sample indices first_sample ..
    first_sample + samples - 1 are uint32 (the PCG counter does not wrap)."""
    if not (isinstance(first_sample, (int, np.integer)) and 0 <= first_sample <= UINT32_LIMIT - samples):
        raise ValueError(f"first_sample must be a whole number from 0 to {UINT32_LIMIT - samples}, "
                         f"got {first_sample!r}")
    return int(first_sample)
