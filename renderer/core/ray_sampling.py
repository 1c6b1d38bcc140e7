"""Where the ray tracer samples a pixel (docs/conventions.md, "Sample positions"): the constants
both twins read, glsl/raytrace/sampling.glsl (as #defines and uniforms, renderer/gpu/
raytracer.py) and reference/raytrace/sampling.py.

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
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np

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

    @property
    def adaptive(self) -> bool:
        return self.threshold is not None

    def defines(self) -> dict[str, object]:
        """sampling.glsl's and raytrace.frag's compile-time constants."""
        return {"NUM_SAMPLES": self.samples, "FIRST_SAMPLES": self.first_set,
                "SAMPLE_TABLE": self.table is not None, "ADAPTIVE": self.adaptive,
                "FIRST_COLUMNS": self.first_strata[0], "FIRST_ROWS": self.first_strata[1],
                "REST_COLUMNS": self.rest_strata[0], "REST_ROWS": self.rest_strata[1]}

    def uniforms(self) -> dict[str, np.ndarray]:
        """The per-tracer uniforms (u_first_sample is per frame)."""
        values = {"u_seed": np.uint32(self.seed)}
        if self.table is not None:
            values["u_sample_offsets"] = self.table
        if self.adaptive:
            values["u_adaptive_threshold"] = np.float32(self.threshold)
        return values


def ray_sampling(pattern: str = "regular", samples: int = 1, seed: int = DEFAULT_SEED,
                 adaptive_threshold: float | None = None) -> RaySampling:
    """The rule of `pattern` with N = `samples`; ValueError (its reason in one line) for an
    unknown pattern, N outside 1..MAX_SAMPLES, a regular N that is not a perfect square,
    adaptive N < FIRST_SET, a seed that is not a uint32, or a threshold with another pattern
    (adaptive: default DEFAULT_ADAPTIVE_THRESHOLD, finite and >= 0)."""
    if pattern not in RAY_PATTERNS:
        raise ValueError(f"sample pattern must be one of {', '.join(RAY_PATTERNS)}, got {pattern!r}")
    n = int(samples)
    if not 1 <= n <= MAX_SAMPLES:
        raise ValueError(f"samples per pixel must be between 1 and {MAX_SAMPLES}, got {samples}")
    if not (isinstance(seed, (int, np.integer)) and 0 <= seed < UINT32_LIMIT):
        raise ValueError(f"the seed must be a whole number from 0 to {UINT32_LIMIT - 1}, got {seed!r}")
    if pattern != "adaptive" and adaptive_threshold is not None:
        raise ValueError("an adaptive threshold is for the adaptive pattern")
    table, threshold = None, None
    first, first_strata, rest_strata = n, (1, 1), (1, 1)
    if pattern in TABLE_PATTERNS:
        table = np.asarray(table_pattern(pattern, n, int(seed)), np.float32)
    elif pattern == "jittered":
        first_strata = strata(n)
    elif pattern == "adaptive":
        if n < FIRST_SET:
            raise ValueError(f"adaptive sampling needs at least {FIRST_SET} samples per pixel "
                             f"(its first set), got {n}")
        threshold = DEFAULT_ADAPTIVE_THRESHOLD if adaptive_threshold is None else float(adaptive_threshold)
        if not (math.isfinite(threshold) and threshold >= 0):
            raise ValueError(f"the adaptive threshold must be a finite number >= 0, got {adaptive_threshold!r}")
        first, first_strata = FIRST_SET, strata(FIRST_SET)
        rest_strata = strata(n - FIRST_SET) if n > FIRST_SET else (1, 1)
    return RaySampling(pattern, n, int(seed), first, first_strata, rest_strata, table, threshold)


def check_first_sample(first_sample: int, samples: int) -> int:
    """first_sample as an int; ValueError unless the frame's sample indices first_sample ..
    first_sample + samples - 1 are uint32 (the PCG counter does not wrap)."""
    if not (isinstance(first_sample, (int, np.integer)) and 0 <= first_sample <= UINT32_LIMIT - samples):
        raise ValueError(f"first_sample must be a whole number from 0 to {UINT32_LIMIT - samples}, "
                         f"got {first_sample!r}")
    return int(first_sample)
