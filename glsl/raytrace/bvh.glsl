// Twin: reference/raytrace/bvh.py
// The closest hit of a ray P = O + s D against the triangles of a BVH (docs/conventions.md,
// "Rays"), traversed depth first with a fixed stack, four boxes a step, the nearest child
// first; and whether any triangle is hit (shadow rays), which stops at the first hit it finds.
// Both walk tree `root`: 0, or one of the trees of a forest (renderer/core/bvh.py, motion
// blur). The BVH is two textures in the layout of renderer/core/bvh.py's Walk (texel k at
// (k % width, k / width), the width a power of two):
//   entries:   RGBA32UI, four texels an entry. Tree r's root: [min.xyz, ref], [max.xyz, 0]
//              (float bits); an interior node's: its up to four children's boxes, quantised
//              (origin + q 2^e, bvh_children), and their refs: >= 0 a child's entry (an
//              interior node), BVH_EMPTY none, another < 0 a leaf of the triangles from
//              -ref - 1 to the first flagged last
//   triangles: RGBA32F, texels 3j, 3j + 1, 3j + 2 = [A.xyz, original index], [B.xyz, last],
//              [C.xyz, 0]
// The builder keeps the depth below BVH_STACK_SIZE: renderer/core/bvh.py's MAX_DEPTH, defined
// before this file (renderer/gpu/shaders.py, FILE_CONSTANTS).
// Needs raytrace/intersect.glsl (ray_triangle).
#include "raytrace/intersect.glsl"

// 1 + 3 * 2^-23: the far end of a slab interval is widened by this (Ize, "Robust BVH Ray
// Traversal", JCGT 2013) so that rounding does not lose a triangle on a box's face.
const float BVH_BOX_FAR_SCALE = 1.00000036;

// Where texel k (>= 0) of a texture in that layout is, and the texel (bvh_texel; bvh_entry
// for the integer texture of entries). The width is a power of two, so k % width and
// k / width are a mask and a shift (llvmpipe has no vector integer division: it would divide
// lane by lane, twice per fetch); log2(width) is the exponent of float(width), exact for a
// power of two (GLSL 3.30 has no findLSB).
ivec2 bvh_address(int width, int k) {
    int log2_width = (floatBitsToInt(float(width)) >> 23) - 127;
    return ivec2(k & (width - 1), k >> log2_width);
}

vec4 bvh_texel(sampler2D texture_, int k) {
    return texelFetch(texture_, bvh_address(textureSize(texture_, 0).x, k), 0);
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

// An unused child's ref (renderer/core/bvh.py EMPTY): below every leaf's.
const int BVH_EMPTY = int(0x80000000u);
// The walk's stack: a step pushes up to three children, and a 4-wide tree is half as deep.
#define BVH_WALK_STACK (3 * (BVH_STACK_SIZE / 2) + 3)

// Texel k of the entries (RGBA32UI, addressed as bvh_texel).
uvec4 bvh_entry(usampler2D entries, int k) {
    return texelFetch(entries, bvh_address(textureSize(entries, 0).x, k), 0);
}

// The four bytes of a word, as floats (child c's in component c).
vec4 bvh_bytes(uint word) {
    return vec4(uvec4(word, word >> 8u, word >> 16u, word >> 24u) & 0xFFu);
}

// The slab of one axis for four boxes at once (bvh_ray_box's, component by component).
void bvh_slabs(float o, float inv_d, vec4 bmin, vec4 bmax, out vec4 tn, out vec4 tf) {
    float inf = uintBitsToFloat(0x7F800000u);
    vec4 lo = (bmin - o) * inv_d;
    vec4 hi = (bmax - o) * inv_d;
    tn = min(lo, hi);
    tf = max(lo, hi);
    if (isinf(inv_d)) {
        bvec4 inside = bvec4(step(bmin, vec4(o)) * step(vec4(o), bmax));
        tn = mix(vec4(inf), vec4(-inf), inside);
        tf = mix(vec4(-inf), vec4(inf), inside);
    }
}

// The children of entry e (up to four): whether the ray meets each one's box in
// [s_min, s_max] (hit), where it enters it (near), and each one's ref (bvh_ray_box's test,
// four boxes at once, on the boxes decoded as origin + q 2^e; an unused child never hit).
void bvh_children(usampler2D entries, int e, vec3 O, vec3 inv_D, float s_min, float s_max,
                  out bvec4 hit, out vec4 near, out ivec4 ref) {
    int k = 4 * e;
    uvec4 t0 = bvh_entry(entries, k);
    uvec4 t1 = bvh_entry(entries, k + 1);
    uvec4 t2 = bvh_entry(entries, k + 2);
    uvec4 t3 = bvh_entry(entries, k + 3);
    vec3 origin = uintBitsToFloat(t0.xyz);
    // 2^e from its biased byte (renderer/core/bvh.py QUANT_BIAS = 127: the byte is the
    // exponent field of 2^e)
    vec3 scale = uintBitsToFloat((uvec3(t0.w, t0.w >> 8u, t0.w >> 16u) & 0xFFu) << 23u);
    vec4 tn_x, tf_x, tn_y, tf_y, tn_z, tf_z;
    bvh_slabs(O.x, inv_D.x, origin.x + bvh_bytes(t1.x) * scale.x,
              origin.x + bvh_bytes(t1.w) * scale.x, tn_x, tf_x);
    bvh_slabs(O.y, inv_D.y, origin.y + bvh_bytes(t1.y) * scale.y,
              origin.y + bvh_bytes(t2.x) * scale.y, tn_y, tf_y);
    bvh_slabs(O.z, inv_D.z, origin.z + bvh_bytes(t1.z) * scale.z,
              origin.z + bvh_bytes(t2.y) * scale.z, tn_z, tf_z);
    ref = ivec4(t2.zw, t3.xy);
    near = max(max(tn_x, tn_y), max(tn_z, vec4(s_min)));
    vec4 far = min(min(min(tf_x, tf_y), tf_z) * BVH_BOX_FAR_SCALE, vec4(s_max));
    hit = bvec4(vec4(lessThanEqual(near, far)) * vec4(notEqual(ref, ivec4(BVH_EMPTY))));
}

// Whether the ray meets tree `root`'s root box in [s_min, s_max] (two texels: the root's entry
// holds it unquantised as [min.xyz, ref], [max.xyz, 0], so that a ray missing it costs two
// fetches); ref: the root's ref.
bool bvh_meets_root(usampler2D entries, int root, vec3 O, vec3 inv_D, float s_min, float s_max,
                    out int ref) {
    uvec4 lo = bvh_entry(entries, 4 * root);
    ref = int(lo.w);
    float near;
    return bvh_ray_box(O, inv_D, uintBitsToFloat(lo.xyz),
                       uintBitsToFloat(bvh_entry(entries, 4 * root + 1).xyz), s_min, s_max, near);
}

// Whether the ray hits triangle j of the triangles texture (vertices A, B, C, original index)
// with s_min < s' < s, nearer than the hit so far, or with s' = s and a lower original index
// than the hit so far's (`triangle`, -1 for none): (s, uv, triangle) then become that hit's
// parameter, barycentric (u, v) and original index. So the closest hit is the nearest, of equal
// ones the lowest original index, whatever order the walk meets them in (two walls meeting at
// a corner give a ray through it the same s; the twin's walk goes level by level).
// `last`: whether j ends its leaf. Both walks test a leaf's triangles so.
bool bvh_nearer_triangle(sampler2D triangles, int j, vec3 O, vec3 D, float s_min,
                         inout float s, inout vec2 uv, inout int triangle, out bool last) {
    vec4 a = bvh_texel(triangles, 3 * j);
    vec4 b = bvh_texel(triangles, 3 * j + 1);
    last = b.w > 0.0;
    float hit_s;
    vec2 hit_uv;
    // s's next float up (s > s_min >= 0), so that ray_triangle's s' < s_max lets s' = s through
    float s_tie = isinf(s) ? s : uintBitsToFloat(floatBitsToUint(s) + 1u);
    bool hit = ray_triangle(O, D, a.xyz, b.xyz, bvh_texel(triangles, 3 * j + 2).xyz, s_min, s_tie,
                            hit_s, hit_uv) && (hit_s < s || int(a.w) < triangle);
    if (hit) {
        s = hit_s;
        uv = hit_uv;
        triangle = int(a.w);
    }
    return hit;
}

// Sort two children by near (a compare-exchange of a sorting network; a tie keeps the order).
void bvh_order(inout float near_a, inout int ref_a, inout float near_b, inout int ref_b) {
    bool swap = near_b < near_a;
    float n = near_a;
    int r = ref_a;
    near_a = swap ? near_b : near_a;
    ref_a = swap ? ref_b : ref_a;
    near_b = swap ? n : near_b;
    ref_b = swap ? r : ref_b;
}

// Whether a triangle is hit with s_min < s < s_max; s the nearest hit's parameter (s_max on a
// miss), uv its barycentric (u, v), triangle its original index (-1 on a miss).
bool bvh_closest_hit(usampler2D entries, sampler2D triangles, int root, vec3 O, vec3 D,
                     float s_min, float s_max, out float s, out vec2 uv, out int triangle) {
    vec3 inv_D = 1.0 / D;
    s = s_max;
    uv = vec2(0.0);
    triangle = -1;
    float inf = uintBitsToFloat(0x7F800000u);
    int stack[BVH_WALK_STACK];
    float stack_near[BVH_WALK_STACK];
    int top = 0;
    int ref;
    if (!bvh_meets_root(entries, root, O, inv_D, s_min, s_max, ref)) return false;
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
            bvec4 hit;
            vec4 near;
            ivec4 child;
            bvh_children(entries, ref, O, inv_D, s_min, s, hit, near, child);
            near = mix(vec4(inf), near, hit);       // the boxes missed sort last
            // the children met, nearest first: a sorting network of five compare-exchanges
            bvh_order(near.x, child.x, near.y, child.y);
            bvh_order(near.z, child.z, near.w, child.w);
            bvh_order(near.x, child.x, near.z, child.z);
            bvh_order(near.y, child.y, near.w, child.w);
            bvh_order(near.y, child.y, near.z, child.z);
            int met = int(hit.x) + int(hit.y) + int(hit.z) + int(hit.w);
            // the farther ones on the stack, the farthest first; the nearest next
            if (met > 3) { stack[top] = child.w; stack_near[top] = near.w; ++top; }
            if (met > 2) { stack[top] = child.z; stack_near[top] = near.z; ++top; }
            if (met > 1) { stack[top] = child.y; stack_near[top] = near.y; ++top; }
            ref = child.x;
            descend = met > 0;
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
bool bvh_any_hit(usampler2D entries, sampler2D triangles, int root, vec3 O, vec3 D, float s_min,
                 float s_max) {
    vec3 inv_D = 1.0 / D;
    int stack[BVH_WALK_STACK];
    int top = 0;
    int ref;
    if (!bvh_meets_root(entries, root, O, inv_D, s_min, s_max, ref)) return false;
    bool hit = false;
    while (true) {
        if (ref < 0) {
            float s = s_max;                        // stays: the first hit ends the walk
            vec2 uv;
            int triangle = -1;
            int j = -ref - 1;
            bool last;
            do {                                    // the test at the end: see bvh_closest_hit
                hit = bvh_nearer_triangle(triangles, j, O, D, s_min, s, uv, triangle, last);
                ++j;
            } while (!last && !hit);
        } else {
            bvec4 met;
            vec4 near;
            ivec4 child;
            bvh_children(entries, ref, O, inv_D, s_min, s_max, met, near, child);
            // the first child met next, the others on the stack (popped in stored order)
            if (met.w) { stack[top] = child.w; ++top; }
            if (met.z) { stack[top] = child.z; ++top; }
            if (met.y) { stack[top] = child.y; ++top; }
            if (met.x) { stack[top] = child.x; ++top; }
        }
        if (hit) break;
        if (top == 0) break;
        --top;
        ref = stack[top];
    }
    return hit;
}
