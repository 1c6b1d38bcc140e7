#version 330 core
// Test shader for tests/test_raytrace_optics.py: per pixel, the camera ray through the pixel's
// sample point (gl_FragCoord.xy + u_sample_offset), and the optics of one (D, N, eta, p) from
// float textures. out_origin, out_direction: the camera ray; out_reflect: the reflection and
// Schlick's F; out_refract: the refraction and 1 where refracted (0 on TIR); out_offset: the
// offset point (RGBA32F: read back bit for bit).
#include "raytrace/camera.glsl"
#include "raytrace/optics.glsl"
uniform vec2 u_sample_offset;
uniform sampler2D u_directions;    // D, eta
uniform sampler2D u_normals;       // N
uniform sampler2D u_points;        // p
layout(location = 0) out vec4 out_origin;
layout(location = 1) out vec4 out_direction;
layout(location = 2) out vec4 out_reflect;
layout(location = 3) out vec4 out_refract;
layout(location = 4) out vec4 out_offset;

void main() {
    vec3 O, D;
    camera_ray(gl_FragCoord.xy + u_sample_offset, O, D);
    out_origin = vec4(O, 0.0);
    out_direction = vec4(D, 0.0);

    ivec2 pixel = ivec2(gl_FragCoord.xy);
    vec4 d_eta = texelFetch(u_directions, pixel, 0);
    vec3 N = texelFetch(u_normals, pixel, 0).xyz;
    vec3 p = texelFetch(u_points, pixel, 0).xyz;
    out_reflect = vec4(ray_reflect(d_eta.xyz, N), fresnel_schlick(d_eta.xyz, N, d_eta.w));
    vec3 T;
    bool refracted = ray_refract(d_eta.xyz, N, d_eta.w, T);
    out_refract = vec4(T, refracted ? 1.0 : 0.0);
    out_offset = vec4(offset_ray_origin(p, N), 0.0);
}
