"""Sampler statistics (issue 16, "Checks that no one can tune to"): each sampling routine of the
distributed ray tracer passes Pearson's chi-square test of about 10^6 of its samples against
its density, in the NumPy twin (tests/chi_square.py: Mitsuba 3's method), the significance
alpha = 0.01 shared by Sidak's correction over the TESTS tests of this module; and each test
shows that it can fail: the same samples against a slightly wrong density (stated per case)
are rejected at that level. The routines, fed by distributed_2d / distributed_1d as the
tracer feeds them:

- square_to_disc (the lens; a disc light's points are the disc scaled into its plane), in
  (phi, r^2), where its density 1/pi is 1/(2 pi);
- square_to_cosine_hemisphere (the path tracer's diffuse bounce), in (phi, cos^2 alpha):
  1/(2 pi);
- square_to_sphere (a sphere light), in (phi, z): 1/(4 pi);
- square_to_phong_lobe at exponents 1, 10, 1000 (glossy reflection), in (phi, alpha) with
  alpha's rows where the lobe's mass is: (e + 1)/(2 pi) cos^e alpha sin alpha;
- distributed_2d's points under each pattern (the pixel-level dimensions, and an area light's
  M = 4 points per sample), uniform on the square; distributed_1d's (the time), uniform on
  [0, 1). Regular places its points at cell centres: its cells are the strata themselves;
  poisson with one point per sample takes the pixel's table: each table point equally often.

The GLSL draws the same samples: its warps of distributed_2d's points (tests/glsl/
raytrace_warp.frag) on EGL and OSMesa are within WARP_EPS of the twin's, the points themselves
bit for bit (distributed_2d on its own: tests/test_raytrace_distributed.py).
"""

from dataclasses import dataclass
from typing import Callable

import numpy as np
import pytest

from chi_square import Grid, expected_counts, histogram, p_value, significance
from glsl_harness import ShaderProbe
from reference.raytrace import warp
from reference.raytrace.motion import motion_time
from reference.raytrace.sampling import distributed_1d, distributed_2d
from reference.raytrace.area_lights import area_light_point
from renderer.core.light_areas import AREA_SHAPE_CODES
from renderer.core.path_options import BOUNCE_DIMENSION
from renderer.core.ray_sampling import LENS_DIMENSION, LIGHT_DIMENSION, TIME_DIMENSION, ray_sampling
from renderer.gpu.defines import sampling_defines

PI = np.pi
SAMPLES_PER_PIXEL = 16
PIXELS = 1 << 16                   # x 16 samples: 1,048,576 points
EPS32 = float(np.finfo(np.float32).eps)
# The GLSL's warps against the twin's, per component: sin, cos, log and exp a few ulps apart
# (measured: 1.6 eps32 at most over 2 x 2 x 64 x 48 points of each warp and 256 x 256 of
# random points).
WARP_EPS = 4 * EPS32


def pixel_grid(pixels: int):
    """(x, y) uint32 of `pixels` pixels, 256 to a row."""
    y, x = np.divmod(np.arange(pixels, dtype=np.uint32), np.uint32(256))
    return x, y


def points_2d(pattern: str, dimension: int = LENS_DIMENSION, slot: int = 0, per_sample: int = 1,
              samples: int = SAMPLES_PER_PIXEL) -> np.ndarray:
    """distributed_2d's points, (P, 2) float32, of every sample (and every m < per_sample) of
    PIXELS / per_sample pixels: about 10^6."""
    sampling = ray_sampling(pattern, samples, light_samples=per_sample)
    x, y = pixel_grid(PIXELS // per_sample)
    k = np.arange(samples)[:, None, None]
    m = np.arange(per_sample)[None, :, None]
    return np.concatenate([distributed_2d(x, y, kk, 0, sampling, slot, dimension, mm, per_sample)
                           for kk in k.ravel() for mm in m.ravel()])


def points_1d(pattern: str) -> np.ndarray:
    sampling = ray_sampling(pattern, SAMPLES_PER_PIXEL)
    x, y = pixel_grid(PIXELS)
    return np.concatenate([distributed_1d(x, y, k, 0, sampling, 0, TIME_DIMENSION)
                           for k in range(SAMPLES_PER_PIXEL)])


def tilted(density, along, amount=0.05):
    """density (1 + amount * along(x, y)): still integrating to 1 where `along` averages to 0
    under it; a few per cent more on one side."""
    return lambda x, y: density(x, y) * (1 + amount * along(x, y))


@dataclass
class Case:
    """One chi-square test: `sample()` -> (x, y) in the grid's parametrisation; `density(x, y)`
    the routine's (Jacobian included), `wrong(x, y)` the density it must be told apart from."""
    name: str
    sample: Callable
    grid: Callable
    density: Callable
    wrong: Callable
    wrong_says: str


# -- the warps ---------------------------------------------------------------------------------

def disc_case():
    def sample():
        p = warp.square_to_disc(points_2d("jittered")).astype(np.float64)
        return np.arctan2(p[:, 1], p[:, 0]), (p ** 2).sum(1)

    def disc(phi, s, radius=1.0):                       # area r dr dphi = 1/2 ds dphi
        r = np.sqrt(s)
        p = np.stack(np.broadcast_arrays(r * np.cos(phi), r * np.sin(phi)), -1)
        return warp.disc_density(p / radius) / radius ** 2 / 2
    return Case("square_to_disc", sample, lambda: Grid.even((-PI, PI), (0, 1), 64, 64), disc,
                lambda phi, s: disc(phi, s, 1.02), "the density of a disc 2 % wider")


def sphere_case():
    def sample():
        d = warp.square_to_sphere(points_2d("random", LIGHT_DIMENSION, slot=1)).astype(np.float64)
        return np.arctan2(d[:, 1], d[:, 0]), d[:, 2]

    def sphere(phi, z):
        r = np.sqrt(np.maximum(0, 1 - z * z))
        return warp.sphere_density(np.stack(np.broadcast_arrays(r * np.cos(phi), r * np.sin(phi), z), -1))
    return Case("square_to_sphere", sample, lambda: Grid.even((-PI, PI), (-1, 1), 64, 32), sphere,
                tilted(sphere, lambda phi, z: z), "5 % more towards +z")


def cosine_case():
    """The path tracer's diffuse bounce, in (phi, cos^2 alpha), where its density
    cos(alpha)/pi is 1/(2 pi) (d omega = d phi d(cos alpha), d(cos^2) = 2 cos d(cos))."""
    def sample():
        d = warp.square_to_cosine_hemisphere(points_2d("random", dimension=BOUNCE_DIMENSION, slot=2)).astype(np.float64)
        return np.arctan2(d[:, 1], d[:, 0]), d[:, 2] ** 2

    def cosine(phi, c2):
        c = np.sqrt(c2)
        s = np.sqrt(np.maximum(0, 1 - c2))
        d = np.stack(np.broadcast_arrays(s * np.cos(phi), s * np.sin(phi), c), -1)
        return warp.cosine_hemisphere_density(d) / (2 * np.maximum(c, 1e-300))
    return Case("square_to_cosine_hemisphere", sample, lambda: Grid.even((-PI, PI), (0, 1), 64, 32),
                cosine, tilted(cosine, lambda phi, c2: c2 - 0.5, 0.1), "10 % more towards the normal")


def lobe_case(exponent: float):
    """Rows of alpha up to 6 / sqrt(e) (the lobe's mass beyond is below e^-18) and one row
    for the rest of the hemisphere."""
    top = min(PI / 2, 6 / np.sqrt(exponent))
    edges = np.linspace(0, top, 49)
    if top < PI / 2:
        edges = np.append(edges, PI / 2)
    wrong_exponent = exponent + max(1.0, exponent / 50)

    def sample():
        d = warp.square_to_phong_lobe(points_2d("random", slot=7, dimension=0), np.float32(exponent))
        d = d.astype(np.float64)
        return np.arctan2(d[:, 1], d[:, 0]), np.arctan2(np.hypot(d[:, 0], d[:, 1]), d[:, 2])

    def lobe(phi, alpha, e=exponent):                   # solid angle: sin alpha dalpha dphi
        d = np.stack(np.broadcast_arrays(np.sin(alpha) * np.cos(phi), np.sin(alpha) * np.sin(phi),
                                         np.cos(alpha)), -1)
        return warp.phong_lobe_density(d, e) * np.sin(alpha)
    return Case(f"square_to_phong_lobe e={exponent:g}", sample,
                lambda: Grid(np.linspace(-PI, PI, 33), edges), lobe,
                lambda phi, alpha: lobe(phi, alpha, wrong_exponent), f"exponent {wrong_exponent:g}")


def rectangle_light_case():
    """A 3 x 2 rectangle light's points (area_lights.py's area_light_point: centre + (2u - 1) of its
    half-edges, u its LIGHT_DIMENSION points, 4 per hit), uniform over the rectangle."""
    half = (1.5, 1.0)

    def sample():
        areas = np.zeros((3, 4), np.float32)
        areas[0, 0], areas[1, 1] = half
        areas[0, 3] = AREA_SHAPE_CODES["rectangle"]
        centre = np.float32([0.5, -2.0, 3.0])
        q = area_light_point(areas, 0, centre, points_2d("jittered", LIGHT_DIMENSION, 3, 4)).astype(np.float64)
        return (q[:, 0] - 0.5) / half[0], (q[:, 1] + 2.0) / half[1]

    def rectangle(x, y):                                # on [-1, 1]^2: 1/4
        return uniform(x, y) / 4
    return Case("area_light_point rectangle", sample, lambda: Grid.even((-1, 1), (-1, 1), 48, 32),
                rectangle, tilted(rectangle, lambda x, y: y), "5 % more towards +y")


def time_case():
    """The sample times of a shutter [0.25, 2.25] (motion.py's motion_time of distributed_1d's
    TIME points, jittered), uniform over it."""
    def sample():
        t = motion_time((0.25, 2.25), points_1d("jittered")).astype(np.float64)
        return t, np.zeros_like(t)

    def shutter(t, _):
        return uniform(t, _) / 2
    return Case("motion_time", sample, lambda: Grid(np.linspace(0.25, 2.25, 1001), np.array([-0.5, 0.5])),
                shutter, tilted(shutter, lambda t, _: t - 1.25), "5 % more towards the close")


# -- distributed_2d and distributed_1d ---------------------------------------------------------

def uniform(x, y):
    return np.ones(np.broadcast_shapes(np.shape(x), np.shape(y)))


def square_case(pattern: str, per_sample: int = 1):
    sampling = ray_sampling(pattern, SAMPLES_PER_PIXEL, light_samples=per_sample)
    columns, rows = sampling.dimension_grid(0, per_sample)
    dimension, slot = (LIGHT_DIMENSION, 5) if per_sample > 1 else (LENS_DIMENSION, 0)

    def sample():
        p = points_2d(pattern, dimension, slot, per_sample).astype(np.float64)
        return p[:, 0], p[:, 1]

    def grid():                                         # regular: its points are cell centres
        return Grid.even((0, 1), (0, 1), columns, rows) if pattern == "regular" else \
            Grid.even((0, 1), (0, 1), 64, 64)
    return Case(f"distributed_2d {pattern} x{per_sample}", sample, grid, uniform,
                tilted(uniform, lambda x, y: 2 * x - 1), "5 % more towards x = 1")


def line_case(pattern: str):
    def sample():
        t = points_1d(pattern).astype(np.float64)
        return t, np.zeros_like(t)

    def grid():
        cells = SAMPLES_PER_PIXEL if pattern == "regular" else 1000
        return Grid(np.linspace(0, 1, cells + 1), np.array([-0.5, 0.5]))
    return Case(f"distributed_1d {pattern}", sample, grid, uniform,
                tilted(uniform, lambda t, _: 2 * t - 1), "5 % more towards 1")


PATTERNS = ("random", "jittered", "regular", "adaptive")
CASES = [disc_case(), cosine_case(), sphere_case(), *(lobe_case(e) for e in (1.0, 10.0, 1000.0)),
         rectangle_light_case(), time_case(),
         *(square_case(p) for p in PATTERNS), square_case("jittered", 4), square_case("poisson", 4),
         *(line_case(p) for p in (*PATTERNS, "poisson"))]
TESTS = len(CASES) + 1                       # and the poisson table's
LEVEL = significance(TESTS)
# The default run holds the glossy lobe (0.3 to 0.6 s a case, measured under load); the full
# run every case (about 7 s in all).
DEFAULT_CASES = {"square_to_phong_lobe e=10"}
PARAMS = [pytest.param(case, id=case.name, marks=[] if case.name in DEFAULT_CASES else [pytest.mark.slow])
          for case in CASES]


@pytest.mark.parametrize("case", PARAMS)
def test_samples_have_their_density_and_not_a_slightly_wrong_one(case):
    x, y = case.sample()
    grid = case.grid()
    observed, outside = histogram(x, y, grid)
    assert outside == 0, f"{case.name}: {outside} samples outside the domain"
    p = p_value(observed, expected_counts(case.density, grid, len(x)))
    assert p >= LEVEL, f"{case.name}: rejected, p = {p:.3g} < {LEVEL:.3g}"
    p_wrong = p_value(observed, expected_counts(case.wrong, grid, len(x)))
    assert p_wrong < LEVEL, f"{case.name}: {case.wrong_says} not rejected (p = {p_wrong:.3g})"


@pytest.mark.slow
def test_poisson_points_take_each_table_point_equally_often():
    """One point per sample under poisson: sample j of a pixel takes table point
    permute(j, n, key) (+ 0.5): over the pixels each of the n points equally often (chi-square
    with n - 1 degrees of freedom), and not 5 % more often the points towards x = 1."""
    sampling = ray_sampling("poisson", SAMPLES_PER_PIXEL)
    p = points_2d("poisson")
    table = np.minimum(sampling.table + np.float32(0.5), np.float32(1 - 2 ** -24))
    order = np.argsort(table[:, 0])
    which = order[np.minimum(np.searchsorted(table[order, 0], p[:, 0]), len(table) - 1)]
    assert (p == table[which]).all()
    observed = np.bincount(which, minlength=len(table))
    n = len(p)
    assert p_value(observed, np.full(len(table), n / len(table))) >= LEVEL
    weights = 1 + 0.05 * (2 * table[:, 0].astype(np.float64) - 1)
    assert p_value(observed, n * weights / weights.sum()) < LEVEL


# -- the GLSL's samples --------------------------------------------------------------------------

def test_glsl_warps_draw_the_twins_samples(gl_contexts):
    """Each warp of distributed_2d's points (2 samples of a 64 x 48 frame, a pattern with
    cells and one without) on EGL and OSMesa: the points bit for bit, the warped ones within
    WARP_EPS per component (the exponents 1 to 1e6; the orthonormal basis of a sphere
    direction)."""
    width, height = 64, 48
    y, x = np.mgrid[0:height, 0:width].astype(np.uint32)
    routines = {1: warp.square_to_disc, 2: warp.square_to_sphere,
                4: lambda u: warp.orthonormal_basis(warp.square_to_sphere(u))[0],
                5: lambda u: warp.orthonormal_basis(warp.square_to_sphere(u))[1],
                6: lambda u: warp.square_to_cosine_hemisphere(u)[..., :2]}
    exponents = (1.0, 10.0, 1000.0, 1e6)
    worst = 0.0
    for kind, ctx in gl_contexts.items():
        for pattern in ("random", "jittered"):
            sampling = ray_sampling(pattern, 4)
            with ShaderProbe(ctx, "raytrace_warp.frag", sampling_defines(sampling), (width, height), 4,
                             dtype="f4") as shader:
                shader.write(sampling.uniforms())
                for k in (0, 3):
                    u = distributed_2d(x, y, k, 5, sampling, 9, 0)
                    common = dict(u_first_sample=5, u_k=k, u_slot=9, u_dimension=0)
                    assert np.array_equal(shader.run(u_routine=0, **common)[..., :2], u), (kind, pattern)
                    cases = [(r, 0.0, f(u)) for r, f in routines.items()]
                    cases += [(3, e, warp.square_to_phong_lobe(u, np.float32(e))) for e in exponents]
                    for routine, exponent, expected in cases:
                        got = shader.run(u_routine=routine, u_exponent=exponent, **common)
                        error = np.abs(got[..., :expected.shape[-1]] - expected).max()
                        assert error <= WARP_EPS, (kind, pattern, k, routine, exponent, error / EPS32)
                        worst = max(worst, float(error))
                    # the cosine hemisphere's z = sqrt(1 - r^2): its few-ulp x and y move r^2 by
                    # up to 3 WARP_EPS, so z^2 (not z, steep at the rim) within that of the twin's
                    z_gpu = shader.run(u_routine=6, **common)[..., 2].astype(np.float64)
                    z_twin = warp.square_to_cosine_hemisphere(u)[..., 2].astype(np.float64)
                    assert np.abs(z_gpu ** 2 - z_twin ** 2).max() <= 3 * WARP_EPS, (kind, pattern, k)
    assert worst > 0                     # sin, cos, log, exp: not bit for bit (conventions.md)
