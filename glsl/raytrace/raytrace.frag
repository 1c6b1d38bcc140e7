#version 330 core
// The ray tracer's full-screen pass (renderer/gpu/raytracer.py; twin: reference/raytrace/
// pipeline.py): per pixel, camera rays through gl_FragCoord.xy + sample_offset(pixel, k)
// (sampling.glsl), with LENS through lens_point(pixel, k) of the thin lens (camera.glsl),
// traced from near to far (trace.glsl; PATH_TRACE: pathtrace.glsl's paths), their colours
// summed in sample order and averaged. Every pixel traces FIRST_SAMPLES samples (NUM_SAMPLES
// but for ADAPTIVE); with
// ADAPTIVE, a pixel whose first samples' clamped colours differ by more than
// u_adaptive_threshold in some channel (max - min over the samples) traces all NUM_SAMPLES.
// out_color: (average linear colour, 1 where some camera ray hit, else 0); out_depth: the
// nearest first hit's s (the view depth), +inf where none hit; ADAPTIVE: out_samples, the
// samples traced.
#include "raytrace/camera.glsl"
#include "raytrace/sampling.glsl"
#include "raytrace/trace.glsl"          // outside the #ifdef: an include is expanded once
#ifdef PATH_TRACE                       // the path tracer's paths (pathtrace.glsl)
#include "raytrace/pathtrace.glsl"
#define TRACE path_trace
#else
#define TRACE trace
#endif

uniform float u_near;
uniform float u_far;
layout(location = 0) out vec4 out_color;
layout(location = 1) out float out_depth;
#ifdef ADAPTIVE
uniform float u_adaptive_threshold;
layout(location = 2) out float out_samples;
#endif
#ifdef SAMPLE_PASSES
// One sample a pass (the path tracer, renderer/gpu/pathtracer.py): sample u_sample alone, its own
// colour out (the caller sums the passes in sample order). llvmpipe ends every loop of a shader
// invocation once all of them together have run 65535 iterations (gallivm's
// LP_MAX_TGSI_LOOP_ITERATIONS), which a pixel's many long paths would reach.
uniform int u_sample;
#endif

void main() {
    uvec2 pixel = uvec2(gl_FragCoord.xy);
    vec3 total = vec3(0.0);
    bool covered = false;
    float depth = TRACE_INF;
    vec3 low = vec3(1.0);
    vec3 high = vec3(0.0);
#ifdef SAMPLE_PASSES
    int first = u_sample;
    int count = u_sample + 1;
#else
    int first = 0;
    int count = FIRST_SAMPLES;
#endif
    for (int k = first; k < count; ++k) {   // one call site of trace: it is inlined where called
        vec3 O, D;
        camera_ray(gl_FragCoord.xy + sample_offset(pixel, k), O, D);
#ifdef LENS
        thin_lens_ray(lens_point(pixel, k), O, D);
#endif
        g_pixel = pixel;
        g_sample = k;
        bool hit;
        float s;
        vec3 colour = TRACE(O, D, u_near, u_far, hit, s);
        total += colour;
        if (hit) {
            covered = true;
            depth = min(depth, s);
        }
#ifdef ADAPTIVE
        low = min(low, clamp(colour, 0.0, 1.0));
        high = max(high, clamp(colour, 0.0, 1.0));
        vec3 spread = high - low;
        if (k == FIRST_SAMPLES - 1 && max(spread.r, max(spread.g, spread.b)) > u_adaptive_threshold)
            count = NUM_SAMPLES;
#endif
    }
#ifdef SAMPLE_PASSES
    out_color = vec4(total, covered ? 1.0 : 0.0);
#else
    out_color = vec4(total / float(count), covered ? 1.0 : 0.0);
#endif
    out_depth = depth;
#ifdef ADAPTIVE
    out_samples = float(count);
#endif
}
