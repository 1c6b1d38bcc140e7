"""# Twin: glsl/raytrace/bvh.glsl

The closest hit of rays against the triangles of a BVH (renderer/core/bvh.py: the layout), in
float32 as the GLSL (or float64, the ground truth), vectorised over rays: a wavefront of
(ray, node) pairs, one level of the tree per step (no Python loop over rays or nodes). The
ray-box test and the triangle test are the GLSL's (`ray_box` below; `ray_triangle` of
intersect.py), so each pair decides as the GLSL does; the order differs (the GLSL goes depth
first, nearer child first), so where triangles are hit at the same s (an edge or vertex they
share, a corner where two walls meet) both take the lowest original index among them, the
order's answer in neither (docs/conventions.md, BVH). `any_hit` (shadow rays)
answers whether closest_hit would hit, dropping each ray from the wavefront at its first hit,
as the GLSL's bvh_any_hit stops at its first. Both walk the tree whose root node is `root`: 0,
or one of the trees of a forest (renderer/core/bvh.py, motion blur).

Ray-box (slab) test with 1/D precomputed, IEEE: 1/(+-0) = +-inf. An axis whose 1/D is
infinite (D's component 0, or so small that 1/D overflows) is parallel to its slab: it admits
the whole line when O lies in the closed slab [min, max], and nothing otherwise (the products
(min - O)/D would be 0 * inf = NaN where O is on the slab's face; they are not used).
Otherwise lo = (min - O) * invD, hi = (max - O) * invD, near = max(s_min, min(lo, hi) over
axes), far = min(s_max, BOX_FAR_SCALE * max-side), and the box is hit when near <= far. The
far end is widened by BOX_FAR_SCALE = 1 + 3 * 2^-23 (about 1 + 2 gamma_3, Ize, "Robust BVH Ray
Traversal", JCGT 2(2) 2013) so that rounding in the slabs (and a 1/D that llvmpipe computes an
ulp off) does not lose a triangle lying on a box's face.

In float64 (rays O, D of that dtype) the same walk runs on the same float32 boxes with the
scene's float64 triangles (`vertices`): those lie within half a float32 ulp of the float32
vertices the boxes were built from, so each box is widened by one float32 ulp on every side
(nextafter) to hold them, and the far end by 1 + 3 eps64.
"""

from __future__ import annotations

import numpy as np

from reference.raytrace.intersect import ray_triangle

F32 = np.float32
BOX_FAR_SCALE = F32(1 + 3 * 2.0 ** -23)


def _dtype(O) -> np.dtype:
    """float64 for float64 rays (the ground truth), else float32 (the GLSL's)."""
    return np.dtype(np.float64) if np.asarray(O).dtype == np.float64 else np.dtype(F32)


def _far_scale(dtype):
    return BOX_FAR_SCALE if dtype == F32 else dtype.type(1 + 3 * np.finfo(dtype).eps)


def inverse_direction(D):
    dtype = _dtype(D)
    with np.errstate(divide="ignore", over="ignore"):
        return (dtype.type(1) / np.asarray(D, dtype)).astype(dtype)


def ray_box(O, inv_D, bmin, bmax, s_min, s_max):
    """(hit, near) for rays (..., 3) against boxes (..., 3), in the dtype of O (float32 or
    float64), as the GLSL's bvh_ray_box."""
    dtype = _dtype(O)
    O, inv_D, bmin, bmax = (np.asarray(a, dtype) for a in (O, inv_D, bmin, bmax))
    inf = dtype.type(np.inf)
    with np.errstate(invalid="ignore", over="ignore"):
        lo = (bmin - O) * inv_D
        hi = (bmax - O) * inv_D
        tn, tf = np.minimum(lo, hi), np.maximum(lo, hi)
    parallel = np.isinf(inv_D)
    inside = (O >= bmin) & (O <= bmax)
    tn = np.where(parallel, np.where(inside, -inf, inf), tn)
    tf = np.where(parallel, np.where(inside, inf, -inf), tf)
    near = np.maximum(np.maximum(tn[..., 0], tn[..., 1]),
                      np.maximum(tn[..., 2], np.asarray(s_min, dtype)))
    with np.errstate(over="ignore"):
        far = np.minimum(np.minimum(tf[..., 0], tf[..., 1]), tf[..., 2]) * _far_scale(dtype)
    far = np.minimum(far, np.asarray(s_max, dtype))
    return near <= far, near


def _walk(bvh, O, D, s_min, vertices):
    """What both walks start from: the rays in their dtype (O, D, 1/D, s_min per ray), the
    nodes and the triangles' vertices (T, 3, 3) in leaf order; with float64 `vertices` (by
    original index) the boxes widened by a float32 ulp to hold them."""
    dtype = _dtype(O)
    O = np.asarray(O, dtype).reshape(-1, 3)
    D = np.asarray(D, dtype).reshape(-1, 3)
    s_min = np.broadcast_to(np.asarray(s_min, dtype), (len(O),))
    nodes, tris = bvh.nodes, bvh.triangles[..., :3]
    if vertices is not None:
        lo = np.nextafter(nodes[:, 0, :3], F32(-np.inf))
        hi = np.nextafter(nodes[:, 1, :3], F32(np.inf))
        nodes = np.stack([np.concatenate([lo, nodes[:, 0, 3:]], -1),
                          np.concatenate([hi, nodes[:, 1, 3:]], -1)], 1)
        tris = np.asarray(vertices, dtype)[bvh.original_index]
    return dtype, O, D, inverse_direction(D), s_min, nodes, tris


def _visit(nodes, O, inv_D, ray, node, s_min, s_max):
    """The (ray, node) pairs whose box the ray meets, with each node's first texel and whether
    it is a leaf."""
    n0, n1 = nodes[node, 0], nodes[node, 1]
    hit, _ = ray_box(O[ray], inv_D[ray], n0[:, :3], n1[:, :3], s_min, s_max)
    return ray[hit], node[hit], n0[hit], n1[hit, 3] > 0


def _leaf_pairs(ray, n0, leaf, count):
    """(ray, triangle) for every triangle of every leaf pair: triangles a .. a + count - 1."""
    count = count[leaf].astype(np.int64)
    starts = np.cumsum(count) - count
    first = n0[leaf, 3].astype(np.int64)
    return np.repeat(ray[leaf], count), np.repeat(first - starts, count) + np.arange(count.sum())


def _triangles(O, D, tris, r, t, s_min, s_max):
    """ray_triangle of each (ray r, triangle t) pair, s_min and s_max per ray."""
    v = tris[t]
    return ray_triangle(O[r], D[r], v[:, 0], v[:, 1], v[:, 2], s_min[r], s_max[r])


def _children(ray, node, n0, inner):
    """The next level of the wavefront: both children (left = i + 1, right = a) of each
    interior pair."""
    children = np.stack([node[inner] + 1, n0[inner, 3].astype(np.int64)], axis=1).reshape(-1)
    return np.repeat(ray[inner], 2), children


def closest_hit(bvh, O, D, s_min=0.0, s_max=np.inf, vertices=None, root=0):
    """(hit, s, uv, triangle) for rays O, D (R, 3): whether a triangle is hit with
    s_min < s < s_max (scalars or per ray), the nearest such s (s_max on a miss), its (u, v),
    and the triangle's original index (-1 on a miss). float32 as the GLSL, or float64 for float64 rays;
    `vertices` (T, 3, 3), by original index, replace the BVH's float32 triangles (the float64
    twin passes the scene's float64 ones; the boxes are widened to hold them)."""
    dtype, O, D, inv_D, s_min, nodes, tris = _walk(bvh, O, D, s_min, vertices)
    R = len(O)
    best_s = np.full(R, dtype.type(s_max), dtype)
    best_uv = np.zeros((R, 2), dtype)
    best = np.full(R, -1, np.int64)                     # the hit's original index
    ray = np.arange(R)
    node = np.full(R, root, np.int64)
    while ray.size:
        ray, node, n0, leaf = _visit(nodes, O, inv_D, ray, node, s_min[ray], best_s[ray])
        # leaves: every (ray, triangle) pair, then the nearest hit per ray, of equal ones the
        # lowest original index (the GLSL's bvh_nearer_triangle: whatever the walk's order)
        r, t = _leaf_pairs(ray, n0, leaf, nodes[node, 1, 3])
        if r.size:
            h, s, uv = _triangles(O, D, tris, r, t, s_min, np.nextafter(best_s, dtype.type(np.inf)))
            r, s, uv, t = r[h], s[h], uv[h], bvh.original_index[t[h]]
            if r.size:
                order = np.lexsort((t, s, r))           # per ray: nearest s, then lowest index
                r, s, uv, t = r[order], s[order], uv[order], t[order]
                first = np.r_[True, r[1:] != r[:-1]]
                r, s, uv, t = r[first], s[first], uv[first], t[first]
                better = (s < best_s[r]) | ((s == best_s[r]) & (t < best[r]))
                r, s, uv, t = r[better], s[better], uv[better], t[better]
                best_s[r], best_uv[r], best[r] = s, uv, t
        ray, node = _children(ray, node, n0, ~leaf)
    return best >= 0, best_s, best_uv, best


def any_hit(bvh, O, D, s_min=0.0, s_max=np.inf, vertices=None, root=0):
    """Whether each ray O, D (R, 3) hits a triangle with s_min < s < s_max (scalars or per
    ray): closest_hit's `hit`, found as the GLSL's bvh_any_hit finds it, a ray leaving the walk
    at its first hit. Dtypes and `vertices` as closest_hit."""
    dtype, O, D, inv_D, s_min, nodes, tris = _walk(bvh, O, D, s_min, vertices)
    R = len(O)
    s_max = np.broadcast_to(np.asarray(s_max, dtype), (R,))
    blocked = np.zeros(R, bool)
    ray = np.arange(R)
    node = np.full(R, root, np.int64)
    while ray.size:
        ray, node, n0, leaf = _visit(nodes, O, inv_D, ray, node, s_min[ray], s_max[ray])
        r, t = _leaf_pairs(ray, n0, leaf, nodes[node, 1, 3])
        blocked[r[_triangles(O, D, tris, r, t, s_min, s_max)[0]]] = True
        ray, node = _children(ray, node, n0, ~leaf & ~blocked[ray])
    return blocked


def closest_hit_brute_force(vertices, O, D, s_min=0.0, s_max=np.inf, chunk=1 << 20):
    """(hit, s, uv, triangle): every ray against every triangle (T, 3, 3) with ray_triangle in
    float32, the nearest hit (the lowest index among equal s)."""
    V = np.asarray(vertices, F32)
    O = np.asarray(O, F32).reshape(-1, 3)
    D = np.asarray(D, F32).reshape(-1, 3)
    R, T = len(O), len(V)
    s_out = np.full(R, F32(s_max), F32)
    uv_out = np.zeros((R, 2), F32)
    tri_out = np.full(R, -1, np.int64)
    step = max(1, chunk // T)
    for i in range(0, R, step):
        shape = (len(O[i:i + step]), T, 3)
        o = np.broadcast_to(O[i:i + step, None], shape)
        d = np.broadcast_to(D[i:i + step, None], shape)
        h, s, uv = ray_triangle(o, d, V[None, :, 0], V[None, :, 1], V[None, :, 2],
                                F32(s_min), F32(s_max))
        k = np.argmin(s, axis=1)
        rows = np.arange(len(k))
        hit = h[rows, k]
        s_out[i:i + step] = s[rows, k]
        uv_out[i:i + step] = uv[rows, k]
        tri_out[i:i + step] = np.where(hit, k, -1)
    return tri_out >= 0, s_out, uv_out, tri_out
