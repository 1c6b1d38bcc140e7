// Twin: reference/radiosity/display.py
#version 330 core
// The interpolated radiosity is the pixel's linear colour, opaque; the view depth beside it. An
// element reflects and emits from its front only: its back, seen, is black.
// SPECULAR: the front adds the direct specular term at the fragment (glsl/radiosity/specular.glsl).

in vec3 v_radiosity;
in float v_view_depth;

#ifdef SPECULAR
#include "radiosity/specular.glsl"
in vec3 v_position;
in vec3 v_normal;
flat in vec3 v_ks;
flat in float v_shininess;
flat in int v_object;
#endif

layout(location = 0) out vec4 out_color;
layout(location = 1) out float out_view_depth;

void main() {
    vec3 colour = vec3(0.0);
    if (gl_FrontFacing) {
        colour = v_radiosity;
#ifdef SPECULAR
        colour += radiosity_specular(v_position, normalize_or_zero(v_normal), v_ks, v_shininess, v_object);
#endif
    }
    out_color = vec4(colour, 1.0);
    out_view_depth = v_view_depth;
}
