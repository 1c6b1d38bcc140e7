"""A bounding volume hierarchy over a triangle list, built once per scene on the CPU (binned
surface area heuristic, NumPy) and laid out flat: the NumPy twin (reference/raytrace/bvh.py)
traverses these arrays, and the GLSL (glsl/raytrace/bvh.glsl) the very same tree laid out four
boxes a step (`walk_layout`, `Walk`).

The layout (every number float32; the integers in it are exact, being below 2^24):

  nodes      (N, 2, 4): node i is two RGBA texels, depth-first (pre-order), root = node 0:
               texel 2i     = [min.x, min.y, min.z, a]
               texel 2i + 1 = [max.x, max.y, max.z, count]
             count > 0: a leaf holding triangles a, a + 1, ..., a + count - 1 (of `triangles`);
             count == 0: an interior node whose left child is i + 1 (it follows its parent) and
             whose right child is a. min/max are the node's axis-aligned bounds: they contain
             its children's bounds and its triangles' vertices.
  triangles  (T, 3, 4): triangle j (in leaf order) is three RGBA texels
               [A.xyz, original index], [B.xyz, 0], [C.xyz, 0]
             with the original index the triangle's row in the input.

As a texture (`texels`): the texels of an array in order, row by row, TEXTURE_WIDTH to a row
(for a short array, the smallest power of two that holds it), the last row padded with zeros;
texel k is at (k % width, k // width), the width read back by the shader with textureSize.
The width is a power of two so that the shader computes that address with a mask and a shift:
llvmpipe has no vector integer division and divides lane by lane.

The build: a node with more than `max_leaf_size` triangles is split by the binned SAH (BINS
bins per axis over its centroids' bounds; the split of least A_left N_left + A_right N_right,
A half the surface area; ties to the lower axis, then the lower bin); one with at most
`max_leaf_size` is a leaf. (Leaving the leaf decision to the SAH as well made the 20,480-
triangle icosphere's build 3.5 times slower for no faster traversal: benchmarks/bench_bvh.py.)
Where the centroids cannot be binned apart (all in one bin on every axis), or the tree would
grow deeper than MAX_DEPTH - 24, the triangles are halved in centroid order along the widest
axis (the object median). Deterministic: the same triangles give the same bytes. The depth
never exceeds MAX_DEPTH (the build refuses otherwise), so a traversal stack of MAX_DEPTH
entries suffices.

The build runs level by level (issue 32): every node of a level is binned, costed and split
at once, with no Python call per node (a recursive build made 40,101 calls for the
131,072-triangle torus knot and took 8 s). Each node's triangles are a contiguous run of one
permutation; a split partitions its run stably, left side first, so that the leaves tile the
permutation left to right, which is then the triangles' leaf order. The pre-order numbering
is worked out afterwards from the subtrees' sizes. Split for split it is the recursive build
(tests/test_raytrace_bvh.py holds the two equal, tests/bvh_recursive.py), to the sign of a
zero in a box.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

BINS = 16
MAX_LEAF_SIZE = 4
MAX_DEPTH = 64                  # the GLSL's BVH_STACK_SIZE (renderer/gpu/shaders.py defines it)
TEXTURE_WIDTH = 1024
MAX_EXACT_INDEX = 1 << 24       # float32 holds every integer below it
GROUP_TRIANGLES = 1 << 14       # a level's nodes split together: at most this many triangles
GROUP_NODES = 1 << 10           # and nodes (but one node of more triangles goes alone)


@dataclass(frozen=True)
class Bvh:
    nodes: np.ndarray           # (N, 2, 4) float32, the layout above
    triangles: np.ndarray       # (T, 3, 4) float32
    depth: int                  # the deepest node's depth (root: 0)

    @property
    def is_leaf(self) -> np.ndarray:
        return self.nodes[:, 1, 3] > 0

    @property
    def bounds_min(self) -> np.ndarray:
        return self.nodes[:, 0, :3]

    @property
    def bounds_max(self) -> np.ndarray:
        return self.nodes[:, 1, :3]

    @property
    def original_index(self) -> np.ndarray:
        return self.triangles[:, 0, 3].astype(np.int64)

    @property
    def vertices(self) -> np.ndarray:
        """(T, 3, 3) float32: A, B, C of each triangle in leaf order."""
        return self.triangles[:, :, :3]


def _half_extent_area(d: np.ndarray, axis: int) -> np.ndarray:
    """Half the surface area of boxes of extent d (x, y and z along `axis`), or of -d: the
    products are the same."""
    x, y, z = (np.take(d, i, axis=axis) for i in range(3))
    return x * y + y * z + z * x


def _running_min(a: np.ndarray) -> np.ndarray:
    """np.minimum.accumulate(a, axis=0), the same values, a plane at a time: numpy's
    accumulate runs along the axis for each element of a plane, several times slower."""
    a = a.copy()
    for i in range(1, len(a)):
        np.minimum(a[i], a[i - 1], out=a[i])
    return a


def _runs(starts: np.ndarray, lengths: np.ndarray) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """(positions, run of each position, each run's offset among the positions) of the
    runs [start, start + length), concatenated in order."""
    run = np.repeat(np.arange(len(starts)), lengths)
    offsets = np.cumsum(lengths) - lengths
    return np.arange(len(run)) - offsets[run] + starts[run], run, offsets


def _sah_splits(ids, run, offsets, counts, centroids, low_high, bins):
    """Every node's best binned SAH split at once (the module docstring): (the nodes that have
    one, the side of each of `ids`: True on the left). `ids` are the nodes' triangles, node by
    node (`run`: the node of each; `offsets`: where each node's begin); `low_high` (T, 6) each
    triangle's min corner and its max corner negated, so that one reduction takes both."""
    m, c = len(counts), np.take(centroids, ids, axis=0)     # take: faster than [ids] for rows
    cmin, cmax = np.minimum.reduceat(c, offsets), np.maximum.reduceat(c, offsets)
    extent = cmax - cmin
    with np.errstate(invalid="ignore", over="ignore", divide="ignore"):
        scale = np.where(extent > 0, bins / np.where(extent > 0, extent, 1.0), 0.0)
        index = ((c - np.repeat(cmin, counts, axis=0)) * np.repeat(scale, counts, axis=0)).astype(np.int64)
        np.minimum(index, bins - 1, out=index)                                          # (e, 3)
    # Each (bin, node, axis)'s triangles: how many, and their bounds (min, then -max), by
    # np.minimum.at on flat indices (numpy >= 1.25 runs it as a plain loop: on the deep levels'
    # bins of a triangle or two, some 2.5 times a sort by bin and a reduceat). The bins are
    # the outer axis and the six bounds the next, so that the scans over bins and the areas
    # below work on whole contiguous planes.
    cells = m * 3
    at = index * cells
    at += run[:, None] * 3 + np.arange(3)                       # (e, 3): (bin, node, axis)
    counted = np.bincount(at.ravel(), minlength=bins * cells).reshape(bins, m, 3)
    at += index * (5 * cells)                                   # (bin, column 0, node, axis)
    bounds = np.full(bins * 6 * cells, np.inf)
    values = np.take(low_high, ids, axis=0)                                          # (e, 6)
    for column in range(6):
        np.minimum.at(bounds, at.ravel(), np.repeat(values[:, column], 3))
        at += cells
    bounds = bounds.reshape(bins, 6, m, 3)
    left_n = np.cumsum(counted, axis=0)[:-1]                                         # (B-1, m, 3)
    right_n = counts[:, None] - left_n
    # The bins' bounds to the left of each split and to its right, min and -max in one scan
    # each way; a box's extent is then -(min + -max), exactly, and its products the same.
    left = _running_min(bounds)[:-1]
    right = _running_min(bounds[::-1])[-2::-1]
    with np.errstate(invalid="ignore", over="ignore"):
        cost = (_half_extent_area(left[:, :3] + left[:, 3:], axis=1) * left_n
                + _half_extent_area(right[:, :3] + right[:, 3:], axis=1) * right_n)
    valid = (left_n > 0) & (right_n > 0) & (extent > 0)
    cost = np.where(valid, cost, np.inf).transpose(1, 2, 0).reshape(m, -1)         # (m, 3 (B-1))
    best = np.argmin(cost, axis=1)              # ties: the lower axis, then the lower bin
    axis, k = np.divmod(best, bins - 1)
    found = np.isfinite(cost[np.arange(m), best])
    return found, index[np.arange(len(ids)), axis[run]] <= k[run]


def _median_splits(ids, run, offsets, counts, centroids, nodes):
    """The sides of the triangles of `nodes` (a mask over the nodes) halved in centroid order
    along each node's widest axis (the object median; stable: ties keep their order), as a
    mask over all of `ids`: True for the first half."""
    left = np.zeros(len(ids), bool)
    c = np.take(centroids, ids, axis=0)
    widest = np.argmax(np.maximum.reduceat(c, offsets) - np.minimum.reduceat(c, offsets), axis=1)
    chosen = np.flatnonzero(nodes[run])
    order = chosen[np.lexsort((c[chosen, widest[run[chosen]]], run[chosen]))]
    node = run[order]
    rank = np.arange(len(order)) - np.searchsorted(node, node, "left")
    left[order] = rank < counts[node] // 2
    return left


def build_inputs(vertices, max_leaf_size: int):
    """(vertices as float32, each triangle's float64 min and max corner, its centroid) of a
    build's checked input: a ValueError for what no tree can hold."""
    vertices = np.asarray(vertices, dtype=np.float32)
    if vertices.ndim != 3 or vertices.shape[1:] != (3, 3) or len(vertices) == 0:
        raise ValueError(f"triangles must be (T, 3, 3) with T >= 1, not {vertices.shape}")
    if not np.isfinite(vertices).all():
        raise ValueError("triangle vertices must be finite")
    if max_leaf_size < 1:
        raise ValueError("max_leaf_size must be at least 1")
    if 2 * len(vertices) >= MAX_EXACT_INDEX:
        raise ValueError(f"{len(vertices)} triangles: the float32 layout indexes at most "
                         f"{MAX_EXACT_INDEX // 2 - 1}")
    tri_min, tri_max = _corners(vertices)
    return vertices, tri_min, tri_max, (tri_min + tri_max) / 2


def _corners(vertices: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """Each float32 triangle's min and max corner as float64: taken in float32 and then
    widened, the same values as in float64 (both exact), a third of the conversion."""
    return vertices.min(1).astype(np.float64), vertices.max(1).astype(np.float64)


def _groups(counts: np.ndarray) -> list[slice]:
    """A level's nodes in consecutive groups of at most GROUP_TRIANGLES triangles and
    GROUP_NODES nodes (a bigger node alone): the temporaries of a split, some 300 bytes a
    triangle and 6 KiB a node, stay bounded however large the mesh (issue 30's limits)."""
    groups, begin, triangles = [], 0, 0
    for end, count in enumerate(counts.tolist()):
        if end > begin and (triangles + count > GROUP_TRIANGLES or end - begin >= GROUP_NODES):
            groups.append(slice(begin, end))
            begin, triangles = end, 0
        triangles += count
    return groups + [slice(begin, len(counts))]


def _split_nodes(perm, starts, counts, depth, centroids, low_high, bins) -> np.ndarray:
    """Split the nodes whose triangles are perm[start:start + count] (the module docstring):
    each run partitioned in place, stably, its left side first; the left sides' sizes."""
    positions, run, offsets = _runs(starts, counts)
    ids = perm[positions]
    sah = np.zeros(len(counts), bool)
    left = np.zeros(len(ids), bool)
    if depth < MAX_DEPTH - 24:
        sah, left = _sah_splits(ids, run, offsets, counts, centroids, low_high, bins)
    if not sah.all():
        left = np.where(sah[run], left, _median_splits(ids, run, offsets, counts, centroids, ~sah))
    n_left = np.bincount(run, weights=left, minlength=len(counts)).astype(np.int64)
    before_left = np.cumsum(left) - left - (np.cumsum(n_left) - n_left)[run]
    before_right = np.cumsum(~left) - ~left - (np.cumsum(counts - n_left) - (counts - n_left))[run]
    perm[np.where(left, starts[run] + before_left, starts[run] + n_left[run] + before_right)] = ids
    return n_left


def build_bvh(vertices, max_leaf_size: int = MAX_LEAF_SIZE, bins: int = BINS, *,
              layout=None) -> Bvh:
    """The BVH of triangles `vertices` (T, 3, 3) (A, B, C of each; any float dtype; the layout
    holds them as float32), T >= 1; or of a Mesh-like (positions, faces) via `mesh_vertices`.
    `layout`: other positions of the same triangles (T, 3, 3) that the layout holds, its boxes
    fitted to them: the tree built on `vertices`, laid out as refit(build_bvh(vertices), layout)
    would give it, without building the boxes twice (a scene's tree is built in world space and
    traced relative to the eye: renderer/core/raytrace_scene.py)."""
    vertices, tri_min, tri_max, centroids = build_inputs(vertices, max_leaf_size)
    if layout is not None:
        placed = np.asarray(layout, dtype=np.float32)
        if placed.shape != vertices.shape or not np.isfinite(placed).all():
            raise ValueError(f"layout must be finite and ({len(vertices)}, 3, 3), not {placed.shape}")
    T = len(vertices)
    perm = np.arange(T)                         # each node's triangles: a run of it
    low_high = np.concatenate([tri_min, -tri_max], axis=1)
    start, count = [np.zeros(1, np.int64)], [np.full(1, T, np.int64)]     # per level
    left_of = []                                # per level: each node's left child, or -1
    depth = 0
    while True:
        starts, counts = start[-1], count[-1]
        split = counts > max_leaf_size
        left_child = np.full(len(starts), -1, np.int64)
        left_of.append(left_child)
        if not split.any():
            break
        starts, counts = starts[split], counts[split]
        n_left = np.concatenate([_split_nodes(perm, starts[group], counts[group], depth, centroids,
                                              low_high, bins)
                                 for group in _groups(counts)])
        first = sum(len(level) for level in start)
        left_child[split] = first + 2 * np.arange(len(counts))    # and the right child after it
        start.append(np.stack([starts, starts + n_left], axis=1).ravel())
        count.append(np.stack([n_left, counts - n_left], axis=1).ravel())
        depth += 1
    if depth >= MAX_DEPTH:
        raise ValueError(f"BVH depth {depth} exceeds the traversal stack ({MAX_DEPTH})")
    if layout is not None:
        vertices = placed
        tri_min, tri_max = _corners(placed)
    return Bvh(*_layout(perm, np.concatenate(start), np.concatenate(count), left_of,
                        vertices, tri_min, tri_max), depth)


def _layout(perm, start, count, left_of, vertices, tri_min, tri_max):
    """(nodes, triangles) in the module docstring's layout, from the nodes in the order they were
    made (level by level; `left_of[d]`: level d's left children, -1 for a leaf)."""
    left = np.concatenate(left_of)
    level = np.repeat(np.arange(len(left_of)), [len(d) for d in left_of])
    leaf, N = left < 0, len(left)
    lo, hi = np.empty((N, 3)), np.empty((N, 3))
    leaves = np.flatnonzero(leaf)
    leaves = leaves[np.argsort(start[leaves], kind="stable")]     # they tile the permutation
    lo[leaves] = np.minimum.reduceat(np.take(tri_min, perm, axis=0), start[leaves])
    hi[leaves] = np.maximum.reduceat(np.take(tri_max, perm, axis=0), start[leaves])
    size = np.ones(N, np.int64)                 # nodes in each subtree
    for d in range(len(left_of) - 2, -1, -1):   # children before their parents
        inner = np.flatnonzero((level == d) & ~leaf)
        l, r = left[inner], left[inner] + 1
        lo[inner], hi[inner] = np.minimum(lo[l], lo[r]), np.maximum(hi[l], hi[r])
        size[inner] = 1 + size[l] + size[r]
    pre = np.zeros(N, np.int64)                 # pre-order: a node, its left subtree, its right
    for d in range(len(left_of) - 1):
        inner = np.flatnonzero((level == d) & ~leaf)
        pre[left[inner]] = pre[inner] + 1
        pre[left[inner] + 1] = pre[inner] + 1 + size[left[inner]]
    nodes = np.zeros((N, 2, 4), np.float32)
    nodes[pre, 0, :3], nodes[pre, 1, :3] = lo, hi
    nodes[pre, 0, 3] = np.where(leaf, start, pre[np.where(leaf, 0, left + 1)])
    nodes[pre, 1, 3] = np.where(leaf, count, 0)
    triangles = np.zeros((len(perm), 3, 4), np.float32)
    triangles[:, :, :3] = np.take(vertices, perm, axis=0)
    triangles[:, 0, 3] = perm
    return nodes, triangles


def refit(bvh: Bvh, vertices) -> Bvh:
    """`bvh`'s tree over the same triangles moved to `vertices` (T, 3, 3), in their original
    order (a translation relative to another eye, say): the tree, leaf order and depth kept,
    every box recomputed from the new float32 vertices, the leaves' from their triangles and
    then the interior nodes' from their children's, level by level from the deepest. Min and
    max are exact, so the boxes are the very ones build_bvh gives the same tree over `vertices`
    (bytes, but for the sign of a zero)."""
    vertices = np.asarray(vertices, dtype=np.float32)
    if vertices.shape != (len(bvh.triangles), 3, 3):
        raise ValueError(f"refit needs the BVH's {len(bvh.triangles)} triangles as "
                         f"({len(bvh.triangles)}, 3, 3), not {vertices.shape}")
    if not np.isfinite(vertices).all():
        raise ValueError("triangle vertices must be finite")
    placed = vertices[bvh.original_index]                   # leaf order
    nodes = bvh.nodes.copy()
    leaf = bvh.is_leaf
    first = nodes[leaf, 0, 3].astype(np.int64)              # increasing: leaves tile 0..T-1
    nodes[leaf, 0, :3] = np.minimum.reduceat(placed.min(1), first)
    nodes[leaf, 1, :3] = np.maximum.reduceat(placed.max(1), first)
    inner = np.flatnonzero(~leaf)
    left, right = inner + 1, nodes[inner, 0, 3].astype(np.int64)
    depth = node_depths(bvh)
    for level in range(bvh.depth - 1, -1, -1):
        at = depth[inner] == level
        i, l, r = inner[at], left[at], right[at]
        nodes[i, 0, :3] = np.minimum(nodes[l, 0, :3], nodes[r, 0, :3])
        nodes[i, 1, :3] = np.maximum(nodes[l, 1, :3], nodes[r, 1, :3])
    triangles = bvh.triangles.copy()
    triangles[:, :, :3] = placed
    return Bvh(nodes, triangles, bvh.depth)


def forest(trees: list[Bvh]) -> Bvh:
    """Several BVHs in one layout (motion blur: the static triangles' tree, then one per moving
    mesh object; docs/conventions.md, "Motion blur"): their nodes and triangles concatenated in
    order, each tree's node and triangle indices offset by the nodes and triangles before it,
    so that a walk from a tree's root (`roots`) sees that tree alone. Triangles keep their
    original indices (the caller's numbering across all trees); depth is the deepest tree's."""
    nodes, triangles, node_base, triangle_base = [], [], 0, 0
    for tree in trees:
        part = tree.nodes.copy()
        leaf = part[:, 1, 3] > 0
        part[:, 0, 3] += np.where(leaf, triangle_base, node_base).astype(np.float32)
        nodes.append(part)
        triangles.append(tree.triangles)
        node_base += len(part)
        triangle_base += len(tree.triangles)
    if 2 * triangle_base >= MAX_EXACT_INDEX or 2 * node_base >= MAX_EXACT_INDEX:
        raise ValueError(f"{triangle_base} triangles in {node_base} nodes: the float32 layout "
                         f"indexes at most {MAX_EXACT_INDEX // 2 - 1}")
    return Bvh(np.concatenate(nodes), np.concatenate(triangles), max(t.depth for t in trees))


def roots(bvh: Bvh) -> np.ndarray:
    """The root node of each tree of a `forest` (of a single BVH: [0]), in order: the nodes no
    interior node names as a child (left i + 1, right a)."""
    inner = np.flatnonzero(~bvh.is_leaf)
    child = np.zeros(len(bvh.nodes), bool)
    child[inner + 1] = True
    child[bvh.nodes[inner, 0, 3].astype(np.int64)] = True
    return np.flatnonzero(~child)


@dataclass(frozen=True)
class Walk:
    """A BVH (or forest) laid out for the GLSL's walk (glsl/raytrace/bvh.glsl): the same tree,
    each step testing up to four boxes at once: an interior node at an even depth (the root's
    0) holds its children, or, where a child is interior, that child's two children, skipping
    its box (a binary tree collapsed to a 4-wide one); the four boxes quantised to 8 bits an
    axis in the node's own box, rounded outwards (issue 32: a step reads four texels, where the
    build's layout took twelve for the same boxes, and texel fetches are most of the walk's time
    on llvmpipe).

      entries    (R + W, 4, 4) uint32 (an RGBA32UI texture; floats as their bits). Entry
                 r < R: tree r's root (the trees of a `forest` in order; a single BVH: R = 1),
                 unquantised: texels [min.xyz, ref], [max.xyz, 0], then zeros. Entry R + k:
                 the k-th even-depth interior node in pre-order, its up to four children in
                 the tree's left-to-right order:
                   texel 0  [origin.xyz, exponents]: the children's boxes are origin +
                            q 2^e on each axis, the byte e + QUANT_BIAS (x, y, z: bits 0, 8, 16)
                   texel 1  [lo.x, lo.y, lo.z, hi.x]  each four bytes: child c's q in byte c
                   texel 2  [hi.y, hi.z, ref 0, ref 1]
                   texel 3  [ref 2, ref 3, 0, 0]
                 A ref (as int32) >= 0 is an interior node's entry; EMPTY an unused child
                 (never hit); another < 0 a leaf whose triangles begin at -ref - 1 and run to
                 the first flagged last. Every decoded box (float32: origin + q 2^e, the
                 product exact) holds its child's float32 box.
      triangles  Bvh.triangles with texel 3j + 1's w = 1 on the last triangle of each leaf.
    """
    entries: np.ndarray
    triangles: np.ndarray


EMPTY = -(1 << 31)              # an unused child's ref: below every leaf's
QUANT_BIAS = 127                # exponent e is stored as the byte e + QUANT_BIAS
QUANT_MIN_EXPONENT = -100       # a flat axis's step: normal, and far below any box's size


def node_depths(bvh: Bvh) -> np.ndarray:
    """Each node's depth in its tree (a root's 0), parents before children in pre-order."""
    inner = np.flatnonzero(~bvh.is_leaf)
    left, right = inner + 1, bvh.nodes[inner, 0, 3].astype(np.int64)
    depth = np.zeros(len(bvh.nodes), np.int64)
    for _ in range(bvh.depth):          # each pass settles one more level, whole-array
        depth[left] = depth[inner] + 1
        depth[right] = depth[inner] + 1
    return depth


def _quantise(lo, hi, used):
    """(origin (W, 3) float32, exponent (W, 3), q_lo, q_hi (W, 4, 3) uint8) of the children's
    boxes lo, hi (W, 4, 3) float32 (`used` (W, 4): the children there are): origin the used
    boxes' min corner, 2^e the smallest power of two with 254 steps spanning them, q rounded
    outwards and checked in the GLSL's float32 arithmetic (origin + q 2^e, the product exact)."""
    f32 = np.float32
    origin = np.where(used[..., None], lo, np.inf).min(1)
    top = np.where(used[..., None], hi, -np.inf).max(1)
    tiny = np.abs(origin) < np.finfo(f32).tiny          # a subnormal origin: llvmpipe flushes it
    origin = np.where(tiny, -np.finfo(f32).tiny, origin).astype(f32)
    span = top.astype(np.float64) - origin
    with np.errstate(divide="ignore"):
        e = np.ceil(np.log2(np.maximum(span, 0.0) / 254.0))
    e = np.maximum(np.where(span > 0, e, QUANT_MIN_EXPONENT), QUANT_MIN_EXPONENT).astype(np.int64)
    while True:                                         # a step too small by rounding: widen
        step = np.ldexp(f32(1), e).astype(f32)
        q_lo = np.floor((lo - origin[:, None]) / step[:, None].astype(np.float64))
        q_hi = np.ceil((hi - origin[:, None]) / step[:, None].astype(np.float64))
        q_lo, q_hi = np.clip(q_lo, 0, 255), np.clip(q_hi, 0, 255)
        for _ in range(2):                              # outwards where float32 rounded inwards
            low = (origin[:, None] + (q_lo * step[:, None]).astype(f32)).astype(f32)
            high = (origin[:, None] + (q_hi * step[:, None]).astype(f32)).astype(f32)
            q_lo = np.where(low > lo, np.maximum(q_lo - 1, 0), q_lo)
            q_hi = np.where(high < hi, np.minimum(q_hi + 1, 255), q_hi)
        low = (origin[:, None] + (q_lo * step[:, None]).astype(f32)).astype(f32)
        high = (origin[:, None] + (q_hi * step[:, None]).astype(f32)).astype(f32)
        bad = ((low > lo) | (high < hi)) & used[..., None]
        if not bad.any():
            return origin, e, q_lo.astype(np.uint8), q_hi.astype(np.uint8)
        e = e + bad.any(1)


def walk_layout(bvh: Bvh) -> Walk:
    """`bvh` (a BVH or a forest) in the layout of `Walk`."""
    leaf, N = bvh.is_leaf, len(bvh.nodes)
    tree_roots = roots(bvh)
    R = len(tree_roots)
    first = bvh.nodes[:, 0, 3].astype(np.int64)           # a leaf's first triangle, or the right child
    inner = ~leaf
    depth = node_depths(bvh)
    wide = np.flatnonzero(inner & (depth % 2 == 0))
    entry = np.full(N, -1, np.int64)
    entry[wide] = R + np.arange(len(wide))
    ref = np.where(leaf, -first - 1, entry)
    # each wide node's four children: per binary child, its two children if it is interior,
    # else itself and an unused slot
    slots = np.full((len(wide), 4), -1, np.int64)
    for half, child in ((0, wide + 1), (2, first[wide])):
        collapsed = inner[child]
        slots[:, half] = np.where(collapsed, child + 1, child)
        slots[:, half + 1] = np.where(collapsed, first[child], -1)
    used = slots >= 0
    node = np.where(used, slots, 0)
    origin, e, q_lo, q_hi = _quantise(bvh.bounds_min[node], bvh.bounds_max[node], used)
    words = np.zeros((len(wide), 4, 4), np.uint32)
    words[:, 0, :3] = origin.view(np.uint32)
    words[:, 0, 3] = ((e + QUANT_BIAS) << np.array([0, 8, 16])).sum(1)
    shifts = np.array([0, 8, 16, 24], np.uint32)[None, :, None]
    lo_words = (q_lo.astype(np.uint32) << shifts).sum(1, dtype=np.uint32)      # (W, 3)
    hi_words = (q_hi.astype(np.uint32) << shifts).sum(1, dtype=np.uint32)
    words[:, 1, :3], words[:, 1, 3] = lo_words, hi_words[:, 0]
    words[:, 2, :2] = hi_words[:, 1:]
    refs = np.where(used, ref[node], EMPTY).astype(np.int32).view(np.uint32)
    words[:, 2, 2:], words[:, 3, :2] = refs[:, :2], refs[:, 2:]
    head = np.zeros((R, 4, 4), np.uint32)
    head[:, 0, :3] = bvh.bounds_min[tree_roots].astype(np.float32).view(np.uint32)
    head[:, 1, :3] = bvh.bounds_max[tree_roots].astype(np.float32).view(np.uint32)
    head[:, 0, 3] = ref[tree_roots].astype(np.int32).view(np.uint32)
    triangles = bvh.triangles.copy()
    count = bvh.nodes[leaf, 1, 3].astype(np.int64)
    triangles[first[leaf] + count - 1, 1, 3] = 1.0
    return Walk(np.concatenate([head, words]), triangles)


def mesh_vertices(positions, faces) -> np.ndarray:
    """(F, 3, 3) float32 triangle vertices of a mesh (positions (V, 3), faces (F, 3))."""
    return np.asarray(positions, np.float32)[np.asarray(faces)]


def texels(array: np.ndarray, width: int = TEXTURE_WIDTH) -> np.ndarray:
    """(rows, width, 4): the RGBA texels of `array` (..., 4) in order, row by row, the last row
    padded with zeros; `width` (a power of two) to a row, or the smallest power of two that
    holds them all if that is narrower. float32, or uint32 for a uint32 array."""
    if width < 1 or width & (width - 1):
        raise ValueError(f"the texture width must be a power of two, got {width}")
    dtype = np.uint32 if np.asarray(array).dtype == np.uint32 else np.float32
    flat = np.asarray(array, dtype).reshape(-1, 4)
    width = min(width, 1 << max(len(flat) - 1, 0).bit_length())
    rows = -(-len(flat) // width)
    out = np.zeros((rows * width, 4), dtype)
    out[: len(flat)] = flat
    return out.reshape(rows, width, 4)
