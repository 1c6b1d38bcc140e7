"""Ray intersections (glsl/raytrace/intersect.glsl, reference/raytrace/intersect.py): cases
worked out by hand, the robust sphere form against the textbook quadratic, and the GLSL on
llvmpipe (EGL, OSMesa; float32) against the NumPy twin in float32 for seeded random rays."""

from fractions import Fraction

import numpy as np
import pytest

from glsl_harness import float_probe
from reference.raytrace.intersect import (plane_normal, ray_plane, ray_sphere, ray_triangle,
                                          sphere_discriminant, sphere_normal, triangle_normal)

INF = np.inf
F32 = np.float32
EPS32 = float(np.finfo(np.float32).eps)


def rays(*pairs, dtype=np.float64):
    """(O, D) arrays from (origin, direction) pairs."""
    return (np.array([p[0] for p in pairs], dtype=dtype), np.array([p[1] for p in pairs], dtype=dtype))


# -- sphere --------------------------------------------------------------------------------------

def test_sphere_from_outside_inside_grazing_and_miss():
    O, D = rays(((0, 0, 5), (0, 0, -1)),        # from outside: the near root, z = 1
                ((0, 0, 5), (0, 0, -2)),        # D not unit: s in units of |D|
                ((0, 0, 0), (0, 0, 1)),         # from the centre: the far root
                ((0, 0, 0.5), (0, 0, -1)),      # from inside, off centre: z = -1 at s = 1.5
                ((-5, 1, 0), (1, 0, 0)),        # grazing: tangent at (0, 1, 0), delta exactly 0
                ((-5, 1.5, 0), (1, 0, 0)),      # misses by 0.5
                ((0, 0, 5), (0, 0, 1)))         # sphere behind the origin
    hit, s = ray_sphere(O, D, (0, 0, 0), 1.0, 0.0, INF)
    assert hit.tolist() == [True, True, True, True, True, False, False]
    assert s.tolist() == [4.0, 2.0, 1.0, 1.5, 5.0, INF, INF]
    assert sphere_discriminant(O[4], D[4], (0, 0, 0), 1.0) == 0.0
    P = O[:5] + s[:5, None] * D[:5]
    assert sphere_normal(P, np.zeros(3), 1.0).tolist() == [[0, 0, 1], [0, 0, 1], [0, 0, 1],
                                                           [0, 0, -1], [0, 1, 0]]
    # s_min / s_max are open: a hit at exactly s_max (or s_min) is refused; with s_min past the
    # near root the far root is the hit
    assert ray_sphere(O[:1], D[:1], (0, 0, 0), 1.0, 0.0, 4.0)[0].tolist() == [False]
    assert ray_sphere(O[:1], D[:1], (0, 0, 0), 1.0, 4.0, INF)[1].tolist() == [6.0]
    assert ray_sphere(O[:1], D[:1], (0, 0, 0), 1.0, 0.0, 3.0)[1].tolist() == [3.0]   # miss: s_max


def exact_near_root(O, D, C, r) -> float:
    """The near root of |O + s D - C|^2 = r^2 for the float32 inputs, in exact rational
    arithmetic up to one final square root in float64 (55 digits: far more than float32's)."""
    from decimal import Decimal, getcontext
    getcontext().prec = 55
    O, D, C = ([Fraction(float(x)) for x in v] for v in (O, D, C))
    r = Fraction(float(r))
    f = [o - c for o, c in zip(O, C)]
    a, b = sum(d * d for d in D), sum(x * d for x, d in zip(f, D))
    c = sum(x * x for x in f) - r * r
    dec = lambda q: Decimal(q.numerator) / Decimal(q.denominator)  # noqa: E731
    return float((-dec(b) - dec(b * b - a * c).sqrt()) / dec(a))


def textbook_near_root(O, D, C, r) -> float:
    """The textbook quadratic in float32: (-b - sqrt(b^2 - a c)) / a, b = (O - C).D."""
    O, D, C, r = (np.asarray(v, F32) for v in (O, D, C, r))
    f = O - C
    a, b, c = D @ D, f @ D, f @ f - r * r
    return float((-b - np.sqrt(b * b - a * c)) / a)


@pytest.mark.parametrize("C, r, textbook_ulps", [
    # tiny sphere 100 away, the ray 5e-5 off its centre: exact s = 99.99991339746...; the textbook
    # b^2 - ac = 1e4 - (1e4 + 2.5e-9 - 1e-8) loses r^2 entirely in float32 (c rounds to 1e4):
    # s = 100.0, 11 ulps (8.7e-5, most of the radius) off; the robust form is within 1 ulp
    ((0, 5e-5, -100), 1e-4, 11),
    # huge sphere 1e6 away, the ray 9990 off its centre (near its rim): exact s = 999552.898...;
    # the textbook gives 999556.6 (60 ulps, 3.7 units off); the robust form is within 1 ulp
    ((0, 9990, -1e6), 1e4, 60),
])
def test_robust_sphere_keeps_the_digits_the_textbook_loses(C, r, textbook_ulps):
    O, D = np.zeros((1, 3), F32), np.array([[0, 0, -1]], F32)
    C, r = np.array(C, F32), F32(r)
    exact = exact_near_root(O[0], D[0], C, r)
    ulp = float(np.spacing(F32(exact)))
    hit, s = ray_sphere(O, D, C, r, F32(0), F32(INF))
    assert hit[0] and s.dtype == np.float32
    robust_error = abs(float(s[0]) - exact)
    textbook_error = abs(textbook_near_root(O[0], D[0], C, r) - exact)
    assert robust_error <= ulp, (robust_error / ulp, "ulps off")
    assert round(textbook_error / ulp) == textbook_ulps, textbook_error / ulp


def test_any_float_dtype_and_batch_shapes():
    O = np.zeros((2, 3, 3))
    D = np.broadcast_to(np.array([0, 0, 1.0]), (2, 3, 3))
    for dtype in (np.float16, np.float32, np.float64):
        hit, s = ray_sphere(O.astype(dtype), D.astype(dtype), (0, 0, 4), 1, 0, INF)
        assert hit.shape == (2, 3) and hit.all() and s.dtype == dtype and (s == 3).all()


# -- plane ---------------------------------------------------------------------------------------

def test_plane_hit_parallel_behind_and_not_unit_normal():
    # the plane z = 1 written as P.N + d = 0 with N = (0, 0, 2), d = -2 (N need not be unit)
    O, D = rays(((0, 0, 5), (0, 0, -1)),        # hit at s = 4
                ((3, 4, 5), (1, 1, -2)),        # oblique: s = 2, P = (5, 6, 1)
                ((0, 0, 5), (1, 0, 0)),         # parallel: miss
                ((0, 0, 1), (1, 0, 0)),         # in the plane: miss
                ((0, 0, 5), (0, 0, 1)))         # plane behind the origin (s = -4): refused
    hit, s = ray_plane(O, D, (0, 0, 2), -2, 0.0, INF)
    assert hit.tolist() == [True, True, False, False, False]
    assert s.tolist() == [4.0, 2.0, INF, INF, INF]
    assert ray_plane(O[4:], D[4:], (0, 0, 2), -2, -10.0, INF)[1].tolist() == [-4.0]  # if allowed
    assert plane_normal((0, 0, 2)).tolist() == [0, 0, 1]


# -- triangle ------------------------------------------------------------------------------------

A, B, C = (0, 0, 0), (1, 0, 0), (0, 1, 0)


def test_triangle_inside_edges_vertices_parallel():
    # Every case is exact in binary floating point (det = 1): the rule is what decides.
    down = (0, 0, -1)
    O, D = rays(((0.25, 0.25, 1), down),        # inside: u = v = 0.25
                ((0.5, 0, 1), down),            # on edge AB (v = 0): hit
                ((0, 0.5, 1), down),            # on edge AC (u = 0): hit
                ((0.5, 0.5, 1), down),          # on edge BC (u + v = 1): hit
                ((0, 0, 1), down),              # vertex A: hit
                ((1, 0, 1), down),              # vertex B: hit
                ((0, 1, 1), down),              # vertex C: hit
                ((0.5, -2.0**-20, 1), down),    # just outside AB: miss
                ((0.75, 0.5, 1), down),         # beyond BC: miss
                ((0.25, 0.25, -1), (0, 0, 1)),  # from the back face: hit (both faces)
                ((0.25, 0.25, 1), (1, 0, 0)),   # parallel to the plane: miss (det = 0)
                ((0.25, 0.25, 0), (1, 1, 0)),   # inside the plane: miss (det = 0)
                ((0.25, 0.25, 1), (0, 0, 1)))   # triangle behind: refused
    hit, s, uv = ray_triangle(O, D, A, B, C, 0.0, INF)
    assert hit.tolist() == [True] * 7 + [False, False, True, False, False, False]
    assert s.tolist() == [1.0] * 7 + [INF, INF, 1.0, INF, INF, INF]
    assert uv[:7].tolist() == [[0.25, 0.25], [0.5, 0], [0, 0.5], [0.5, 0.5], [0, 0], [1, 0], [0, 1]]
    P = O[:7] + s[:7, None] * D[:7]
    barycentric = (1 - uv[:7].sum(-1))[:, None] * A + uv[:7, :1] * B + uv[:7, 1:] * C
    assert (P == barycentric).all()
    assert triangle_normal(A, B, C).tolist() == [0, 0, 1]
    assert not ray_triangle(O[:1], D[:1], A, B, (2, 0, 0), 0, INF)[0][0]   # degenerate: miss


# -- the GLSL against the twin -------------------------------------------------------------------

WIDTH, HEIGHT = 128, 64                         # 8192 rays
SCENE = {"u_center": (0.25, -0.5, 0.125), "u_radius": 1.5, "u_plane_normal": (0.3, 1.0, -0.2),
         "u_plane_d": 0.7, "u_a": (-2.0, -1.0, 0.5), "u_b": (2.0, -1.5, 0.0), "u_c": (0.0, 2.0, -0.5),
         "u_s_min": 0.0, "u_s_max": 1e30}
K = 8                                           # rounding-error bound: K units of float32 eps
ULPS = 4                                        # the plain relative tolerance most hits meet


def seeded_rays():
    rng = np.random.default_rng(14)
    O = rng.uniform(-3, 3, (HEIGHT, WIDTH, 3)).astype(F32)
    D = (rng.normal(size=(HEIGHT, WIDTH, 3)) * rng.uniform(0.25, 4, (HEIGHT, WIDTH, 1))).astype(F32)
    return O, D


def gpu_intersections(ctx, O, D):
    """(out_s, out_extra, out_uv) of tests/glsl/raytrace_intersect.frag, (HEIGHT, WIDTH, 4) each."""
    return float_probe(ctx, "raytrace_intersect.frag", {"u_origins": O, "u_directions": D}, outputs=3,
                       uniforms=SCENE)


def norm(v):
    return np.sqrt((np.asarray(v, np.float64) ** 2).sum(-1))


def test_glsl_intersections_agree_with_the_float32_twin(gl_contexts):
    """Hit or miss agree exactly but where the decision is within float32 rounding of its
    boundary (the sphere's delta, a triangle's edge, the plane's D.N); s agrees within K eps32
    times the forward rounding-error bound of its formula (llvmpipe may fuse multiply-adds and
    divide through a reciprocal, the twin does neither), which is ULPS ulps for most hits but
    more where a dot product cancels (near-grazing spheres, near-parallel planes)."""
    O, D = seeded_rays()
    p = {name: np.asarray(value, F32) for name, value in SCENE.items()}
    s_min, s_max = p["u_s_min"], p["u_s_max"]
    center, radius = p["u_center"], p["u_radius"]
    sphere_hit, sphere_s = ray_sphere(O, D, center, radius, s_min, s_max)
    plane_hit, plane_s = ray_plane(O, D, p["u_plane_normal"], p["u_plane_d"], s_min, s_max)
    tri_hit, tri_s, tri_uv = ray_triangle(O, D, p["u_a"], p["u_b"], p["u_c"], s_min, s_max)
    assert 0.1 < sphere_hit.mean() < 0.3 and 0.3 < plane_hit.mean() < 0.7 and 0.02 < tri_hit.mean()

    # forward error bounds (float64), in units of eps32 after multiplying by K
    O64, D64 = O.astype(np.float64), D.astype(np.float64)
    f = O64 - center
    a = norm(D64) ** 2
    delta64 = sphere_discriminant(O64, D64, center.astype(np.float64), float(radius))
    with np.errstate(invalid="ignore", divide="ignore"):
        closest = f - ((f * D64).sum(-1) / a)[..., None] * D64    # centre to ray: |l| <= r at hits
    delta_scale = float(radius) ** 2 + norm(closest) * norm(f)
    with np.errstate(divide="ignore"):
        sphere_bound = (np.abs(sphere_s) + np.abs(f * D64).sum(-1) / a
                        + delta_scale / (2 * np.sqrt(a * np.maximum(delta64, 0))))
        N = p["u_plane_normal"].astype(np.float64)
        DN = D64 @ N
        plane_bound = ((norm(O64) * norm(N) + abs(float(p["u_plane_d"]))) / np.abs(DN)
                       + np.abs(plane_s) * (1 + norm(D64) * norm(N) / np.abs(DN)))
        e1, e2 = p["u_b"] - p["u_a"], p["u_c"] - p["u_a"]
        t = O64 - p["u_a"]
        det = np.cross(D64, e2) @ e1
        tri_bound = (norm(e2) * norm(t) * norm(e1) + np.abs(tri_s) * norm(e1) * norm(D64) * norm(e2)) / np.abs(det)
        u = (t * np.cross(D64, e2)).sum(-1) / det
        v = (D64 * np.cross(t, e1)).sum(-1) / det
        uv_bound = (norm(t) + norm(e1) + norm(e2)) * norm(D64) * max(norm(e1), norm(e2)) / np.abs(det)
    edge_distance = np.minimum(np.minimum(np.abs(u), np.abs(v)), np.abs(1 - u - v))
    boundary = {
        "sphere": np.abs(delta64) <= K * EPS32 * delta_scale,
        "plane": np.abs(DN) <= K * EPS32 * norm(D64) * norm(N),
        "triangle": edge_distance <= K * EPS32 * uv_bound,
    }
    twin = {"sphere": (sphere_hit, sphere_s, sphere_bound), "plane": (plane_hit, plane_s, plane_bound),
            "triangle": (tri_hit, tri_s, tri_bound)}
    for kind, ctx in gl_contexts.items():
        out_s, out_extra, out_uv = gpu_intersections(ctx, O, D)
        mask = out_s[..., 3].astype(int)
        for column, (name, (hit, s, bound)) in enumerate(twin.items()):
            gpu_hit = (mask >> column) & 1 == 1
            disagree = gpu_hit != hit
            assert not (disagree & ~boundary[name]).any(), (kind, name, "hit/miss off the boundary")
            assert disagree.sum() <= 0.001 * hit.size, (kind, name, disagree.sum())
            both = gpu_hit & hit
            error = np.abs(out_s[..., column][both].astype(np.float64) - s[both])
            assert (error <= K * EPS32 * bound[both]).all(), (kind, name, error.max())
            ulps = error / np.spacing(np.abs(s[both]))
            assert (ulps > ULPS).mean() < 0.05, (kind, name, (ulps > ULPS).sum())
            assert (out_s[..., column][~gpu_hit] == F32(SCENE["u_s_max"])).all()      # s_max on a miss
        # the triangle's (u, v) and the sphere's normal at the hit, where both hit
        both = ((mask & 4) == 4) & tri_hit
        uv_error = np.abs(out_uv[..., :2][both] - tri_uv[both]).max(-1)
        assert (uv_error <= K * EPS32 * uv_bound[both]).all(), (kind, uv_error.max())
        both = ((mask & 1) == 1) & sphere_hit
        normal = sphere_normal(O + sphere_s[..., None] * D, center, radius)
        normal_error = norm(out_extra[..., :3][both] - normal[both])
        normal_bound = K * EPS32 * (norm(D64[both]) * sphere_bound[both] + 3 * norm(f[both]) + 3) / radius
        assert (normal_error <= normal_bound).all(), (kind, normal_error.max())
        assert np.allclose(norm(normal[both]), 1, atol=1e-5)


def test_glsl_intersections_are_the_float32_twins_bit_for_bit(gl_contexts):
    """With the twin's dot summed as llvmpipe sums GLSL's (z first: reference/glsl_builtins.py's dot), every
    probe ray's hit or miss, s and the triangle's (u, v) are the GPU's exactly (summed x first,
    only 58 % of the triangle's s and 34 % of its (u, v) were)."""
    O, D = seeded_rays()
    p = {name: np.asarray(value, F32) for name, value in SCENE.items()}
    s_min, s_max = p["u_s_min"], p["u_s_max"]
    twin = [ray_sphere(O, D, p["u_center"], p["u_radius"], s_min, s_max),
            ray_plane(O, D, p["u_plane_normal"], p["u_plane_d"], s_min, s_max),
            ray_triangle(O, D, p["u_a"], p["u_b"], p["u_c"], s_min, s_max)]
    for kind, ctx in gl_contexts.items():
        out_s, _, out_uv = gpu_intersections(ctx, O, D)
        mask = out_s[..., 3].astype(int)
        for column, (hit, s, *uv) in enumerate(twin):
            assert np.array_equal((mask >> column) & 1 == 1, hit), (kind, column)
            assert np.array_equal(out_s[..., column], s), (kind, column)
        assert np.array_equal(out_uv[..., :2], twin[2][2]), kind
