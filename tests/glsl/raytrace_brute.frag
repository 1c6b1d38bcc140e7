#version 330 core
// Test shader for benchmarks/bench_bvh.py: one ray per pixel against every triangle of a BVH's
// triangle texture in turn (brute force, the baseline of the BVH's speed-up).
// out_hit: (s, original triangle index or -1, u, v), as raytrace_bvh.frag.
#include "raytrace/bvh.glsl"
uniform sampler2D u_origins;
uniform sampler2D u_directions;
uniform sampler2D u_triangles;
uniform int u_count;
uniform float u_s_min;
uniform float u_s_max;
layout(location = 0) out vec4 out_hit;

void main() {
    ivec2 pixel = ivec2(gl_FragCoord.xy);
    vec3 O = texelFetch(u_origins, pixel, 0).xyz;
    vec3 D = texelFetch(u_directions, pixel, 0).xyz;
    float s = u_s_max;
    vec2 uv = vec2(0.0);
    int triangle = -1;
    for (int j = 0; j < u_count; ++j) {
        vec4 A = bvh_texel(u_triangles, 3 * j);
        float hit_s;
        vec2 hit_uv;
        if (ray_triangle(O, D, A.xyz, bvh_texel(u_triangles, 3 * j + 1).xyz,
                         bvh_texel(u_triangles, 3 * j + 2).xyz, u_s_min, s, hit_s, hit_uv)) {
            s = hit_s;
            uv = hit_uv;
            triangle = int(A.w);
        }
    }
    out_hit = vec4(s, float(triangle), uv);
}
