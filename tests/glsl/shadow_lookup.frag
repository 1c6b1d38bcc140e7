#version 330 core
// Test shader for tests/test_shadow_lookup.py: glsl/shadow/lookup.glsl's functions on inputs
// from an RGBA32F texture, one case per pixel. u_mode 0: out = (shadow_filter(in.xyz, u_layer,
// int(in.w)), 0, 0, 0) on the uploaded array texture (unit 0, as the point lights' stack); 1: out = (cube_face(in.xyz),
// the face's right, up and axis as three base-4 digits (component + 1) each).
#define NUM_POINT_LIGHTS 1
#include "shadow/lookup.glsl"
uniform sampler2D u_inputs;
uniform int u_mode;
uniform float u_layer;
out vec4 out_value;

float digits(vec3 v) {
    return (v.x + 1.0) * 16.0 + (v.y + 1.0) * 4.0 + (v.z + 1.0);
}

void main() {
    vec4 q = texelFetch(u_inputs, ivec2(gl_FragCoord.xy), 0);
    if (u_mode == 0) {
        out_value = vec4(shadow_filter(u_point_shadow_maps, u_point_shadow_map_size, q.xyz, u_layer,
                                       int(q.w)), 0.0, 0.0, 0.0);
    } else {
        int f = cube_face(q.xyz);
        out_value = vec4(float(f), digits(CUBE_FACE_RIGHT[f]), digits(CUBE_FACE_UP[f]),
                         digits(CUBE_FACE_AXIS[f]));
    }
}
