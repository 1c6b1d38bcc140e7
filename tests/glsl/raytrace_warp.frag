#version 330 core
// Test shader for tests/test_sampler_statistics.py: per pixel, a warp (warp.glsl) of sample
// u_k's distributed_2d point (u_dimension at u_slot): u_routine 0 the point itself, 1
// square_to_disc, 2 square_to_sphere, 3 square_to_phong_lobe(u_exponent), 4 and 5 b1 and b2
// of orthonormal_basis(square_to_sphere), 6 square_to_cosine_hemisphere.
#include "raytrace/sampling.glsl"
#include "raytrace/warp.glsl"
uniform int u_k;
uniform uint u_slot;
uniform uint u_dimension;
uniform int u_routine;
uniform float u_exponent;
out vec4 out_value;

void main() {
    vec2 u = distributed_2d(uvec2(gl_FragCoord.xy), u_k, u_slot, u_dimension, 0u, 1u);
    vec3 b1, b2;
    orthonormal_basis(square_to_sphere(u), b1, b2);
    if (u_routine == 0) out_value = vec4(u, 0.0, 0.0);
    else if (u_routine == 1) out_value = vec4(square_to_disc(u), 0.0, 0.0);
    else if (u_routine == 2) out_value = vec4(square_to_sphere(u), 0.0);
    else if (u_routine == 3) out_value = vec4(square_to_phong_lobe(u, u_exponent), 0.0);
    else if (u_routine == 4) out_value = vec4(b1, 0.0);
    else if (u_routine == 6) out_value = vec4(square_to_cosine_hemisphere(u), 0.0);
    else out_value = vec4(b2, 0.0);
}
