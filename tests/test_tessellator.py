"""The fixed-function tessellator's twin (reference/tessellation/tessellator.py, a port of
Mesa's D3D11 reference tessellator) against llvmpipe's, bit for bit.

llvmpipe's side is captured by transform feedback (tests/tessellation_capture.py,
glsl/tessellation/capture.*): one vertex a patch carries the patch's levels, the evaluation
shader hands on gl_TessCoord and gl_PrimitiveID, and the capture holds every primitive's
vertices in order. The twin's side is reference.tessellation.tessellator.captured_draw: each
patch's tess_coord at its primitives' indices, patch after patch, as llvmpipe's draw module
lays a draw out. They are compared as float32 bit patterns, with the primitive counts and the
patch each vertex belongs to; every failure names the first patch that differs and its levels.

First hand-checked cases (corners, level 1, fixed-point thirds, fractional_odd just above 1,
clamps and culling), each on both contexts; then a representative sweep (every domain and
spacing, both orders, point mode) in a few draws; then what one draw of many patches does on
llvmpipe 22.3.6 (runs of 4096 input vertices, uint16 element indices). The exhaustive sweep
(every integer level 1 .. 64 against a set of others, every eighth from 0 to 66, mixed per-edge
levels, special values) is marked slow, and so is every case's OSMesa run (the same llvmpipe
tessellator as EGL's; the full run holds both).
"""

import numpy as np
import pytest

from reference.tessellation.tessellator import (MAX_RUN_POINTS, PATCH_RUN_VERTICES, SPACINGS, captured_draw,
                                                patch_runs, primitive_vertices, run_points, tess_coord,
                                                tessellate)
from tests.tessellation_capture import VERTICES_PER_PRIMITIVE, capture

# OSMesa runs the same llvmpipe tessellator as EGL: its cases in the full run (the default run's budget)
CONTEXT_PARAMS = ["egl", pytest.param("osmesa", marks=pytest.mark.slow)]
DOMAINS = ("triangles", "quads", "isolines")
DENORMAL = float(np.float32(1e-40))


def twins_of(domain, spacing, levels, order="ccw", point_mode=False):
    return [tessellate(domain, spacing, patch[:4], patch[4:], order, point_mode) for patch in np.asarray(levels)]


def draws_of(twins, patch_vertices=1):
    """The patches cut into draws that llvmpipe draws whole (one run each, at most
    MAX_RUN_POINTS domain points): lists of patch numbers."""
    draws, current, points = [], [], 0
    for number, twin in enumerate(twins):
        if current and (points + len(twin.u) > MAX_RUN_POINTS or len(current) == PATCH_RUN_VERTICES // patch_vertices):
            draws.append(current)
            current, points = [], 0
        current.append(number)
        points += len(twin.u)
    return draws + [current] if current else draws


def assert_draw_matches(ctx, domain, spacing, levels, order="ccw", point_mode=False, patch_vertices=1,
                        twins=None) -> int:
    """One draw of the patches `levels` (N, 6), captured, equals the twin's, bit for bit.
    Returns the number of vertices compared."""
    levels = np.asarray(levels, dtype=np.float32).reshape(-1, 6)
    twins = twins_of(domain, spacing, levels, order, point_mode) if twins is None else twins
    expected = captured_draw(twins, patch_vertices)
    # one vertex of room more than expected: a GPU that makes more primitives shows it in `generated`
    got = capture(ctx, domain, spacing, levels, order, point_mode, capacity=len(expected.tess_coord) + 1,
                  patch_vertices=patch_vertices)
    per_primitive = VERTICES_PER_PRIMITIVE[got.primitive]
    where = f"{domain}, {spacing}, {order}{', point_mode' if point_mode else ''}"
    assert got.generated == got.written == len(expected.tess_coord) // per_primitive, (
        f"{where}: GL made {got.generated} primitives, the twin {len(expected.tess_coord) // per_primitive}"
        f"{first_difference(got, expected, levels)}")
    same = np.array_equal(got.tess_coord.view(np.uint32), expected.tess_coord.view(np.uint32))
    assert same and np.array_equal(got.patch_id, expected.primitive_id), \
        f"{where}: the capture differs from the twin{first_difference(got, expected, levels)}"
    return len(got.tess_coord)


def first_difference(got, expected, levels) -> str:
    """Where a capture first departs from the twin: the patch, its levels, the vertex."""
    count = min(len(got.tess_coord), len(expected.tess_coord))
    differs = (got.tess_coord[:count].view(np.uint32) != expected.tess_coord[:count].view(np.uint32)).any(axis=1)
    differs |= got.patch_id[:count] != expected.primitive_id[:count]
    if not differs.any():
        return f" (the first {count} vertices agree)"
    k = int(np.argmax(differs))
    patch = int(expected.patch[k])
    return (f"; first at vertex {k}, of patch {patch} (outer {levels[patch, :4].tolist()}, inner "
            f"{levels[patch, 4:].tolist()}): GL {got.tess_coord[k].tolist()} of patch id {got.patch_id[k]}, "
            f"the twin {expected.tess_coord[k].tolist()} of patch id {expected.primitive_id[k]}")


def assert_sweep_matches(ctx, domain, spacing, levels, order="ccw", point_mode=False, twins=None) -> int:
    """Every patch of `levels` drawn (in as few draws as llvmpipe draws whole) and compared."""
    levels = np.asarray(levels, dtype=np.float32).reshape(-1, 6)
    twins = twins_of(domain, spacing, levels, order, point_mode) if twins is None else twins
    return sum(assert_draw_matches(ctx, domain, spacing, levels[draw], order, point_mode,
                                   twins=[twins[p] for p in draw])
               for draw in draws_of(twins))


def row(outer, inner=()):
    """A patch's levels (6,) from its outer and inner levels (the rest 1)."""
    levels = np.ones(6, np.float32)
    levels[:len(outer)] = outer
    levels[4:4 + len(inner)] = inner
    return levels


# -- hand-checked cases ----------------------------------------------------------------------------

@pytest.mark.parametrize("kind", CONTEXT_PARAMS)
def test_a_quad_at_level_1_is_its_four_corners_and_two_triangles(gl_contexts, kind):
    quad = tessellate("quads", "equal_spacing", [1, 1, 1, 1], [1, 1])
    assert quad.u.tolist() == [0, 1, 1, 0] and quad.v.tolist() == [0, 0, 1, 1]
    assert quad.indices.tolist() == [0, 1, 3, 1, 2, 3] and quad.primitive == "triangles"
    # counter-clockwise in GL's domain (u right, v up): (0,0) (1,0) (0,1), then (1,0) (1,1) (0,1)
    assert primitive_vertices(quad).tolist() == [[0, 0, 0], [1, 0, 0], [0, 1, 0], [1, 0, 0], [1, 1, 0], [0, 1, 0]]
    assert tessellate("quads", "equal_spacing", [1] * 4, [1, 1], order="cw").indices.tolist() == [0, 3, 1, 1, 3, 2]
    for spacing in ("equal_spacing", "fractional_odd_spacing"):      # even spacing clamps 1 to 2
        for order in ("ccw", "cw"):
            assert_draw_matches(gl_contexts[kind], "quads", spacing, [row([1] * 4, [1, 1])], order)


@pytest.mark.parametrize("kind", CONTEXT_PARAMS)
def test_a_triangle_at_level_1_is_one_triangle(gl_contexts, kind):
    triangle = tessellate("triangles", "equal_spacing", [1, 1, 1], [1])
    # D3D's order: V = 1, then W = 1, then U = 1; gl_TessCoord's third is (1 - u) - v
    assert tess_coord(triangle).tolist() == [[0, 1, 0], [0, 0, 1], [1, 0, 0]]
    assert triangle.indices.tolist() == [0, 1, 2]
    assert tessellate("triangles", "equal_spacing", [1] * 3, [1], order="cw").indices.tolist() == [0, 2, 1]
    for order in ("ccw", "cw"):
        assert_draw_matches(gl_contexts[kind], "triangles", "equal_spacing", [row([1, 1, 1], [1])], order)


@pytest.mark.parametrize("kind", CONTEXT_PARAMS)
def test_equal_spacing_at_level_3_puts_the_edge_points_at_fixed_point_thirds(gl_contexts, kind):
    """Points are 15.16 fixed point: a third is 0x5555 / 65536 and two thirds 0xaaab / 65536
    (1 - 0x5555 / 65536, the far half mirrored), not float32(1 / 3) and float32(2 / 3)."""
    thirds = np.array([0, 0x5555, 0xAAAB, 0x10000], np.float32) / np.float32(65536)
    line = tessellate("isolines", "equal_spacing", [1, 3])
    assert np.array_equal(line.u, thirds) and line.v.tolist() == [0, 0, 0, 0]
    assert line.indices.tolist() == [0, 1, 1, 2, 2, 3] and line.primitive == "lines"
    assert line.u[1] != np.float32(1 / 3) and line.u[2] != np.float32(2 / 3)
    quad = tessellate("quads", "equal_spacing", [3] * 4, [3, 3])
    assert len(quad.u) == 16 and set(quad.u.tolist()) == set(thirds.tolist())
    assert_draw_matches(gl_contexts[kind], "isolines", "equal_spacing", [row([1, 3])])
    assert_draw_matches(gl_contexts[kind], "quads", "equal_spacing", [row([3] * 4, [3, 3])])


@pytest.mark.parametrize("kind", CONTEXT_PARAMS)
def test_fractional_odd_at_level_1_and_just_above(gl_contexts, kind):
    """fractional_odd at all levels 1 is the bare triangle; an outer level that stays 1 in
    fixed point (1 + 2^-17 rounds to 0x10000) too; the next float32 above, 0x10001 in fixed
    point, forces the inner level to 1 + 2^-16, a "picture frame" of 8 points and 9 triangles
    whose new points all fall on the corners (their tiny segments round to nothing in 16-bit
    fixed point): 6 of the triangles have no area."""
    half_epsilon = 1 + 2.0 ** -17
    above = float(np.nextafter(np.float32(half_epsilon), np.float32(2)))
    levels = [row([1, 1, 1], [1]), row([half_epsilon, 1, 1], [1]), row([above, 1, 1], [1])]
    counts = [(len(t.u), len(t.indices) // 3) for t in twins_of("triangles", "fractional_odd_spacing", levels)]
    assert counts == [(3, 1), (3, 1), (8, 9)]
    raised = tessellate("triangles", "fractional_odd_spacing", [above, 1, 1], [1])
    assert raised.u[:4].tolist() == [0, 0, 0, 0] and raised.v[:4].tolist() == [1, 1, 0, 0]   # the raised edge
    assert set(zip(raised.u.tolist(), raised.v.tolist())) == {(0, 1), (0, 0), (1, 0)}
    assert_draw_matches(gl_contexts[kind], "triangles", "fractional_odd_spacing", levels)


@pytest.mark.parametrize("kind", CONTEXT_PARAMS)
def test_levels_are_clamped_and_an_outer_level_of_zero_or_nan_culls_the_patch(gl_contexts, kind):
    """An outer level the domain reads <= 0 or NaN culls the patch; so does a denormal one
    (llvmpipe draws with denormals as zero: D3D's C alone would keep it); an unread outer level
    (quads read 4, triangles 3, isolines 2) does not. An inner NaN is the lower bound (1, or 2
    for even spacing); a level above 64 (63 for fractional_odd), infinity included, clamps."""
    ctx = gl_contexts[kind]
    culling = [0.0, -0.0, -1.0, float("nan"), -float("inf"), DENORMAL]
    for domain, read in (("quads", 4), ("triangles", 3), ("isolines", 2)):
        for spacing in SPACINGS:
            unread = row([5] * read + [0.0] * (4 - read), [5, 5])     # zeros past what is read
            levels = [unread, *[row([5] * k + [bad] + [5] * (read - 1 - k), [5, 5])
                                for bad in culling for k in range(read)]]
            twins = twins_of(domain, spacing, levels)
            assert len(twins[0].u) > 0 and all(len(t.u) == 0 and len(t.indices) == 0 for t in twins[1:])
            assert_draw_matches(ctx, domain, spacing, levels)
    for spacing, lower, upper in (("equal_spacing", 1, 64), ("fractional_even_spacing", 2, 64),
                                  ("fractional_odd_spacing", 1, 63)):
        for domain in ("quads", "triangles"):
            def points(outer, inner):
                t = tessellate(domain, spacing, outer, inner)
                return primitive_vertices(t).view(np.uint32).tolist()
            assert points([7] * 4, [float("nan")] * 2) == points([7] * 4, [lower] * 2)
            assert points([70] * 4, [1e9] * 2) == points([upper] * 4, [upper] * 2)
            assert points([float("inf")] * 4, [float("inf")] * 2) == points([upper] * 4, [upper] * 2)
            assert_draw_matches(ctx, domain, spacing, [row([7] * 4, [float("nan")] * 2), row([70] * 4, [1e9] * 2),
                                                       row([float("inf")] * 4, [float("inf")] * 2),
                                                       row([7, 9, 11, 13], [DENORMAL, -3])])


# -- the sweep ---------------------------------------------------------------------------------------

def representative_levels() -> np.ndarray:
    """About 40 patches: uniform integer levels (both parities, 1, 2, 3, 63, 64), uniform
    fractional ones, and mixed per-edge levels, integer and fractional."""
    rng = np.random.default_rng(34)
    uniform = [1, 2, 3, 4, 5, 6, 7, 8, 15, 16, 17, 31, 32, 33, 62, 63, 64,
               1.5, 2.25, 2.999, 3.5, 4.75, 7.1, 12.5, 33.3, 63.9]
    mixed_integer = rng.integers(1, 65, size=(8, 6))
    mixed_fractional = rng.uniform(0.5, 66, size=(8, 6))
    return np.concatenate([np.repeat(np.array(uniform, np.float32)[:, None], 6, axis=1),
                           mixed_integer, mixed_fractional]).astype(np.float32)


@pytest.mark.parametrize("domain", DOMAINS)
@pytest.mark.parametrize("kind", CONTEXT_PARAMS)
def test_the_twin_tessellates_as_llvmpipe_does(gl_contexts, kind, domain):
    """Every spacing, counter-clockwise over the representative levels; clockwise and point
    mode over a few of them."""
    ctx, levels = gl_contexts[kind], representative_levels()
    for spacing in SPACINGS:
        assert_sweep_matches(ctx, domain, spacing, levels)
        assert_sweep_matches(ctx, domain, spacing, levels[::5], order="cw")
        assert_sweep_matches(ctx, domain, spacing, levels[::5], point_mode=True)


GRID = (1, 2, 3, 4, 5, 7, 8, 16, 17, 32, 33, 63, 64)     # the other level, against every integer


def exhaustive_levels(domain: str) -> np.ndarray:
    """Every integer level 1 .. 64 uniform; every eighth from 0 to 66 uniform; every integer
    outer level against each of GRID inner (isolines: density against detail) and back; 500
    mixed per-edge integer and 500 mixed fractional sets, 200 below 4 (where fractional_odd
    draws its picture frame), and 300 of special values (0, -0, NaN, infinities, a denormal,
    1 + 2^-17 and its neighbours, 63.5, 64.5, 1e9) mixed."""
    rng = np.random.default_rng(3400)
    integers = np.arange(1, 65, dtype=np.float32)
    eighths = np.arange(0, 66 * 8 + 1, dtype=np.float32) / 8
    pairs = [(a, b) for a in integers for b in GRID] + [(a, b) for a in GRID for b in integers if b not in GRID]
    if domain == "isolines":
        grid = [row([a, b]) for a, b in pairs]
    else:
        grid = [row([a] * 4, [b, b]) for a, b in pairs]
    specials = np.array([0, -0.0, -1, np.nan, np.inf, -np.inf, DENORMAL, 1, 1 + 2 ** -17,
                         np.nextafter(np.float32(1 + 2 ** -17), np.float32(2)), 1 + 2 ** -16, 2 - 2 ** -22,
                         2, 2 + 2 ** -16, 3, 62.5, 63, 63.5, 64, 64.5, 65, 1e9, 0.5, 1.5], np.float32)
    return np.concatenate([np.repeat(integers[:, None], 6, axis=1), np.repeat(eighths[:, None], 6, axis=1),
                           np.array(grid, np.float32), rng.integers(1, 65, size=(200, 6)),
                           rng.uniform(0, 66, size=(200, 6)), rng.uniform(0, 4, size=(200, 6)),
                           rng.choice(specials, size=(300, 6))]).astype(np.float32)


@pytest.mark.slow
@pytest.mark.parametrize("spacing", SPACINGS)
@pytest.mark.parametrize("domain", DOMAINS)
def test_the_twin_tessellates_as_llvmpipe_does_exhaustively(gl_contexts, domain, spacing):
    """2,988 level sets counter-clockwise, every eighth of them clockwise (not isolines) and
    in point mode, on EGL (OSMesa runs the same llvmpipe tessellator; the representative sweep
    above holds it on both)."""
    levels = exhaustive_levels(domain)
    variants = [(levels, "ccw", False), (levels[::8], "ccw", True)]
    if domain != "isolines":
        variants.append((levels[::8], "cw", False))
    for some, order, point_mode in variants:
        twins = twins_of(domain, spacing, some, order, point_mode)
        assert_sweep_matches(gl_contexts["egl"], domain, spacing, some, order, point_mode, twins=twins)


# -- one draw of many patches ------------------------------------------------------------------------

@pytest.mark.parametrize("kind", CONTEXT_PARAMS)
def test_a_draw_past_65536_domain_points_wraps_its_uint16_element_indices(gl_contexts, kind):
    """draw_tess.c stores each primitive vertex's element index, the patch's first point's
    number in the draw plus its index, as a uint16. 16 quads at level 63 (4096 points each)
    are 65,536 points, the last index 65,535: exact. A 17th patch's indices wrap to 0 ..
    4095: its primitives are drawn with the first patch's points (its own evaluation-shader
    outputs are never read), and the renderer must split such draws."""
    ctx = gl_contexts[kind]
    level_63 = row([63] * 4, [63, 63])
    quad = tessellate("quads", "equal_spacing", level_63[:4], level_63[4:])
    assert len(quad.u) == 4096
    assert run_points([quad] * 16) == [MAX_RUN_POINTS]
    exact = captured_draw([quad] * 16)
    assert np.array_equal(exact.patch, np.repeat(np.arange(16), len(quad.indices)))
    assert_draw_matches(ctx, "quads", "equal_spacing", [level_63] * 16)

    wrapped = captured_draw([quad] * 17)
    last = wrapped.patch[16 * len(quad.indices):]
    assert len(last) == len(quad.indices) and (last == 0).all()      # the 17th draws with patch 0's points
    assert_draw_matches(ctx, "quads", "equal_spacing", [level_63] * 17)
    # mixed patches: wrong from the first patch whose points pass 65,536
    levels = representative_levels()
    big = np.concatenate([levels, levels, levels])
    twins = twins_of("quads", "fractional_odd_spacing", big)
    assert run_points(twins)[0] > MAX_RUN_POINTS
    assert_draw_matches(ctx, "quads", "fractional_odd_spacing", big, twins=twins)


@pytest.mark.parametrize("kind", CONTEXT_PARAMS)
def test_a_draw_is_cut_into_runs_of_4096_input_vertices_and_gl_primitive_id_restarts_in_each(gl_contexts, kind):
    """llvmpipe tessellates a draw of patches in runs of 4096 // GL_PATCH_VERTICES patches;
    each run's points and element indices start again from 0, and so does gl_PrimitiveID in
    the evaluation shader (GL counts it from the draw's first patch)."""
    ctx = gl_contexts[kind]
    assert [len(run) for run in patch_runs(9000)] == [4096, 4096, 808]
    assert [len(run) for run in patch_runs(4500, patch_vertices=3)] == [1365, 1365, 1365, 405]
    rng = np.random.default_rng(7)
    levels = np.concatenate([rng.integers(1, 4, size=(4500, 4)), rng.integers(1, 3, size=(4500, 2))],
                            axis=1).astype(np.float32)
    twins = twins_of("quads", "equal_spacing", levels)
    model = captured_draw(twins)
    assert model.primitive_id[model.patch == 4096].max() == 0
    for patch_vertices in (1, 3, 32):
        assert_draw_matches(ctx, "quads", "equal_spacing", levels, patch_vertices=patch_vertices, twins=twins)
    # runs of 4096 patches of 25 points each: the first run passes 65,536 points at patch 2,621
    level_4 = row([4] * 4, [4, 4])
    assert run_points(twins_of("quads", "equal_spacing", [level_4] * 4200)) == [4096 * 25, 104 * 25]
    assert_draw_matches(ctx, "quads", "equal_spacing", [level_4] * 4200)
