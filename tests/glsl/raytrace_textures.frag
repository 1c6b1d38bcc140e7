#version 330 core
// Test shader for tests/test_raytrace_textures.py: per pixel, the texel of u_inputs at
// gl_FragCoord.xy holds (x, y, z, 0); out: texture_sphere_uv((x, y, z)) and
// texture_atan2(y, x) (textures.glsl, compiled alone: no shapes, no meshes, one slot).
#define NUM_TEXTURES 1
vec4 trace_texel(sampler2D texture_, int k) { return vec4(0.0); }   // trace.glsl's, unused
vec3 u_ka;
vec3 u_kd;
#include "raytrace/textures.glsl"
uniform sampler2D u_inputs;
out vec4 out_value;

void main() {
    vec3 d = texelFetch(u_inputs, ivec2(gl_FragCoord.xy), 0).xyz;
    out_value = vec4(texture_sphere_uv(d), texture_atan2(d.y, d.x), 0.0);
}
