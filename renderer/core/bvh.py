"""A bounding volume hierarchy over a triangle list, built once per scene on the CPU (binned
surface area heuristic, NumPy) and laid out flat, so that the GLSL (glsl/raytrace/bvh.glsl) and
its NumPy twin (reference/raytrace/bvh.py) traverse the very same arrays.

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
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

BINS = 16
MAX_LEAF_SIZE = 4
MAX_DEPTH = 64                  # the GLSL's BVH_STACK_SIZE (renderer/gpu/shaders.py defines it)
TEXTURE_WIDTH = 1024
# Triangles binned at once by a SAH split: the (chunk, 3, BINS, 3) float64 temporaries of a
# node's bin bounds take 1152 bytes a triangle, 38 MiB a chunk, where a 5-million-triangle
# root once asked for 5.4 GiB at once (issue 30). Bin bounds are minima and maxima: the
# same in any grouping, so the tree is the same.
SAH_CHUNK = 1 << 15
MAX_EXACT_INDEX = 1 << 24       # float32 holds every integer below it


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


def _half_area(lo: np.ndarray, hi: np.ndarray) -> np.ndarray:
    d = hi - lo
    return d[..., 0] * d[..., 1] + d[..., 1] * d[..., 2] + d[..., 2] * d[..., 0]


def _sah_split(centroids, tri_min, tri_max, bins):
    """(axis, mask of the left side, cost) of the best binned SAH split, or None."""
    cmin, cmax = centroids.min(0), centroids.max(0)
    extent = cmax - cmin
    n = len(centroids)
    if not (extent > 0).any():
        return None
    with np.errstate(invalid="ignore", over="ignore", divide="ignore"):
        scale = np.where(extent > 0, bins / np.where(extent > 0, extent, 1.0), 0.0)
        index = np.minimum(((centroids - cmin) * scale).astype(np.int64), bins - 1)   # (n, 3)
    counts = np.zeros((3, bins), np.int64)
    lo, hi = np.full((3, bins, 3), np.inf), np.full((3, bins, 3), -np.inf)            # (3, B, 3)
    for start in range(0, n, SAH_CHUNK):        # the (chunk, 3, B, 3) temporaries stay bounded
        part = slice(start, start + SAH_CHUNK)
        onehot = index[part, :, None] == np.arange(bins)                              # (c, 3, B)
        counts += onehot.sum(0)
        np.minimum(lo, np.where(onehot[..., None], tri_min[part, None, None, :], np.inf).min(0), out=lo)
        np.maximum(hi, np.where(onehot[..., None], tri_max[part, None, None, :], -np.inf).max(0), out=hi)
    left_n = np.cumsum(counts, axis=1)[:, :-1]                                         # (3, B-1)
    right_n = n - left_n
    left_lo = np.minimum.accumulate(lo, axis=1)[:, :-1]
    left_hi = np.maximum.accumulate(hi, axis=1)[:, :-1]
    right_lo = np.minimum.accumulate(lo[:, ::-1], axis=1)[:, ::-1][:, 1:]
    right_hi = np.maximum.accumulate(hi[:, ::-1], axis=1)[:, ::-1][:, 1:]
    with np.errstate(invalid="ignore", over="ignore"):
        cost = _half_area(left_lo, left_hi) * left_n + _half_area(right_lo, right_hi) * right_n
    valid = (left_n > 0) & (right_n > 0) & (extent > 0)[:, None]
    cost = np.where(valid, cost, np.inf)
    flat = int(np.argmin(cost))                 # ties: the lower axis, then the lower bin
    axis, k = divmod(flat, bins - 1)
    if not np.isfinite(cost[axis, k]):
        return None
    return axis, index[:, axis] <= k, float(cost[axis, k])


def _median_split(centroids):
    axis = int(np.argmax(centroids.max(0) - centroids.min(0)))
    order = np.argsort(centroids[:, axis], kind="stable")
    left = np.zeros(len(centroids), bool)
    left[order[: len(centroids) // 2]] = True
    return left


def build_bvh(vertices, max_leaf_size: int = MAX_LEAF_SIZE, bins: int = BINS) -> Bvh:
    """The BVH of triangles `vertices` (T, 3, 3) (A, B, C of each; any float dtype; the layout
    holds them as float32), T >= 1; or of a Mesh-like (positions, faces) via `mesh_vertices`."""
    vertices = np.asarray(vertices, dtype=np.float32)
    if vertices.ndim != 3 or vertices.shape[1:] != (3, 3) or len(vertices) == 0:
        raise ValueError(f"triangles must be (T, 3, 3) with T >= 1, not {vertices.shape}")
    if not np.isfinite(vertices).all():
        raise ValueError("triangle vertices must be finite")
    if max_leaf_size < 1:
        raise ValueError("max_leaf_size must be at least 1")
    T = len(vertices)
    if 2 * T >= MAX_EXACT_INDEX:
        raise ValueError(f"{T} triangles: the float32 layout indexes at most {MAX_EXACT_INDEX // 2 - 1}")
    v64 = vertices.astype(np.float64)
    tri_min, tri_max = v64.min(1), v64.max(1)
    centroids = (tri_min + tri_max) / 2

    nodes = []                  # [min(3), a, max(3), count] per node, pre-order
    order = []                  # original indices in leaf order
    placed = 0
    depth_seen = 0

    def emit(ids: np.ndarray, depth: int) -> None:
        nonlocal placed, depth_seen
        depth_seen = max(depth_seen, depth)
        lo, hi = tri_min[ids].min(0), tri_max[ids].max(0)
        index = len(nodes)
        nodes.append([lo, 0, hi, 0])
        n = len(ids)
        split = None
        if n > max_leaf_size:
            if depth < MAX_DEPTH - 24:
                split = _sah_split(centroids[ids], tri_min[ids], tri_max[ids], bins)
            if split is None:
                split = (None, _median_split(centroids[ids]), None)
        if not split:
            nodes[index][1], nodes[index][3] = placed, n
            order.append(ids)
            placed += n
            return
        left = split[1]
        emit(ids[left], depth + 1)
        nodes[index][1] = len(nodes)
        emit(ids[~left], depth + 1)

    emit(np.arange(T), 0)
    if depth_seen >= MAX_DEPTH:
        raise ValueError(f"BVH depth {depth_seen} exceeds the traversal stack ({MAX_DEPTH})")
    flat = np.zeros((len(nodes), 2, 4), np.float32)
    for i, (lo, a, hi, count) in enumerate(nodes):
        flat[i, 0, :3], flat[i, 0, 3], flat[i, 1, :3], flat[i, 1, 3] = lo, a, hi, count
    order = np.concatenate(order)
    triangles = np.zeros((T, 3, 4), np.float32)
    triangles[:, :, :3] = vertices[order]
    triangles[:, 0, 3] = order
    return Bvh(flat, triangles, depth_seen)


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
    depth = np.zeros(len(nodes), np.int64)                  # pre-order: a parent precedes
    for _ in range(bvh.depth):                              # its children, so one pass per
        depth[left] = depth[inner] + 1                      # level settles every depth
        depth[right] = depth[inner] + 1
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


def mesh_vertices(positions, faces) -> np.ndarray:
    """(F, 3, 3) float32 triangle vertices of a mesh (positions (V, 3), faces (F, 3))."""
    return np.asarray(positions, np.float32)[np.asarray(faces)]


def texels(array: np.ndarray, width: int = TEXTURE_WIDTH) -> np.ndarray:
    """(rows, width, 4) float32: the RGBA texels of `array` (..., 4) in order, row by row, the
    last row padded with zeros; `width` (a power of two) to a row, or the smallest power of two
    that holds them all if that is narrower."""
    if width < 1 or width & (width - 1):
        raise ValueError(f"the texture width must be a power of two, got {width}")
    flat = np.asarray(array, np.float32).reshape(-1, 4)
    width = min(width, 1 << max(len(flat) - 1, 0).bit_length())
    rows = -(-len(flat) // width)
    out = np.zeros((rows * width, 4), np.float32)
    out[: len(flat)] = flat
    return out.reshape(rows, width, 4)
