// Twin: reference/radiosity/specular.py
// Radiosity's direct specular term (issue 33; docs/radiosity.md, "The specular term"): what the
// display adds to the interpolated radiosity where an element's material has k_s. It is the
// lighting equation's k_s term (glsl/lighting.glsl's light_contribution, with k_d = 0) of each
// source radiosity was lit by (renderer/core/light_buffers.py: a point light, each point of an
// area light's grid with its share of the intensity and its emitter's cosine, a directional
// light), weighed by the source's visibility: 1 where the pixel of the source's light buffer
// under the fragment saw the fragment's object's front, else 0 (light_buffers.LightSurfaces).
// The shadows of the highlights are the light buffers' own, at their resolution.
// NUM_SOURCES and NUM_VIEWS (defines, renderer/gpu/radiosity.py) size the arrays: six views a
// point source, one a directional one, in the sources' order. Positions are camera-relative
// (the eye at 0), as the display's corners (renderer/core/radiosity.py SpecularDisplay).

#define MATERIAL_VARIABLES
#define SPECULAR
#include "lighting.glsl"

uniform usampler2DArray u_light_surfaces;   // a layer a view: object + 1 whose front a pixel saw, or 0
uniform mat4 u_light_view[NUM_VIEWS];       // clip_from_world (camera-relative) of each view
uniform vec4 u_source_where[NUM_SOURCES];   // a point's position and 1; a direction of travel and 0
uniform vec3 u_source_intensity[NUM_SOURCES];
uniform vec3 u_source_attenuation[NUM_SOURCES];   // (c, l, q)
uniform vec4 u_source_emitter[NUM_SOURCES];       // an area point's emitting normal, scale (0: none)

// 1 where the first of views first..first+count-1 whose frustum holds P saw `object` there.
float source_visibility(int first, int count, vec3 P, int object) {
    ivec2 size = textureSize(u_light_surfaces, 0).xy;
    for (int k = 0; k < count; ++k) {
        vec4 clip = u_light_view[first + k] * vec4(P, 1.0);
        if (clip.w > 0.0 && abs(clip.x) <= clip.w && abs(clip.y) <= clip.w) {
            vec2 window = (clip.xy / clip.w * 0.5 + 0.5) * vec2(size);    // the view's viewport
            ivec2 at = clamp(ivec2(floor(window)), ivec2(0), size - 1);
            uint seen = texelFetch(u_light_surfaces, ivec3(at, first + k), 0).r;
            return seen == uint(object + 1) ? 1.0 : 0.0;
        }
    }
    return 0.0;
}

// The specular term at P (camera-relative) with unit normal N, of a material (ks, n) of `object`.
vec3 radiosity_specular(vec3 P, vec3 N, vec3 ks, float n, int object) {
    u_ka = vec3(0.0);
    u_kd = vec3(0.0);
    u_ks = ks;
    u_n = n;
    u_eye = vec3(0.0);
    vec3 V = view_vector(P);
    vec3 sum = vec3(0.0);
    int first = 0;
    for (int i = 0; i < NUM_SOURCES; ++i) {
        vec4 where = u_source_where[i];
        bool point = where.w > 0.0;
        int count = point ? 6 : 1;
        vec3 L;
        float att = 1.0;
        float emitted = 1.0;
        if (point) {
            vec3 to_light = where.xyz - P;
            float d = length(to_light);
            L = d > 0.0 ? to_light / d : N;          // a light on the surface: fully incident
            vec3 c_l_q = u_source_attenuation[i];
            att = 1.0 / (c_l_q.x + c_l_q.y * d + c_l_q.z * d * d);
            vec4 emitter = u_source_emitter[i];
            if (emitter.w > 0.0)
                emitted = emitter.w * max(0.0, -dot(L, emitter.xyz));
        } else {
            L = normalize(-where.xyz);
        }
        vec3 term = light_contribution(N, L, V, att * emitted * u_source_intensity[i]);
        if (any(greaterThan(term, vec3(0.0))))       // no lookup where the term is 0
            sum += term * source_visibility(first, count, P, object);
        first += count;
    }
    return sum;
}
