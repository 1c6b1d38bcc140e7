#version 330 core
// Test shader for tests/test_raytrace_random.py: per pixel, the stream of (x, y, u_sample,
// u_bounce, u_seed), its numbers 0 and 1, and the bits of its float number 2.
#include "raytrace/random.glsl"
uniform uint u_sample;
uniform uint u_bounce;
uniform uint u_seed;
out uvec4 out_value;

void main() {
    uvec2 pixel = uvec2(gl_FragCoord.xy);
    uint stream = random_stream(pixel.x, pixel.y, u_sample, u_bounce, u_seed);
    out_value = uvec4(stream, random_uint(stream, 0u), random_uint(stream, 1u),
                      floatBitsToUint(random_float(stream, 2u)));
}
