#version 330 core
// Test shader for tests/test_raytrace_intersect.py: one ray per pixel (origins and directions
// from two float textures) against one sphere, plane and triangle. out_s: the three s (s_max on
// a miss) and a hit mask (1 sphere, 2 plane, 4 triangle); out_extra: the sphere's normal at
// its hit and the robust discriminant; out_uv: the triangle's barycentric (u, v) at its hit.
#include "raytrace/intersect.glsl"
uniform sampler2D u_origins;
uniform sampler2D u_directions;
uniform vec3 u_center;
uniform float u_radius;
uniform vec3 u_plane_normal;
uniform float u_plane_d;
uniform vec3 u_a;
uniform vec3 u_b;
uniform vec3 u_c;
uniform float u_s_min;
uniform float u_s_max;
layout(location = 0) out vec4 out_s;
layout(location = 1) out vec4 out_extra;
layout(location = 2) out vec4 out_uv;

void main() {
    ivec2 pixel = ivec2(gl_FragCoord.xy);
    vec3 O = texelFetch(u_origins, pixel, 0).xyz;
    vec3 D = texelFetch(u_directions, pixel, 0).xyz;
    float s_sphere, s_plane, s_triangle;
    vec2 uv;
    bool sphere = ray_sphere(O, D, u_center, u_radius, u_s_min, u_s_max, s_sphere);
    bool plane = ray_plane(O, D, u_plane_normal, u_plane_d, u_s_min, u_s_max, s_plane);
    bool triangle = ray_triangle(O, D, u_a, u_b, u_c, u_s_min, u_s_max, s_triangle, uv);
    float mask = (sphere ? 1.0 : 0.0) + (plane ? 2.0 : 0.0) + (triangle ? 4.0 : 0.0);
    out_s = vec4(s_sphere, s_plane, s_triangle, mask);
    vec3 normal = sphere ? sphere_normal(O + s_sphere * D, u_center, u_radius) : vec3(0.0);
    out_extra = vec4(normal, sphere_discriminant(O, D, u_center, u_radius));
    out_uv = vec4(uv, 0.0, 0.0);
}
