#version 330 core
// Test shader for tests/test_raytrace_sampling.py: per pixel, the bits of sample u_k's offset
// (sampling.glsl, its constants from renderer/core/ray_sampling.py as #defines and uniforms).
#include "raytrace/sampling.glsl"
uniform int u_k;
out uvec2 out_value;

void main() {
    out_value = floatBitsToUint(sample_offset(uvec2(gl_FragCoord.xy), u_k));
}
