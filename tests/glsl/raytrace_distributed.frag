#version 330 core
// Test shader for tests/test_raytrace_distributed.py: per pixel, the bits of sample u_k's
// distributed_2d point (u_dimension at u_slot, point u_m of u_per_sample) and distributed_1d
// point, and permute(u_k, u_length, the pixel's x * 7919 + y).
#include "raytrace/sampling.glsl"
uniform int u_k;
uniform uint u_slot;
uniform uint u_dimension;
uniform uint u_m;
uniform uint u_per_sample;
uniform uint u_length;
out uvec4 out_value;

void main() {
    uvec2 pixel = uvec2(gl_FragCoord.xy);
    vec2 point = distributed_2d(pixel, u_k, u_slot, u_dimension, u_m, u_per_sample);
    float line = distributed_1d(pixel, u_k, u_slot, u_dimension);
    uint p = permute(uint(u_k) % u_length, u_length, pixel.x * 7919u + pixel.y);
    out_value = uvec4(floatBitsToUint(point), floatBitsToUint(line), p);
}
