"""The BVH build as it was before issue 32: a node at a time, recursing in Python (the
binned SAH of renderer/core/bvh.py's docstring, ties to the lower axis, then the lower bin;
the object median where no split is found or the tree is deep). Kept as the oracle that the
level-by-level build (renderer/core/bvh.py build_bvh) makes the same tree, split for split:
tests/test_raytrace_bvh.py."""

from __future__ import annotations

import numpy as np

from renderer.core.bvh import BINS, MAX_DEPTH, MAX_LEAF_SIZE, Bvh, build_inputs

SAH_CHUNK = 1 << 15             # triangles binned at once: bounded temporaries


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


def build_bvh_recursive(vertices, max_leaf_size: int = MAX_LEAF_SIZE, bins: int = BINS) -> Bvh:
    """The BVH of triangles `vertices` (T, 3, 3) (A, B, C of each; any float dtype; the layout
    holds them as float32), T >= 1."""
    vertices, tri_min, tri_max, centroids = build_inputs(vertices, max_leaf_size)
    T = len(vertices)

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
