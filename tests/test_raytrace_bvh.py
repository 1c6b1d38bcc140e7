"""The BVH (renderer/core/bvh.py: binned SAH build and flat layout; glsl/raytrace/bvh.glsl and
its twin reference/raytrace/bvh.py: closest-hit traversal): a tiny layout checked by hand, the
builder's invariants, the twin against brute force (every ray against every triangle) on seeded
random rays for a triangle soup and the 20,480-triangle icosphere, and the GLSL on llvmpipe
(EGL, OSMesa) against the twin.

Ties: a ray through an edge or vertex that triangles share hits them all at the same s (docs/
conventions.md, "Rays"). The closest hit is then the lowest original index among them, whatever
order a walk meets them in (the GPU's depth first, the twin's level by level): a corner where
two walls meet is the case (test_a_tie_goes_to_the_lowest_index_whatever_the_walk). Where the
GPU's s is an ulp off the twin's, two answers may still name different triangles: each must be
hit by the ray at the other's s (within the GPU tolerance)."""

from pathlib import Path

import numpy as np
import pytest

from reference.raytrace.bvh import any_hit, closest_hit, closest_hit_brute_force, inverse_direction, ray_box
from reference.raytrace.intersect import ray_triangle
from renderer.core.bvh import (EMPTY, MAX_DEPTH, MAX_LEAF_SIZE, Bvh, build_bvh, forest, mesh_vertices,
                                node_depths, refit, roots, texels, walk_layout)
from renderer.core.builtin import builtin_scenes
from renderer.core.scene_file import load_scene
from renderer.core.primitives import icosphere

GLSL = Path(__file__).parent / "glsl"
F32 = np.float32
EPS32 = float(np.finfo(np.float32).eps)
INF = np.inf
K = 8                               # the GPU tolerance of tests/test_raytrace_intersect.py


# -- a tiny layout by hand ---------------------------------------------------------------------

TWO = np.array([[(4, 0, 0), (5, 0, 0), (4, 1, 0)],          # original 0, right of x = 2
                [(0, 0, 0), (1, 0, 0), (0, 1, 0)]], F32)     # original 1, left

HAND = Bvh(nodes=np.array([
    [[0, 0, 0, 2], [5, 1, 0, 0]],       # 0: interior, bounds (0,0,0)-(5,1,0); left 1, right 2
    [[0, 0, 0, 0], [1, 1, 0, 1]],       # 1: leaf, triangle 0 (original 1)
    [[4, 0, 0, 1], [5, 1, 0, 1]],       # 2: leaf, triangle 1 (original 0)
], F32), triangles=np.array([
    [[0, 0, 0, 1], [1, 0, 0, 0], [0, 1, 0, 0]],
    [[4, 0, 0, 0], [5, 0, 0, 0], [4, 1, 0, 0]],
], F32), depth=1)


def test_the_builder_makes_the_hand_written_layout():
    bvh = build_bvh(TWO, max_leaf_size=1)
    assert bvh.nodes.tolist() == HAND.nodes.tolist()
    assert bvh.triangles.tolist() == HAND.triangles.tolist()
    assert bvh.depth == 1 and bvh.original_index.tolist() == [1, 0]
    # with leaves of up to 4 (the default) two triangles are one leaf, in their own order
    assert build_bvh(TWO).nodes.tolist() == [[[0, 0, 0, 0], [5, 1, 0, 2]]]
    assert build_bvh(TWO).original_index.tolist() == [0, 1]
    # texels: node i at texels 2i, 2i + 1, row by row
    assert texels(HAND.nodes, width=4).shape == (2, 4, 4)
    assert texels(HAND.nodes, width=4)[1, 1].tolist() == HAND.nodes[2, 1].tolist()
    assert texels(HAND.nodes, width=4)[1, 2:].tolist() == [[0] * 4] * 2


def decoded_walk(walk):
    """The Walk's entries read back as the GLSL reads them (bvh_children, bvh_meets_root): each
    entry's four children's decoded boxes (float32) and refs; each entry read as a root's
    (min, max, ref)."""
    e = walk.entries
    words = e.view(np.int32)
    byte = lambda w, c: ((w.astype(np.int64) >> (8 * c)) & 0xFF).astype(F32)
    origin = e[:, 0, :3].view(F32)
    lo_words = e[:, 1, :3]
    hi_words = np.stack([e[:, 1, 3], e[:, 2, 0], e[:, 2, 1]], 1)
    with np.errstate(over="ignore", invalid="ignore"):      # the roots' rows are not quantised
        step = np.ldexp(F32(1), ((e[:, 0, 3:4].astype(np.int64) >> np.array([0, 8, 16])) & 0xFF) - 127).astype(F32)
        lo = np.stack([origin + byte(lo_words, c) * step for c in range(4)], 1).astype(F32)
        hi = np.stack([origin + byte(hi_words, c) * step for c in range(4)], 1).astype(F32)
    refs = np.concatenate([words[:, 2, 2:], words[:, 3, :2]], 1)
    return lo, hi, refs, origin, e[:, 1, :3].view(F32), words[:, 0, 3]


def test_the_walk_layout_holds_the_tree_four_children_a_step():
    """walk_layout (the GLSL's layout, renderer/core/bvh.py Walk): the root first, unquantised;
    then each even-depth interior node with its children, or an interior child's two children,
    in the tree's order; every leaf of the tree is one child of one entry, and each decoded box
    holds its node's box (quantised outwards) and is no more than a step wider on each side."""
    for vertices in (soup(500, 3), grid_triangles(12), TWO):
        bvh = build_bvh(vertices)
        walk = walk_layout(bvh)
        lo, hi, refs, root_min, root_max, root_ref = decoded_walk(walk)
        assert walk.entries.dtype == np.uint32 and walk.entries.shape[1:] == (4, 4)
        assert root_min[0].tolist() == bvh.bounds_min[0].tolist() and root_max[0].tolist() == bvh.bounds_max[0].tolist()
        leaf = bvh.is_leaf
        first, count = bvh.nodes[:, 0, 3].astype(int), bvh.nodes[:, 1, 3].astype(int)
        # walk the entries from the root, recording the binary nodes each child stands for
        seen_leaves = []
        depth = node_depths(bvh)
        node_of_entry = {1 + k: n for k, n in enumerate(np.flatnonzero(~leaf & (depth % 2 == 0)))}
        if leaf[0]:
            assert root_ref[0] == -1 and len(walk.entries) == 1
            seen_leaves.append(0)
        for entry, n in node_of_entry.items():
            children = []
            for child in (n + 1, first[n]):
                children += [child + 1, first[child]] if not leaf[child] else [child, None]
            for c, node in enumerate(children):
                if node is None:
                    assert refs[entry, c] == EMPTY
                    continue
                assert np.all(lo[entry, c] <= bvh.bounds_min[node]) and np.all(hi[entry, c] >= bvh.bounds_max[node])
                step = np.ldexp(1.0, ((walk.entries[entry, 0, 3].astype(np.int64) >> np.array([0, 8, 16])) & 0xFF) - 127)
                assert np.all(bvh.bounds_min[node] - lo[entry, c] <= 2 * step)
                assert np.all(hi[entry, c] - bvh.bounds_max[node] <= 2 * step)
                if leaf[node]:
                    assert refs[entry, c] == -first[node] - 1
                    seen_leaves.append(node)
                else:
                    assert node_of_entry[refs[entry, c]] == node
        assert sorted(seen_leaves) == np.flatnonzero(leaf).tolist()
        # each leaf's last triangle flagged, and only those
        last = np.zeros(len(bvh.triangles), bool)
        last[first[leaf] + count[leaf] - 1] = True
        assert (walk.triangles[:, 1, 3] == 1).tolist() == last.tolist()
        assert np.array_equal(np.delete(walk.triangles, 1, axis=1), np.delete(bvh.triangles, 1, axis=1))


def test_texture_rows_are_a_power_of_two_wide():
    """The shader finds texel k at (k & (width - 1), k >> log2(width)): a short array gets the
    smallest power of two that holds it, a long one rows of TEXTURE_WIDTH."""
    assert texels(HAND.nodes).shape == (1, 8, 4)                     # 6 texels
    assert texels(np.zeros((1, 4))).shape == (1, 1, 4)
    assert texels(np.zeros((1025, 4))).shape == (2, 1024, 4)
    with pytest.raises(ValueError, match="power of two"):
        texels(HAND.nodes, width=6)


def test_traversal_of_the_hand_written_layout():
    down = (0, 0, -1)
    O = np.array([(0.25, 0.25, 1), (4.25, 0.25, 2), (2, 0.5, 1), (0, 0.25, 1),   # x on a face
                  (-1, 0.25, 1), (0.25, 0.25, -1), (-3, 0.25, 1)], F32)   # the last: s = 4 at (4.25, 0.25, 0)
    D = np.array([down, down, down, down, down, (0, 0, 1), (1.8125, 0, -0.25)], F32)
    hit, s, uv, tri = closest_hit(HAND, O, D)
    assert hit.tolist() == [True, True, False, True, False, True, True]
    assert tri.tolist() == [1, 0, -1, 1, -1, 1, 0]
    assert s.tolist() == [1, 2, INF, 1, INF, 1, 4]
    assert uv[:2].tolist() == [[0.25, 0.25], [0.25, 0.25]] and uv[3].tolist() == [0, 0.25]
    # the open interval: s_max = 1 refuses the hit at s = 1, s_min = 1 too
    assert not closest_hit(HAND, O[:1], D[:1], 0, 1)[0][0]
    assert not closest_hit(HAND, O[:1], D[:1], 1, INF)[0][0]
    # any hit (shadow rays): the same answers, s_max one per ray
    assert any_hit(HAND, O, D).tolist() == hit.tolist()
    assert any_hit(HAND, O, D, 0, np.array([1, 2.5, 9, 9, 9, 9, 3.5], F32)).tolist() == \
        [False, True, False, True, False, True, False]


def test_ray_box_slabs_and_parallel_axes():
    bmin, bmax = np.zeros(3, F32), np.ones(3, F32)
    O = np.array([(-1, 0.5, 0.5), (-1, 0, 0.5), (-1, 1, 1), (-1, 1.5, 0.5), (0.5, 0.5, 0.5),
                  (2, 0.5, 0.5)], F32)
    D = np.array([(1, 0, 0), (1, 0, 0), (2, -0.0, 0), (1, 0, 0), (0, 0, 1), (1, 0, 0)], F32)
    hit, near = ray_box(O, inverse_direction(D), bmin, bmax, F32(0), F32(INF))
    # through; on the face y = 0 (closed); on the edge y = z = 1 (-0.0 as 0); outside the y slab;
    # from inside (near = s_min); box behind
    assert hit.tolist() == [True, True, True, False, True, False]
    assert near[:3].tolist() == [1, 1, 0.5] and near[4] == 0


# -- the builder's invariants ------------------------------------------------------------------

def soup(count, seed):
    rng = np.random.default_rng(seed)
    centres = rng.uniform(-1, 1, (count, 1, 3))
    return (centres + rng.normal(scale=0.1, size=(count, 3, 3))).astype(F32)


SPHERE_TRIANGLES = {4: 5120, 5: 20480}


@pytest.fixture(scope="module", params=[4, pytest.param(5, marks=pytest.mark.slow)],
                ids=["5120-triangle sphere", "20480-triangle sphere"])
def sphere(request):
    """The icosphere at 5,120 triangles in the default run; the full run (--all) adds the
    20,480-triangle one (its traversal tests are the slow part; benchmarks/bench_bvh.py times
    the build)."""
    mesh = icosphere(subdivisions=request.param)
    vertices = mesh_vertices(mesh.positions, mesh.faces)
    assert len(vertices) == SPHERE_TRIANGLES[request.param]
    return vertices, build_bvh(vertices)


def check_invariants(vertices, bvh, max_leaf_size=4):
    T, N = len(vertices), len(bvh.nodes)
    leaf = bvh.is_leaf
    first = bvh.nodes[leaf, 0, 3].astype(int)
    count = bvh.nodes[leaf, 1, 3].astype(int)
    assert (count >= 1).all() and (count <= max_leaf_size).all()
    # the leaves' ranges tile 0..T-1 in node order, and every triangle is in exactly one
    assert first.tolist() == (np.cumsum(count) - count).tolist() and count.sum() == T
    assert sorted(bvh.original_index.tolist()) == list(range(T))
    assert (bvh.vertices == vertices[bvh.original_index]).all()
    # children: left i + 1, right a > i + 1; each node exactly one parent (a tree, pre-order)
    inner = np.flatnonzero(~leaf)
    right = bvh.nodes[inner, 0, 3].astype(int)
    children = np.concatenate([inner + 1, right])
    assert (right > inner + 1).all() and sorted(children.tolist()) == list(range(1, N))
    lo, hi = bvh.bounds_min, bvh.bounds_max
    for child in (inner + 1, right):
        assert (lo[inner] <= lo[child]).all() and (hi[child] <= hi[inner]).all()
    owner = np.repeat(np.flatnonzero(leaf), count)
    assert (lo[owner] <= bvh.vertices.min(1)).all() and (bvh.vertices.max(1) <= hi[owner]).all()
    assert lo[0].tolist() == vertices.min((0, 1)).tolist() and hi[0].tolist() == vertices.max((0, 1)).tolist()
    assert bvh.depth < MAX_DEPTH


def test_builder_invariants_soup_sphere_and_degenerate(sphere):
    for seed, size in ((1, 1), (2, 7), (3, 1000)):
        vertices = soup(size, seed)
        check_invariants(vertices, build_bvh(vertices))
    check_invariants(*sphere)
    same = np.repeat(soup(1, 4), 50, axis=0)                # 50 copies: the object median
    check_invariants(same, build_bvh(same))
    check_invariants(soup(100, 5), build_bvh(soup(100, 5), max_leaf_size=1), max_leaf_size=1)
    vertices, bvh = sphere
    assert build_bvh(vertices[:2000]).nodes.tobytes() == build_bvh(vertices[:2000]).nodes.tobytes()
    with pytest.raises(ValueError):
        build_bvh(np.zeros((0, 3, 3)))


def same_tree(a: Bvh, b: Bvh) -> bool:
    """The same nodes (to the sign of a zero in a box: min(0.0, -0.0) may give either), the same
    triangles in the same leaf order, the same depth."""
    return ((a.nodes + 0.0).tobytes() == (b.nodes + 0.0).tobytes()
            and a.triangles.tobytes() == b.triangles.tobytes() and a.depth == b.depth)


def grid_triangles(n: int) -> np.ndarray:
    """2n^2 right triangles tiling an n x n square: centroids in rows, ties on every axis."""
    corner = np.stack(np.meshgrid(np.arange(n), np.arange(n)), -1).reshape(-1, 2).astype(F32)
    out = np.zeros((2 * len(corner), 3, 3), F32)
    for k, offsets in enumerate((((0, 0), (1, 0), (0, 1)), ((1, 0), (1, 1), (0, 1)))):
        for v, offset in enumerate(offsets):
            out[k::2, v, :2] = corner + offset
    return out


def chain(count: int) -> np.ndarray:
    """Small triangles at x = 2^k: the SAH peels a few off at a time, a lopsided tree of many
    levels (28 for 120), each with nodes of very different sizes."""
    out = np.zeros((count, 3, 3), F32)
    out[:, :, 0] = np.exp2(np.arange(count, dtype=F32))[:, None]
    out[:, 1, 1] = out[:, 2, 2] = 1.0
    return out


@pytest.mark.parametrize("case", ["soup", "copies", "near copies", "grid", "flat", "chain",
                                  "mesh_file", "shadow_knot_floor"])
def test_the_level_by_level_build_makes_the_recursive_builds_tree(case):
    """Split for split (issue 32): SAH costs in the same float64 arithmetic, ties to the lower axis
    and bin, the object median where no split is found, stable partitions; for leaves of 4 and of 1."""
    from bvh_recursive import build_bvh_recursive
    if case in ("mesh_file", "shadow_knot_floor"):
        scene = load_scene(builtin_scenes()[case])
        meshes = [o.mesh for o in scene.objects if o.mesh is not None and o.mesh.triangle_count > 100]
        vertices = np.concatenate([mesh_vertices(m.positions, m.faces) for m in meshes])
    else:
        rng = np.random.default_rng(7)
        vertices = {"soup": soup(3000, 8), "copies": np.repeat(soup(1, 4), 50, axis=0),
                    "near copies": np.repeat(soup(1, 4), 40, axis=0)
                    + rng.normal(scale=1e-6, size=(40, 1, 1)).astype(F32),
                    "grid": grid_triangles(30), "flat": grid_triangles(12) * F32([1, 1, 0]),
                    "chain": chain(120)}[case]
    for leaf in (MAX_LEAF_SIZE, 1):
        assert same_tree(build_bvh(vertices, max_leaf_size=leaf),
                         build_bvh_recursive(vertices, max_leaf_size=leaf)), (case, leaf)


# -- a refit: the tree kept, the boxes made again -----------------------------------------------

def test_a_refit_moves_the_hand_written_boxes_with_the_triangles():
    moved = refit(HAND, TWO + F32([1, 2, -3]))
    shift = np.array([1, 2, -3], F32)
    assert (moved.nodes[:, :, :3] == HAND.nodes[:, :, :3] + shift).all()
    assert (moved.nodes[:, :, 3] == HAND.nodes[:, :, 3]).all()           # the tree: a, count
    assert (moved.vertices == HAND.vertices + shift).all()
    assert moved.original_index.tolist() == [1, 0] and moved.depth == 1
    assert refit(HAND, TWO).nodes.tobytes() == HAND.nodes.tobytes()
    with pytest.raises(ValueError, match="2 triangles"):
        refit(HAND, TWO[:1])


def test_a_build_laid_out_on_other_positions_is_its_refit():
    """build_bvh(v, layout=w): the tree built on v, its boxes and triangles w's, as
    refit(build_bvh(v), w) (a scene's tree built in world space, traced relative to the eye)."""
    v = soup(2000, 30)
    w = (v * F32(1.5) + F32([40, -3, 7])).astype(F32)
    laid, refitted = build_bvh(v, layout=w), refit(build_bvh(v), w)
    assert laid.nodes.tolist() == refitted.nodes.tolist() and laid.depth == refitted.depth
    assert laid.triangles.tolist() == refitted.triangles.tolist()
    assert laid.nodes[:, :, 3].tolist() == build_bvh(v).nodes[:, :, 3].tolist()     # the same tree
    with pytest.raises(ValueError, match="layout"):
        build_bvh(v, layout=w[:10])


def check_tight(bvh):
    """Every leaf's box is its triangles' bounds, every interior node's its children's union."""
    lo, hi, a, count = bvh.bounds_min, bvh.bounds_max, bvh.nodes[:, 0, 3], bvh.nodes[:, 1, 3]
    for i in range(len(bvh.nodes)):
        if count[i] > 0:
            inside = bvh.vertices[int(a[i]):int(a[i] + count[i])]
            expected = inside.min((0, 1)), inside.max((0, 1))
        else:
            children = [i + 1, int(a[i])]
            expected = lo[children].min(0), hi[children].max(0)
        assert (lo[i] == expected[0]).all() and (hi[i] == expected[1]).all(), i


def test_a_refit_of_the_sphere_moved_and_stretched_is_tight(sphere):
    V, bvh = sphere
    moved = V * F32([3, 0.5, 1]) + F32([1e3, -7.25, 0.1])
    check_invariants(moved, refit(bvh, moved))
    check_tight(refit(bvh, moved))
    assert (refit(bvh, moved).nodes[:, :, 3] == bvh.nodes[:, :, 3]).all()


def test_a_scenes_tree_does_not_depend_on_the_eye():
    """ray_scene builds the tree over world-space triangles and fits its boxes to the
    camera-relative ones, so a new eye needs only a refit: the same bytes as a new build
    (before, a build over camera-relative float32 triangles changed its tree with the eye)."""
    from dataclasses import replace
    from renderer.core.builtin import resolve_scene
    from renderer.core.raytrace_scene import ray_scene
    from renderer.core.scene_file import load_scene
    authored = load_scene(resolve_scene("flat_shading"))
    first = ray_scene(authored).bvh
    eye = tuple(np.add(authored.camera.eye, (1.3, -0.7, 2.1)))
    moved = replace(authored, camera=replace(authored.camera, eye=eye))
    built, refitted = ray_scene(moved).bvh, ray_scene(moved, tree=first).bvh
    assert built.nodes.tobytes() == refitted.nodes.tobytes()
    assert built.triangles.tobytes() == refitted.triangles.tobytes()
    assert (built.nodes[:, :, 3] == first.nodes[:, :, 3]).all()
    assert not (built.nodes[:, :, :3] == first.nodes[:, :, :3]).all()     # the boxes moved


# -- the twin against brute force --------------------------------------------------------------

def random_rays(count, seed, spread=2.0):
    """Origins in a cube, directions normal; every 10th ray along an axis (D's other components
    exactly 0: the slab test's parallel case), every 10th in a coordinate plane."""
    rng = np.random.default_rng(seed)
    O = rng.uniform(-spread, spread, (count, 3)).astype(F32)
    D = rng.normal(size=(count, 3)).astype(F32)
    D[::10, 1:] = 0
    D[5::10, rng.integers(0, 3)] = 0
    return O, D


def assert_same_closest_hit(V, O, D, answer, expected):
    hit, s, _, tri = answer
    hit_b, s_b, _, tri_b = expected
    assert (hit == hit_b).all()
    differ = hit & (tri != tri_b)
    assert (s[hit & ~differ] == s_b[hit & ~differ]).all()
    if differ.any():                                # ties: the other triangle is hit at that s
        _, s_other, _ = ray_triangle(O[differ], D[differ], *(V[tri[differ], k] for k in range(3)), F32(0), F32(INF))
        assert (s_other == s[differ]).all() and (np.abs(s[differ] - s_b[differ]) <= 2 * np.spacing(s_b[differ])).all()
    return differ.sum()


def test_twin_equals_brute_force_on_a_soup():
    V = soup(1000, 6)
    O, D = random_rays(3000, 7)
    answer = closest_hit(build_bvh(V), O, D)
    assert 0.1 < answer[0].mean() < 0.9
    assert assert_same_closest_hit(V, O, D, answer, closest_hit_brute_force(V, O, D)) == 0


def test_a_forest_walks_each_tree_from_its_root(gl_contexts):
    """A forest (motion blur's layout: several trees in one pair of textures, each tree's node
    and triangle indices offset by those before it): the walk from each tree's root answers as
    that tree alone, closest hit and any hit, in the twin and in the GLSL (bit for bit the
    GPU's walk of the tree alone); triangles keep the numbering their trees were given."""
    A, B = soup(400, 20), soup(300, 21)
    second = build_bvh(B)
    numbered = second.triangles.copy()
    numbered[:, 0, 3] += len(A)                        # B's triangles after A's
    trees = [build_bvh(A), Bvh(second.nodes, numbered, second.depth)]
    both = forest(trees)
    assert roots(both).tolist() == [0, len(trees[0].nodes)] and roots(trees[1]).tolist() == [0]
    assert len(both.triangles) == 700 and refit(both, np.concatenate([A, B])).nodes.tolist() == both.nodes.tolist()
    O, D = random_rays(32 * 32, 22, spread=1.2)
    for root, tree in zip(roots(both), trees):
        alone, walked = closest_hit(tree, O, D), closest_hit(both, O, D, root=root)
        assert 0.1 < alone[0].mean() < 0.9, alone[0].mean()
        for a, b in zip(alone, walked):
            assert np.array_equal(a, b)
        assert np.array_equal(any_hit(both, O, D, root=root), alone[0])
        ctx = gl_contexts["egl"]
        rays = O.reshape(32, 32, 3), D.reshape(32, 32, 3)
        assert np.array_equal(gpu_closest_hits(ctx, both, *rays, root=root), gpu_closest_hits(ctx, tree, *rays))


def test_any_hit_answers_as_closest_hit_does(sphere):
    """The shadow rays' walk stops at its first hit: whether something is hit is closest_hit's
    answer, ray for ray, whatever s_max (here from 0.5 to 4, and infinite)."""
    for V, bvh, (O, D) in ((soup(1000, 6), build_bvh(soup(1000, 6)), random_rays(3000, 14)),
                           (*sphere, random_rays(3000, 15, spread=1.5))):
        s_max = np.where(np.arange(len(O)) % 2, np.random.default_rng(16).uniform(0.5, 4, len(O)), np.inf).astype(F32)
        hit = closest_hit(bvh, O, D, 0, s_max)[0]
        assert 0.1 < hit.mean() < 0.9
        assert (any_hit(bvh, O, D, 0, s_max) == hit).all()


def test_twin_equals_brute_force_on_the_icosphere(sphere):
    V, bvh = sphere
    O, D = random_rays(600, 8, spread=1.5)            # some inside the sphere, most outside
    O[::3] *= F32(0.5)                                  # a third inside
    D[1::3] = -O[1::3] + np.random.default_rng(9).normal(scale=0.3, size=(200, 3)).astype(F32)  # aimed at it
    answer = closest_hit(bvh, O, D)
    assert 0.5 < answer[0].mean() < 0.95
    assert_same_closest_hit(V, O, D, answer, closest_hit_brute_force(V, O, D))


# -- the GLSL against the twin -----------------------------------------------------------------

def grid(origin, u, v, k):
    """(2 k^2, 3, 3) float32: the parallelogram origin + [0, 1] u + [0, 1] v in k x k squares."""
    o, u, v = (np.asarray(a, np.float64) for a in (origin, u, v))
    i, j = np.meshgrid(np.arange(k), np.arange(k), indexing="ij")
    a = o + (i.ravel()[:, None] * u + j.ravel()[:, None] * v) / k
    b, c, d = a + u / k, a + (u + v) / k, a + v / k
    return np.concatenate([np.stack([a, b, c], 1), np.stack([a, c, d], 1)]).astype(F32)


def corner_rays(count, seed):
    """A floor (y = 0) and a wall (z = -2) meeting along a corner, each of 128 triangles (so
    that a walk meets them in different leaves); rays from the room's inside aimed at points of
    the corner line, kept where a floor's and a wall's triangle are hit at one float32 s."""
    floor = grid((-2, 0, -2), (4, 0, 0), (0, 0, 4), 8)
    wall = grid((-2, 0, -2), (0, 2, 0), (4, 0, 0), 8)
    rng = np.random.default_rng(seed)
    O = np.stack([rng.uniform(-1.5, 1.5, count), rng.uniform(0.2, 1.8, count), rng.uniform(-1, 1.5, count)], 1).astype(F32)
    target = np.stack([rng.uniform(-1.9, 1.9, count), np.zeros(count), np.full(count, -2.0)], 1)
    D = (target - O).astype(F32)
    s = np.stack([ray_triangle(O, D, *(t[k] for k in range(3)), F32(0), F32(INF))[1]
                  for t in np.concatenate([floor, wall])])
    tied = np.isfinite(s).sum(0) >= 2
    tied &= np.array([len(set(c[np.isfinite(c)].tolist())) == 1 for c in s.T])
    return floor, wall, O[tied], D[tied]


@pytest.mark.parametrize("wall_first", [False, True])
def test_a_tie_goes_to_the_lowest_index_whatever_the_walk(gl_contexts, wall_first):
    """Rays through a corner hit the floor and the wall at one s: the GPU's walk (depth first,
    the nearer box first: the two flat boxes meet the ray at that same s too), the twin's
    (level by level) and brute force all name the lower original index, floor or wall, each
    way round; before this rule the walks' orders decided, and a path through a corner went
    one way on the GPU and the other in the twin (radiosity_window at 16 paths a pixel)."""
    floor, wall, O, D = corner_rays(4000, 30)
    assert len(O) > 100
    first, second = (wall, floor) if wall_first else (floor, wall)
    V = np.concatenate([first, second])
    bvh = build_bvh(V)
    n = 16 * (len(O) // 16)
    O, D = O[:n], D[:n]
    expected = closest_hit_brute_force(V, O, D)
    twin = closest_hit(bvh, O, D, 0.0, F32(1e30))
    assert np.array_equal(twin[3], expected[3]) and np.array_equal(twin[1], expected[1])
    assert (twin[3] < len(first)).all()                    # the first surface's, every one
    for kind, ctx in gl_contexts.items():
        out = gpu_closest_hits(ctx, bvh, O.reshape(16, -1, 3), D.reshape(16, -1, 3)).reshape(-1, 4)
        assert np.array_equal(out[:, 1].astype(np.int64), twin[3]), kind
        assert np.array_equal(out[:, 0], twin[1]), kind


WIDTH, HEIGHT = 64, 64


def gpu_closest_hits(ctx, bvh, O, D, s_min=0.0, s_max=1e30, any_hit=False, root=0):
    """(s, triangle, u, v) per ray from bvh_closest_hit; any_hit: (1 or 0, 0, 0, 0) from
    bvh_any_hit; both walking the tree whose root node is `root`."""
    from renderer.gpu.bvh import bvh_textures
    from renderer.gpu.context import activate
    from renderer.gpu.shaders import shader_source
    activate(ctx)               # a test run before (the command line's) may leave another current
    fragment = shader_source("raytrace_bvh.frag", {"ANY_HIT": any_hit}, directory=GLSL).text
    program = ctx.program(vertex_shader=shader_source("fullscreen.vert", directory=GLSL).text,
                          fragment_shader=fragment)
    h, w = O.shape[:2]
    inputs = [ctx.texture((w, h), 3, np.ascontiguousarray(a, F32).tobytes(), dtype="f4") for a in (O, D)]
    inputs += bvh_textures(ctx, bvh)
    output = ctx.texture((w, h), 4, dtype="f4")
    framebuffer = ctx.framebuffer([output])
    vao = ctx.vertex_array(program, [])
    try:
        for unit, (texture, name) in enumerate(zip(inputs, ("u_origins", "u_directions", "u_nodes", "u_triangles"))):
            texture.filter = (ctx.NEAREST, ctx.NEAREST)
            texture.use(unit)
            program[name].value = unit
        program["u_s_min"].value = s_min
        program["u_s_max"].value = s_max
        program["u_root"].value = int(np.flatnonzero(roots(bvh) == root)[0])   # the tree's entry
        framebuffer.use()
        vao.render(vertices=3)
        ctx.finish()
        return np.frombuffer(output.read(), F32).reshape(h, w, 4)
    finally:
        for thing in (vao, framebuffer, program, *inputs, output):
            thing.release()


def norm(v):
    return np.sqrt((np.asarray(v, np.float64) ** 2).sum(-1))


def triangle_bounds(O, D, V, s):
    """The forward rounding-error bounds of tests/test_raytrace_intersect.py for s and for the
    distance to the nearest edge, and that distance, per ray against its triangle V (R, 3, 3)."""
    O64, D64, V64 = (np.asarray(a, np.float64) for a in (O, D, V))
    e1, e2 = V64[:, 1] - V64[:, 0], V64[:, 2] - V64[:, 0]
    t = O64 - V64[:, 0]
    with np.errstate(divide="ignore", invalid="ignore"):
        det = (np.cross(D64, e2) * e1).sum(-1)
        s_bound = (norm(e2) * norm(t) * norm(e1) + np.abs(s) * norm(e1) * norm(D64) * norm(e2)) / np.abs(det)
        u = (t * np.cross(D64, e2)).sum(-1) / det
        v = (D64 * np.cross(t, e1)).sum(-1) / det
        uv_bound = (norm(t) + norm(e1) + norm(e2)) * norm(D64) * np.maximum(norm(e1), norm(e2)) / np.abs(det)
    edge = np.minimum(np.minimum(np.abs(u), np.abs(v)), np.abs(1 - u - v))
    return s_bound, edge, uv_bound


@pytest.mark.parametrize("scene", ["soup", "icosphere"])
def test_glsl_traversal_agrees_with_the_twin(gl_contexts, sphere, scene):
    """Hit or miss agree but where the hit triangle is hit within rounding of its edge (a ray
    can slip between two triangles: Moeller-Trumbore is not watertight); the triangle agrees
    but at ties, where the other is hit within the tolerance at the same s; s within K eps32
    times the triangle's forward error bound. The any-hit walk (shadow rays) answers as the
    GPU's closest hit does, ray for ray."""
    if scene == "soup":
        V = soup(2000, 10)
        bvh = build_bvh(V)
        O, D = random_rays(WIDTH * HEIGHT, 11)
    else:
        V, bvh = sphere
        O, D = random_rays(WIDTH * HEIGHT, 12, spread=1.5)
        O[::3] *= F32(0.5)
        D[1::3] = -O[1::3] + np.random.default_rng(13).normal(scale=0.3, size=D[1::3].shape).astype(F32)
    hit, s, uv, tri = closest_hit(bvh, O, D, 0.0, F32(1e30))
    assert 0.1 < hit.mean() < 0.95
    for kind, ctx in gl_contexts.items():
        out = gpu_closest_hits(ctx, bvh, O.reshape(HEIGHT, WIDTH, 3), D.reshape(HEIGHT, WIDTH, 3)).reshape(-1, 4)
        gpu_s, gpu_tri = out[:, 0], out[:, 1].astype(np.int64)
        gpu_hit = gpu_tri >= 0
        assert (gpu_s[~gpu_hit] == F32(1e30)).all(), kind
        gpu_any = gpu_closest_hits(ctx, bvh, O.reshape(HEIGHT, WIDTH, 3), D.reshape(HEIGHT, WIDTH, 3),
                                   any_hit=True).reshape(-1, 4)[:, 0] > 0
        assert (gpu_any == gpu_hit).all(), kind
        # hit/miss: only where the hitting side's triangle is hit within rounding of an edge
        one = gpu_hit != hit
        assert one.sum() <= 0.002 * len(hit), (kind, one.sum())
        if one.any():
            which = np.where(hit[one], tri[one], gpu_tri[one])
            _, edge, uv_bound = triangle_bounds(O[one], D[one], V[which], s[one])
            assert (edge <= K * EPS32 * uv_bound).all(), (kind, "hit/miss off an edge")
        both = gpu_hit & hit
        s_bound, _, _ = triangle_bounds(O[both], D[both], V[tri[both]], s[both])
        error = np.abs(gpu_s[both].astype(np.float64) - s[both])
        same = gpu_tri[both] == tri[both]
        assert (error[same] <= K * EPS32 * s_bound[same]).all(), (kind, error[same].max())
        # ties: the GPU's triangle is hit by the twin's ray at (about) the twin's s
        if (~same).any():
            O_t, D_t = O[both][~same], D[both][~same]
            V_t = V[gpu_tri[both][~same]]
            other_hit, other_s, _ = ray_triangle(O_t, D_t, V_t[:, 0], V_t[:, 1], V_t[:, 2], F32(0), F32(INF))
            other_bound, edge, uv_bound = triangle_bounds(O_t, D_t, V_t, other_s)
            assert ((other_hit | (edge <= K * EPS32 * uv_bound))).all(), kind
            assert (np.abs(other_s - s[both][~same]) <= K * EPS32 * (other_bound + s_bound[~same])).all(), kind
            assert (~same).sum() <= 0.002 * len(hit), (kind, (~same).sum())
