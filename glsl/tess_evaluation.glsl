// Twin: reference/tessellation/evaluation.py
#version 410 core
// Tessellation evaluation (notes 4.1; issue 34): every point the tessellator makes in a patch
// (gl_TessCoord, barycentric in GL's triangle domain) placed on the exact surface, with the
// surface's exact normal, in object space. SPACING_* picks the tessellator's spacing
// (equal, fractional_even, fractional_odd); SURFACE_SPHERE: the sphere of centre u_sphere.xyz
// and radius u_sphere.w, each point the patch's barycentric point projected from the centre.
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

#ifdef CAPTURE
out vec3 t_position;                 // object space, on the surface
out vec3 t_normal;                   // object space, unit
out vec4 t_levels;                   // gl_TessLevelOuter[0..2], gl_TessLevelInner[0]
#else
#include "vertex_stage.glsl"
#endif

void main() {
    vec3 p = gl_TessCoord.x * c_position[0] + gl_TessCoord.y * c_position[1] + gl_TessCoord.z * c_position[2];
#ifdef SURFACE_SPHERE
    vec3 n = normalize(p - u_sphere.xyz);
    vec3 position = u_sphere.xyz + u_sphere.w * n;
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
