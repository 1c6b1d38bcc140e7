// Twin: reference/raytrace/bvh.py
// The closest hit of a ray P = O + s D against the triangles of a BVH (docs/conventions.md,
// "Rays"), traversed depth first with a fixed stack, the nearer child first; and whether any
// triangle is hit (shadow rays), which stops at the first hit it finds. Both walk the tree whose
// root is `root`: 0, or tree `root` of a forest (renderer/core/bvh.py, motion blur). The BVH is
// two RGBA32F textures in the layout of renderer/core/bvh.py's Walk (texel k at (k % width,
// k / width), the width a power of two):
//   entries:   tree r's root: texel 4r = [min.xyz, ref], 4r + 1 = [max.xyz, 0]; an interior
//              node's entry e: texels 4e, 4e + 1 = its left child's [min.xyz, ref], [max.xyz, 0],
//              4e + 2, 4e + 3 = its right child's; ref >= 0: that child's entry (an interior
//              node), ref < 0: a leaf of the triangles from -ref - 1 to the first flagged last
//   triangles: texels 3j, 3j + 1, 3j + 2 = [A.xyz, original index], [B.xyz, last], [C.xyz, 0]
// The builder keeps the depth below BVH_STACK_SIZE: renderer/core/bvh.py's MAX_DEPTH, defined
// before this file (renderer/gpu/shaders.py, FILE_CONSTANTS).
// Needs raytrace/intersect.glsl (ray_triangle).
#include "raytrace/intersect.glsl"

// 1 + 3 * 2^-23: the far end of a slab interval is widened by this (Ize, "Robust BVH Ray
// Traversal", JCGT 2013) so that rounding does not lose a triangle on a box's face.
const float BVH_BOX_FAR_SCALE = 1.00000036;

// Texel k (>= 0) of a texture in that layout. The width is a power of two, so k % width and
// k / width are a mask and a shift (llvmpipe has no vector integer division: it would divide
// lane by lane, twice per fetch); log2(width) is the exponent of float(width), exact for a
// power of two (GLSL 3.30 has no findLSB).
vec4 bvh_texel(sampler2D texture_, int k) {
    int width = textureSize(texture_, 0).x;
    int log2_width = (floatBitsToInt(float(width)) >> 23) - 127;
    return texelFetch(texture_, ivec2(k & (width - 1), k >> log2_width), 0);
}

// Slab test with inv_D = 1 / D (IEEE: +-inf where D's component is 0). An axis with infinite
// inv_D is parallel to its slab: the whole line if min <= O <= max there, nothing otherwise
// (the products, NaN where O is on a face, are not used). Hit when near <= far.
bool bvh_ray_box(vec3 O, vec3 inv_D, vec3 bmin, vec3 bmax, float s_min, float s_max,
                 out float near) {
    float inf = uintBitsToFloat(0x7F800000u);
    vec3 lo = (bmin - O) * inv_D;
    vec3 hi = (bmax - O) * inv_D;
    vec3 tn = min(lo, hi);
    vec3 tf = max(lo, hi);
    bvec3 parallel = isinf(inv_D);
    bvec3 inside = bvec3(step(bmin, O) * step(O, bmax));
    tn = mix(tn, mix(vec3(inf), vec3(-inf), inside), parallel);
    tf = mix(tf, mix(vec3(-inf), vec3(inf), inside), parallel);
    near = max(max(tn.x, tn.y), max(tn.z, s_min));
    float far = min(min(min(tf.x, tf.y), tf.z) * BVH_BOX_FAR_SCALE, s_max);
    return near <= far;
}

// Whether the ray meets in [s_min, s_max] the box at texels k, k + 1 of the entries (a root's,
// or an interior node's child's): near is where it enters, ref that node's ref.
bool bvh_box_at(sampler2D entries, int k, vec3 O, vec3 inv_D, float s_min, float s_max,
                out float near, out int ref) {
    vec4 lo = bvh_texel(entries, k);
    ref = int(lo.w);
    return bvh_ray_box(O, inv_D, lo.xyz, bvh_texel(entries, k + 1).xyz, s_min, s_max, near);
}

// Whether the ray hits triangle j of the triangles texture (vertices A, B, C, original index)
// with s_min < s' < s, nearer than the hit so far: (s, uv, triangle) then become that hit's
// parameter, barycentric (u, v) and original index. `last`: whether j ends its leaf. Both
// walks test a leaf's triangles so.
bool bvh_nearer_triangle(sampler2D triangles, int j, vec3 O, vec3 D, float s_min,
                         inout float s, inout vec2 uv, inout int triangle, out bool last) {
    vec4 a = bvh_texel(triangles, 3 * j);
    vec4 b = bvh_texel(triangles, 3 * j + 1);
    last = b.w > 0.0;
    float hit_s;
    vec2 hit_uv;
    bool hit = ray_triangle(O, D, a.xyz, b.xyz, bvh_texel(triangles, 3 * j + 2).xyz, s_min, s,
                            hit_s, hit_uv);
    if (hit) {
        s = hit_s;
        uv = hit_uv;
        triangle = int(a.w);
    }
    return hit;
}

// Whether a triangle is hit with s_min < s < s_max; s the nearest hit's parameter (s_max on a
// miss), uv its barycentric (u, v), triangle its original index (-1 on a miss).
bool bvh_closest_hit(sampler2D entries, sampler2D triangles, int root, vec3 O, vec3 D,
                     float s_min, float s_max, out float s, out vec2 uv, out int triangle) {
    vec3 inv_D = 1.0 / D;
    s = s_max;
    uv = vec2(0.0);
    triangle = -1;
    int stack[BVH_STACK_SIZE];
    float stack_near[BVH_STACK_SIZE];
    int top = 0;
    float near;
    int ref;
    if (!bvh_box_at(entries, 4 * root, O, inv_D, s_min, s, near, ref)) return false;
    while (true) {
        bool descend = false;
        if (ref < 0) {
            // the leaf's triangles; the test at the end of the body, as a do-while, since
            // llvmpipe runs a body with lanes masked off until every lane of its SIMD group has
            // left: a test at the top ran one whole body more (a triangle, three fetches)
            int j = -ref - 1;
            bool last;
            do {
                bvh_nearer_triangle(triangles, j, O, D, s_min, s, uv, triangle, last);
                ++j;
            } while (!last);
        } else {
            int left, right;
            float near_left, near_right;
            bool hit_left = bvh_box_at(entries, 4 * ref, O, inv_D, s_min, s, near_left, left);
            bool hit_right = bvh_box_at(entries, 4 * ref + 2, O, inv_D, s_min, s, near_right, right);
            if (hit_left && hit_right) {
                bool right_first = near_right < near_left;
                ref = right_first ? right : left;
                if (top < BVH_STACK_SIZE) {
                    stack[top] = right_first ? left : right;
                    stack_near[top] = right_first ? near_left : near_right;
                    ++top;
                }
                descend = true;
            } else if (hit_left || hit_right) {
                ref = hit_left ? left : right;
                descend = true;
            }
        }
        if (descend) continue;
        // pop the next node still nearer than the closest hit so far
        bool found = false;
        while (top > 0 && !found) {
            --top;
            if (stack_near[top] <= s) {
                ref = stack[top];
                found = true;
            }
        }
        if (!found) break;
    }
    return triangle >= 0;
}

// Whether any triangle is hit with s_min < s < s_max (a shadow ray): the same walk, but it stops
// at the first hit it finds and takes the children in stored order (no nearest-first ordering,
// no distances on the stack, s_max fixed), so it answers as bvh_closest_hit's return value.
bool bvh_any_hit(sampler2D entries, sampler2D triangles, int root, vec3 O, vec3 D, float s_min,
                 float s_max) {
    vec3 inv_D = 1.0 / D;
    int stack[BVH_STACK_SIZE];
    int top = 0;
    float near;
    int ref;
    if (!bvh_box_at(entries, 4 * root, O, inv_D, s_min, s_max, near, ref)) return false;
    bool hit = false;
    while (true) {
        bool descend = false;
        if (ref < 0) {
            float s = s_max;                        // stays: the first hit ends the walk
            vec2 uv;
            int triangle;
            int j = -ref - 1;
            bool last;
            do {                                    // the test at the end: see bvh_closest_hit
                hit = bvh_nearer_triangle(triangles, j, O, D, s_min, s, uv, triangle, last);
                ++j;
            } while (!last && !hit);
        } else {
            int left, right;
            float near_left, near_right;
            bool hit_left = bvh_box_at(entries, 4 * ref, O, inv_D, s_min, s_max, near_left, left);
            bool hit_right = bvh_box_at(entries, 4 * ref + 2, O, inv_D, s_min, s_max, near_right, right);
            if (hit_left && hit_right && top < BVH_STACK_SIZE) {
                stack[top] = right;
                ++top;
            }
            ref = hit_left ? left : right;
            descend = hit_left || hit_right;
        }
        if (!descend && top > 0) {
            --top;
            ref = stack[top];
            descend = true;
        }
        if (hit || !descend) break;
    }
    return hit;
}
