#version 330 core
// The ray tracer's full-screen pass (renderer/gpu/raytracer.py; twin: reference/raytrace/
// pipeline.py): per pixel, NUM_SAMPLES camera rays through gl_FragCoord.xy + u_sample_offsets[k]
// traced from near to far (trace.glsl), their colours summed in sample order and averaged.
// out_color: (average linear colour, 1 where some camera ray hit, else 0); out_depth: the
// nearest first hit's s (the view depth), +inf where none hit.
#ifndef NUM_SAMPLES
#define NUM_SAMPLES 1
#endif
#include "raytrace/camera.glsl"
#include "raytrace/trace.glsl"

uniform vec2 u_sample_offsets[NUM_SAMPLES];
uniform float u_near;
uniform float u_far;
layout(location = 0) out vec4 out_color;
layout(location = 1) out float out_depth;

void main() {
    vec3 total = vec3(0.0);
    bool covered = false;
    float depth = TRACE_INF;
    for (int k = 0; k < NUM_SAMPLES; ++k) {
        vec3 O, D;
        camera_ray(gl_FragCoord.xy + u_sample_offsets[k], O, D);
        bool hit;
        float s;
        total += trace(O, D, u_near, u_far, hit, s);
        if (hit) {
            covered = true;
            depth = min(depth, s);
        }
    }
    out_color = vec4(total / float(NUM_SAMPLES), covered ? 1.0 : 0.0);
    out_depth = depth;
}
