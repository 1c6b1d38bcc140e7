// Twin: reference/fragment.py
#version 330 core
// Per-fragment shading. Flat and Gouraud pick the colour lit for the side seen
// (gl_FrontFacing: counter-clockwise in window coordinates); Phong renormalises the
// interpolated normal, flips it for a two-sided back face, and lights the fragment.
// out_color is clamped and converted to unorm8 by GL; LINEAR_OUTPUT adds the unclamped
// float colour as a second output. Alpha is 1: the background is cleared to alpha 0.
// SHADOW_MAPS (Phong, an object that receives shadows in a scene with maps): each light's
// diffuse and specular terms are multiplied by its visibility from the shadow maps
// (lighting.glsl's SHADOWS hook, answered by shadow/lookup.glsl).

#if defined(SHADING_PHONG)
#ifdef SHADOW_MAPS
#define SHADOWS
#endif
#include "lighting.glsl"
#ifdef SHADOW_MAPS
#include "shadow/lookup.glsl"
#endif
in vec3 v_world_position;
in vec3 v_world_normal;
#elif defined(SHADING_FLAT)
flat in vec3 f_color_front;          // from geometry.glsl, one per triangle
#ifdef TWO_SIDED
flat in vec3 f_color_back;
#endif
#else
in vec3 v_color_front;               // from vertex.glsl, interpolated
#ifdef TWO_SIDED
in vec3 v_color_back;
#endif
#endif

// A back face seen is lit from its own side only for a two-sided material. The all-features
// build compiles that code for every material and asks u_two_sided at run time.
#ifdef ALL_FEATURES
uniform bool u_two_sided;
#define BACK_FACE_LIT (!gl_FrontFacing && u_two_sided)
#else
#define BACK_FACE_LIT (!gl_FrontFacing)
#endif

layout(location = 0) out vec4 out_color;
#ifdef LINEAR_OUTPUT
layout(location = 1) out vec4 out_linear_color;
#endif

void main() {
#if defined(SHADING_PHONG)
    vec3 N = normalize_or_zero(v_world_normal);
#ifdef TWO_SIDED
    if (BACK_FACE_LIT) {
        N = -N;                      // the back face is seen: light its side
    }
#endif
    vec3 color = lighting(v_world_position, N);
#elif defined(SHADING_FLAT)
#ifdef TWO_SIDED
    vec3 color = BACK_FACE_LIT ? f_color_back : f_color_front;
#else
    vec3 color = f_color_front;
#endif
#else
#ifdef TWO_SIDED
    vec3 color = BACK_FACE_LIT ? v_color_back : v_color_front;
#else
    vec3 color = v_color_front;
#endif
#endif
    out_color = vec4(color, 1.0);
#ifdef LINEAR_OUTPUT
    out_linear_color = vec4(color, 1.0);
#endif
}
