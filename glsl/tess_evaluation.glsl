// Twin: reference/tessellation/evaluation.py
#version 410 core
// Tessellation evaluation (notes 4.1; issue 34): every point the tessellator makes in a patch
// (gl_TessCoord, barycentric in GL's triangle domain) placed on the exact surface, with the
// surface's exact normal, in object space. SPACING_* picks the tessellator's spacing
// (equal, fractional_even, fractional_odd); SURFACE_SPHERE: the sphere of centre u_sphere.xyz
// and radius u_sphere.w, each point the patch's barycentric point projected from the centre;
// SURFACE_PN: the patch's PN triangle (renderer/core/tessellation.py), from the net the control
// stage made: the flat point plus each edge's term and the centre's, the normal the paper's
// quadratic. Each edge's term is written so that the edge's two patches compute it alike:
// 3 (t_a t_b) (t_a o_ab + t_b o_ba), products and sums of two, which commute; on an edge the
// other terms are exactly 0. `precise` keeps that order: without it the compiler regroups the
// products (half the points an ulp off the twin's, and an edge's two patches could differ).
// SURFACE_DISPLACED: the point moved along its interpolated normal by S times the height image's
// red channel at its interpolated UV (textureLod, level 0); the normal the displaced surface's,
// from the patch's UV tangents and the height's central differences a texel apart
// (renderer/core/tessellation.py).
// Then the vertex stage's work on the point (glsl/vertex_stage.glsl: world and clip positions,
// Gouraud's lighting, what each shading mode hands on), as glsl/vertex.glsl does for a mesh.
// CAPTURE (tests/test_tessellation_stages.py): instead, the point and its patch's levels handed
// on to transform feedback.

#if defined(SPACING_EQUAL)
layout(triangles, equal_spacing, ccw) in;
#elif defined(SPACING_FRACTIONAL_EVEN)
layout(triangles, fractional_even_spacing, ccw) in;
#else
layout(triangles, fractional_odd_spacing, ccw) in;
#endif

uniform vec4 u_sphere;               // object space: centre xyz, radius w

in vec3 c_position[];
in vec3 c_normal[];
#ifdef SURFACE_DISPLACED
uniform sampler2D u_height;          // the height image, on DISPLACEMENT_TEXTURE_UNIT
uniform vec2 u_height_size;          // width, height in texels
uniform vec2 u_height_texel;         // 1 / width, 1 / height
uniform float u_displacement_scale;  // S
in vec2 c_st[];                      // the corners' lookup coordinates
patch in vec3 c_tangent_s;
patch in vec3 c_tangent_t;

float height_at(vec2 st) {
    return textureLod(u_height, st, 0.0).r;
}
#endif
#ifdef SURFACE_PN
patch in vec3 c_offset[6];
patch in vec3 c_centre;
patch in vec3 c_mid_normal[3];

// edge k's term (corners i = k + 1, j = k + 2, mod 3)
vec3 pn_edge(float ti, float tj, vec3 o_ij, vec3 o_ji) {
    return (3.0 * (ti * tj)) * (ti * o_ij + tj * o_ji);
}
#endif

#ifdef CAPTURE
out vec3 t_position;                 // object space, on the surface
out vec3 t_normal;                   // object space, unit
out vec4 t_levels;                   // gl_TessLevelOuter[0..2], gl_TessLevelInner[0]
#else
#include "vertex_stage.glsl"
#endif

void main() {
    vec3 p = gl_TessCoord.x * c_position[0] + gl_TessCoord.y * c_position[1] + gl_TessCoord.z * c_position[2];
#if defined(SURFACE_SPHERE)
    vec3 n = normalize(p - u_sphere.xyz);
    vec3 position = u_sphere.xyz + u_sphere.w * n;
#elif defined(SURFACE_PN)
    vec3 t = gl_TessCoord;
    precise vec3 edges = (pn_edge(t.y, t.z, c_offset[0], c_offset[1]) + pn_edge(t.z, t.x, c_offset[2], c_offset[3]))
                         + pn_edge(t.x, t.y, c_offset[4], c_offset[5]);
    precise vec3 position = (p + edges) + (6.0 * ((t.x * t.y) * t.z)) * c_centre;
    precise vec3 n = normalize(((((t.x * t.x) * c_normal[0] + (t.y * t.y) * c_normal[1]) + (t.z * t.z) * c_normal[2])
                        + ((t.y * t.z) * c_mid_normal[0] + (t.z * t.x) * c_mid_normal[1]))
                       + (t.x * t.y) * c_mid_normal[2]);
#elif defined(SURFACE_DISPLACED)
    vec3 t = gl_TessCoord;
    precise vec2 st = (t.x * c_st[0] + t.y * c_st[1]) + t.z * c_st[2];
    precise vec3 along = normalize((t.x * c_normal[0] + t.y * c_normal[1]) + t.z * c_normal[2]);
    precise vec3 position = p + along * (height_at(st) * u_displacement_scale);
    float dh_ds = (height_at(st + vec2(u_height_texel.x, 0.0)) - height_at(st - vec2(u_height_texel.x, 0.0)))
                  * (u_height_size.x * 0.5);
    float dh_dt = (height_at(st + vec2(0.0, u_height_texel.y)) - height_at(st - vec2(0.0, u_height_texel.y)))
                  * (u_height_size.y * 0.5);
    precise vec3 across = cross(c_tangent_s + along * (u_displacement_scale * dh_ds),
                                c_tangent_t + along * (u_displacement_scale * dh_dt));
    precise vec3 n = normalize(dot(across, along) < 0.0 ? -across : across);
#else
    vec3 n = normalize(gl_TessCoord.x * c_normal[0] + gl_TessCoord.y * c_normal[1] + gl_TessCoord.z * c_normal[2]);
    vec3 position = p;
#endif
#ifdef CAPTURE
    t_position = position;
    t_normal = n;
    t_levels = vec4(gl_TessLevelOuter[0], gl_TessLevelOuter[1], gl_TessLevelOuter[2], gl_TessLevelInner[0]);
    gl_Position = vec4(position, 1.0);
#else
    vertex_stage(position, n);
#endif
}
