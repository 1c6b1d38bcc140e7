#version 330 core
// Test shader for tests/test_raytrace_bvh.py (and benchmarks/bench_bvh.py): one ray per pixel
// (origins and directions from two float textures) against a BVH's triangles
// (glsl/raytrace/bvh.glsl). out_hit: (s, original triangle index or -1, u, v); with ANY_HIT
// defined, (1 if bvh_any_hit finds a hit else 0, 0, 0, 0).
#include "raytrace/bvh.glsl"
uniform sampler2D u_origins;
uniform sampler2D u_directions;
uniform usampler2D u_nodes;
uniform sampler2D u_triangles;
uniform float u_s_min;
uniform float u_s_max;
uniform int u_root;                 // the tree walked (a forest's; 0 unless set)
layout(location = 0) out vec4 out_hit;

void main() {
    ivec2 pixel = ivec2(gl_FragCoord.xy);
    vec3 O = texelFetch(u_origins, pixel, 0).xyz;
    vec3 D = texelFetch(u_directions, pixel, 0).xyz;
#ifdef ANY_HIT
    out_hit = vec4(bvh_any_hit(u_nodes, u_triangles, u_root, O, D, u_s_min, u_s_max) ? 1.0 : 0.0, 0.0, 0.0, 0.0);
#else
    float s;
    vec2 uv;
    int triangle;
    bvh_closest_hit(u_nodes, u_triangles, u_root, O, D, u_s_min, u_s_max, s, uv, triangle);
    out_hit = vec4(s, float(triangle), uv);
#endif
}
