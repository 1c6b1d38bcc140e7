// Twin: reference/tessellation/control.py
#version 410 core
// Tessellation control (notes 4.1; issue 34): each triangle patch of a curved surface passes
// its corners on and asks for the levels that keep the surface's deviation from its chords
// under u_target_error pixels (renderer/core/tessellation.py states the rules and derives them).
// gl_TessLevelOuter[i] is the edge opposite corner i (GL's triangle domain: the edge u = 0
// joins corners 1 and 2); each edge's level depends on its two end points alone, symmetrically,
// so the two patches sharing an edge compute it from the same bits and no crack opens.
// SURFACE_SPHERE: an analytic sphere of radius u_surface_radius (world units). SURFACE_PN: the
// patch's PN triangle; its net's offsets and its edges' mid normals are made here, once a
// patch, for glsl/tess_evaluation.glsl (c_offset, c_centre, c_mid_normal). SURFACE_DISPLACED:
// the patch displaced by a height image; its UV tangents made here (c_tangent_s, c_tangent_t).

layout(vertices = 3) out;

uniform mat4 u_model;                // M_world
uniform mat4 u_view;                 // V
uniform mat4 u_projection;           // P
uniform float u_viewport_height;     // H, pixels
uniform float u_target_error;        // pixels
uniform float u_surface_radius;      // R in world units (0: flat, level 1)
uniform float u_max_level;
uniform float u_fixed_level;         // > 0: this level on every edge and inside (not by need)

in vec3 v_position[];                // object space
in vec3 v_normal[];
out vec3 c_position[];
out vec3 c_normal[];

// the length in world units of an object-space vector
float world_length(vec3 d) {
    return length((u_model * vec4(d, 0.0)).xyz);
}

float clip_w(vec3 world) {
    return (u_projection * (u_view * vec4(world, 1.0))).w;
}

// the target error in world units at clip w (> 0): the target in pixels over the pixels a
// world unit spans there, H P11 / (2 w)
float world_error(float w) {
    float pixels_per_unit = u_viewport_height * u_projection[1][1] / (2.0 * w);
    return u_target_error / pixels_per_unit;
}

#ifdef SURFACE_DISPLACED
uniform vec2 u_height_size;          // the height image's width and height, texels
uniform float u_height_slope;        // g: the largest height step between neighbouring texels
uniform float u_displacement_scale;  // S: object units for a height of 1
uniform vec2 u_height_uv_scale;      // the lookup st = uv * scale + offset
uniform vec2 u_height_uv_offset;
in vec2 v_uv[];
out vec2 c_st[];                     // the corners' lookup coordinates
patch out vec3 c_tangent_s;          // dP/ds, dP/dt of the patch (object space)
patch out vec3 c_tangent_t;

// st = uv * scale + offset, rounded after the product and after the sum (as glsl/texture.glsl)
vec2 lookup_st(vec2 uv) {
    vec2 st = uv * u_height_uv_scale;
    return st + u_height_uv_offset;
}

// the edge from a to b (world) of lookup coordinates ua to ub and object normals na, nb: a part per texel
// at most, and as few as keep the height's stray from the chords within the target
float displaced_edge_level(vec3 a, vec3 b, vec3 na, vec3 nb, vec2 ua, vec2 ub) {
    if (u_fixed_level > 0.0)
        return u_fixed_level;
    vec2 span = abs(ub - ua) * u_height_size;
    float texels = max(span.x, span.y);
    float w = clip_w((a + b) * 0.5);
    float level = texels;
    if (w > 0.0) {
        float e = world_error(w);
        float s = u_displacement_scale * max(world_length(na), world_length(nb));
        level = min(texels * (u_height_slope * s) / (2.0 * e), texels);
    }
    return clamp(level, 1.0, u_max_level);
}
#endif

#ifdef SURFACE_PN
const float PN_CURVE_BOUND = 0.75;   // renderer/core/tessellation.py
const float ONE_THIRD = 0.33333334;  // float32(1 / 3)
in float v_straight[];
// c_offset[2k], c_offset[2k + 1]: o_ij, o_ji of edge k (corners i = k + 1, j = k + 2, mod 3)
patch out vec3 c_offset[6];
patch out vec3 c_centre;             // the net's centre's offset: the six offsets' sum / 4
patch out vec3 c_mid_normal[3];      // edge k's: n_ij

// o_ab: how far the net's point near corner a on the edge to b leaves the flat triangle
vec3 pn_offset(vec3 pa, vec3 na, vec3 pb) {
    float w = dot(pb - pa, na);
    return na * (-w * ONE_THIRD);
}

vec3 pn_mid_normal(vec3 pa, vec3 na, vec3 pb, vec3 nb) {
    vec3 e = pb - pa;
    float e2 = dot(e, e);
    float v = e2 > 0.0 ? 2.0 * dot(e, na + nb) / e2 : 0.0;
    return normalize((na + nb) - v * e);
}

// the level that keeps a cubic whose control points' largest second difference is m (world
// units) within the target of its chords, seen at clip w
float pn_level(float m, float w) {
    if (!(w > 0.0))
        return u_max_level;
    float level = sqrt(PN_CURVE_BOUND * m / world_error(w));
    return clamp(level, 1.0, u_max_level);
}

// edge k's level from its ends alone: its two second differences swap with the ends
float pn_edge_level(vec3 a, vec3 b, vec3 o_ab, vec3 o_ba) {
    if (u_fixed_level > 0.0)
        return u_fixed_level;
    float m = max(world_length(o_ba - 2.0 * o_ab), world_length(o_ab - 2.0 * o_ba));
    return pn_level(m, clip_w((a + b) * 0.5));
}
#endif

float edge_level(vec3 a, vec3 b) {
    if (u_fixed_level > 0.0)
        return u_fixed_level;
    float R = u_surface_radius;
    if (!(R > 0.0))
        return 1.0;
    float w = clip_w((a + b) * 0.5);
    if (!(w > 0.0))
        return u_max_level;                                   // at or behind the eye
    float s = world_error(w) / R;                             // e / R
    if (!(s < 1.0))
        return 1.0;
    vec3 chord_vector = a - b;
    float c2 = dot(chord_vector, chord_vector);
    float c = sqrt(c2);
    float d = sqrt(max(R * R - c2 * 0.25, 0.0));
    if (!(d > 0.0))
        return u_max_level;                                   // a chord across the sphere
    float level = c * (1.0 - s) / (2.0 * d * sqrt(s * (2.0 - s)));
    return clamp(level, 1.0, u_max_level);
}

// the patch's levels (outer 0..2, inner) from its world corners; a PN patch's net and a
// displaced patch's tangents handed on too
#if defined(SURFACE_PN)
vec4 patch_levels(vec3 p0, vec3 p1, vec3 p2) {
    vec3 offsets[6];
    for (int k = 0; k < 3; k++) {
        int i = (k + 1) % 3, j = (k + 2) % 3;
        bool curved = !(v_straight[k] > 0.5);
        offsets[2 * k] = curved ? pn_offset(v_position[i], v_normal[i], v_position[j]) : vec3(0.0);
        offsets[2 * k + 1] = curved ? pn_offset(v_position[j], v_normal[j], v_position[i]) : vec3(0.0);
        c_offset[2 * k] = offsets[2 * k];
        c_offset[2 * k + 1] = offsets[2 * k + 1];
        c_mid_normal[k] = pn_mid_normal(v_position[i], v_normal[i], v_position[j], v_normal[j]);
    }
    vec3 centre = (((((offsets[0] + offsets[1]) + offsets[2]) + offsets[3]) + offsets[4]) + offsets[5]) * 0.25;
    c_centre = centre;
    float outer0 = pn_edge_level(p1, p2, offsets[0], offsets[1]);
    float outer1 = pn_edge_level(p2, p0, offsets[2], offsets[3]);
    float outer2 = pn_edge_level(p0, p1, offsets[4], offsets[5]);
    float inner = max(max(outer0, outer1), outer2);
    if (!(u_fixed_level > 0.0)) {
        // the interior's second differences: (o_ik + o_jk) - 2 c for corner k (the two
        // offsets on the edges to k, near their other ends): corners 2, 0, 1 in turn
        float m = max(max(world_length((offsets[3] + offsets[0]) - 2.0 * centre),
                          world_length((offsets[5] + offsets[2]) - 2.0 * centre)),
                      world_length((offsets[1] + offsets[4]) - 2.0 * centre));
        inner = max(inner, pn_level(m, clip_w(((p0 + p1) + p2) * ONE_THIRD)));
    }
    return vec4(outer0, outer1, outer2, inner);
}
#elif defined(SURFACE_DISPLACED)
vec4 patch_levels(vec3 p0, vec3 p1, vec3 p2) {
    vec2 st0 = lookup_st(v_uv[0]);
    vec2 st1 = lookup_st(v_uv[1]);
    vec2 st2 = lookup_st(v_uv[2]);
    vec3 e1 = v_position[1] - v_position[0];
    vec3 e2 = v_position[2] - v_position[0];
    vec2 d1 = st1 - st0;
    vec2 d2 = st2 - st0;
    float det = d1.x * d2.y - d2.x * d1.y;
    float r = det != 0.0 ? 1.0 / det : 0.0;
    c_tangent_s = (e1 * d2.y - e2 * d1.y) * r;
    c_tangent_t = (e2 * d1.x - e1 * d2.x) * r;
    float outer0 = displaced_edge_level(p1, p2, v_normal[1], v_normal[2], st1, st2);
    float outer1 = displaced_edge_level(p2, p0, v_normal[2], v_normal[0], st2, st0);
    float outer2 = displaced_edge_level(p0, p1, v_normal[0], v_normal[1], st0, st1);
    return vec4(outer0, outer1, outer2, max(max(outer0, outer1), outer2));
}
#else
vec4 patch_levels(vec3 p0, vec3 p1, vec3 p2) {
    float outer0 = edge_level(p1, p2);
    float outer1 = edge_level(p2, p0);
    float outer2 = edge_level(p0, p1);
    return vec4(outer0, outer1, outer2, max(max(outer0, outer1), outer2));
}
#endif

void main() {
    c_position[gl_InvocationID] = v_position[gl_InvocationID];
    c_normal[gl_InvocationID] = v_normal[gl_InvocationID];
#ifdef SURFACE_DISPLACED
    c_st[gl_InvocationID] = lookup_st(v_uv[gl_InvocationID]);
#endif
    if (gl_InvocationID == 0) {
        vec3 p0 = (u_model * vec4(v_position[0], 1.0)).xyz;
        vec3 p1 = (u_model * vec4(v_position[1], 1.0)).xyz;
        vec3 p2 = (u_model * vec4(v_position[2], 1.0)).xyz;
        vec4 levels = patch_levels(p0, p1, p2);
        gl_TessLevelOuter[0] = levels.x;
        gl_TessLevelOuter[1] = levels.y;
        gl_TessLevelOuter[2] = levels.z;
        gl_TessLevelInner[0] = levels.w;
    }
}
