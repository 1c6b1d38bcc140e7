// Twin: reference/raytrace/pathtrace.py
// Path tracing (docs/pathtrace.md; Kajiya 1986), the independent check of radiosity: one path
// per camera sample, from hit to hit, through trace.glsl's scene queries (scene_hit, surface,
// occluded), its lights (lighting.glsl with the ambient term 0, point lights' areas, shadow
// rays) and materials. At each hit on a surface's lit side (its front, or either side of a
// two-sided material): its emission; the scene's lights' terms; and, under EMITTERS,
// next-event estimation of the emitting triangles (emitter_light: one triangle by its power, one
// point on it, one shadow ray), times k_d. The light of an emitter is found both ways, by
// next-event estimation and by a diffuse bounce that hits it; each is weighted by Veach's
// power heuristic of the two densities (multiple importance sampling), so that neither's
// rare huge samples (an emitter next to the point lit, one seen at a grazing angle) remain.
// Then the path goes on by one lobe chosen in proportion to the largest channel of its weight:
// diffuse k_d (a cosine-weighted direction about the lit normal), reflected k_r + k_t F
// (glossy.glsl's lobe under GLOSSY) or transmitted k_t (1 - F), the weight divided by the
// choice's probability; Russian roulette from bounce ROULETTE_DEPTH; at most MAX_DEPTH bounces.
// A surface's back, unless two-sided, neither emits nor reflects diffusely, as radiosity's
// elements (its mirror and glass terms act on both sides).
//
// Units: a pixel shows pi times the radiance reaching it, the exitance a Lambertian surface of
// that radiance has, which is what radiosity shows (B) and what the lighting equation's k_d I
// cos term is (reflected irradiance): k_d is the Lambertian reflectance rho (the BRDF rho / pi),
// an emission E the exitance pi L_e, the background a distant surround of exitance `background`.
// The numbers of bounce b come from slot 1 + b (g_ray_key = b): renderer/core/path_options.py's
// dimensions, which these mirror.
#include "raytrace/trace.glsl"

const uint EMITTER_CHOICE_DIMENSION = 1024u;
const uint EMITTER_POINT_DIMENSION = 1025u;
const uint LOBE_DIMENSION = 1026u;
const uint BOUNCE_DIMENSION = 1027u;
const uint ROULETTE_DIMENSION = 1028u;
#ifndef ROULETTE_DEPTH
#define ROULETTE_DEPTH 3
#endif

// per object: (E, density): the density per unit area with which next-event estimation picks
// its points (renderer/core/path_emitters.py), 0 where it does not
uniform sampler2D u_emission;

float largest(vec3 v) {
    return max(v.r, max(v.g, v.b));
}

// The share of the paths from this hit that go on by a diffuse bounce (0 at the last bounce):
// with cos / pi, the diffuse bounce's density over directions, which next-event estimation
// weighs its samples against.
float g_diffuse_share;

// Veach's power heuristic: the weight of a sample of the strategy of density `mine` where the
// other's is `other` (both per steradian). The two weights of one point sum to 1.
float power_heuristic(float mine, float other) {
    return mine * mine / (mine * mine + other * other);
}

#ifdef EMITTERS
// renderer/core/path_emitters.py: per emitting triangle the rows (A, cdf), (B, density: its
// probability per unit area), (C, object).
uniform sampler2D u_emitters;
uniform int u_emitter_count;

// The first emitter k with u < cdf_k (the last one's cdf is 1), by bisection.
int emitter_search(float u) {
    int low = 0;
    int high = u_emitter_count - 1;
    while (low < high) {
        int middle = (low + high) / 2;
        if (u < trace_texel(u_emitters, 3 * middle).w) high = middle;
        else low = middle + 1;
    }
    return low;
}

// Next-event estimation: the light one point Q of one emitting triangle sends to P (lit normal
// N), as the exitance a white Lambertian surface at P reflects: E cos_P cos_Q / (pi d^2 p(Q)),
// p(Q) the emitter's density per unit area, times the power heuristic of p(Q) d^2 / cos_Q (per
// steradian) against the diffuse bounce's g_diffuse_share cos_P / pi; 0 where Q lies behind P's
// surface or P behind the emitter's front, where the facet is turned from Q, or where the
// shadow ray is blocked.
// The point: u = EMITTER_POINT's, r = sqrt(u.x), Q = A + r (1 - u.y) (B - A) + r u.y (C - A).
vec3 emitter_light(vec3 P, vec3 N) {
    uint slot = 1u + g_ray_key;
    int k = emitter_search(distributed_1d(g_pixel, g_sample, slot, EMITTER_CHOICE_DIMENSION));
    vec4 a = trace_texel(u_emitters, 3 * k);
    vec4 b = trace_texel(u_emitters, 3 * k + 1);
    vec4 c = trace_texel(u_emitters, 3 * k + 2);
    vec2 u = distributed_2d(g_pixel, g_sample, slot, EMITTER_POINT_DIMENSION, 0u, 1u);
    float r = sqrt(u.x);
    vec3 Q = a.xyz + (r * (1.0 - u.y)) * (b.xyz - a.xyz) + (r * u.y) * (c.xyz - a.xyz);
    vec3 to_light = Q - P;
    float d2 = dot(to_light, to_light);
    float d = sqrt(d2);
    vec3 L = to_light / d;
    float cos_here = dot(N, L);
    float cos_there = -dot(triangle_normal(a.xyz, b.xyz, c.xyz), L);
    if (!(d2 > 0.0 && cos_here > 0.0 && cos_there > 0.0) || facet_turned_from(N, to_light))
        return vec3(0.0);
    float visible = light_visibility_at(Q, P);
    vec4 e = trace_texel(u_emission, int(c.w));
    float weight = power_heuristic(e.w * d2 / cos_there, g_diffuse_share * cos_here / WARP_PI);
    return e.xyz * (visible * cos_here * cos_there / (WARP_PI * d2 * e.w) * weight);
}
#endif

// The weight of an emitter's light found by the path's last bounce, arriving along D (Du
// normalised) at distance s onto the outward normal Ng: 1 after the camera, a mirror, glass or
// a glossy lobe (bounce_density 0: nothing else finds it) or where next-event estimation does
// not sample the emitter (density 0); else the power heuristic of the diffuse bounce's density
// against next-event estimation's, density s^2 |D|^2 / cos (per steradian).
float emission_weight(float bounce_density, float density, float s, vec3 D, vec3 Du, vec3 Ng) {
    if (!(bounce_density > 0.0 && density > 0.0)) return 1.0;
    return power_heuristic(bounce_density, density * (s * s * dot(D, D)) / -dot(Du, Ng));
}

// The light seen along the camera ray O + s D (s_min < s < s_max; the bounces from 0 to
// infinity); hit and s: the camera ray's hit.
vec3 path_trace(vec3 O0, vec3 D0, float s_min, float s_max, out bool hit, out float s_hit) {
    vec3 colour = vec3(0.0);
    vec3 O = O0;
    vec3 D = D0;
    vec3 w = vec3(1.0);
    int from_shape = -1;
    float bounce_density = 0.0;          // the last diffuse bounce's, per steradian; 0: none
    hit = false;
    s_hit = s_max;
#ifdef MOTION
    trace_motion_at(trace_sample_time());
#endif
    for (int depth = 0; depth <= MAX_DEPTH; ++depth) {
        int index;
        float s;
        vec2 uv;
        int kind = ray_hit(O, D, depth, s_min, s_max, from_shape, index, s, uv, hit, s_hit);
        if (kind == TRACE_MISS) {
            colour += w * u_background;
            break;
        }
        vec3 P, Ng, Ns;
        int obj;
        surface(O, D, kind, index, s, uv, P, Ng, Ns, obj);
        vec3 Du = normalize(D);
        bool back = dot(Du, Ng) > 0.0;
        vec4 m0 = trace_texel(u_materials, 5 * obj);
        vec4 m1 = trace_texel(u_materials, 5 * obj + 1);
        vec4 m2 = trace_texel(u_materials, 5 * obj + 2);
        vec4 m3 = trace_texel(u_materials, 5 * obj + 3);
        vec4 m4 = trace_texel(u_materials, 5 * obj + 4);
        shade_hit(m0, m1, m2, obj, kind, index, P, uv, O, Ng, uint(depth));
        u_ka = vec3(0.0);                // no ambient term: the bounces are the ambient light
        bool lit = !back || m1.w > 0.5;
        vec3 N_in = back ? -Ns : Ns;         // the normals on the side the path arrives from
        vec3 Ng_in = back ? -Ng : Ng;
        vec3 kd = lit ? u_kd : vec3(0.0);
        // The next bounce's lobes first: next-event estimation weighs against the diffuse one.
        vec3 kr = m3.xyz;
        vec3 kt = m4.xyz;
        float eta = back ? m2.w : 1.0 / m2.w;
        float F = m4.w > 0.5 ? fresnel_exact(Du, N_in, eta) : fresnel_schlick(Du, N_in, eta);
        vec3 T;
        bool refracted = ray_refract(Du, N_in, eta, T);
        vec3 w_r = kr + kt * F;
        vec3 w_t = refracted ? kt * transmitted_share(F, eta) : vec3(0.0);
        float p_d = largest(kd);
        float p_r = largest(w_r);
        float p_t = largest(w_t);
        float total = p_d + p_r + p_t;
        g_diffuse_share = depth < MAX_DEPTH && total > 0.0 ? p_d / total : 0.0;
        if (lit) {
            vec4 e = trace_texel(u_emission, obj);
            if (!back) colour += w * (e.xyz * emission_weight(bounce_density, e.w, s, D, Du, Ng));
            colour += w * lighting(P, N_in);
#ifdef EMITTERS
            colour += w * (kd * emitter_light(P, N_in));
#endif
        }
        if (depth == MAX_DEPTH || !(total > 0.0)) break;   // absorbed where nothing goes on
        float u = distributed_1d(g_pixel, g_sample, 1u + g_ray_key, LOBE_DIMENSION) * total;
        int lobe = u < p_d ? 0 : u < p_d + p_r ? 1 : 2;
        float p = lobe == 0 ? p_d : lobe == 1 ? p_r : p_t;
        if (!(p > 0.0)) break;               // u rounded up to total (at most 2^-24 of paths)
        vec3 factor = (lobe == 0 ? kd : lobe == 1 ? w_r : w_t) * (total / p);
        if (lobe == 0) {                     // diffuse: cosine-weighted about the lit normal
            vec3 v = square_to_cosine_hemisphere(distributed_2d(g_pixel, g_sample, 1u + g_ray_key,
                                                                BOUNCE_DIMENSION, 0u, 1u));
            vec3 b1, b2;
            orthonormal_basis(N_in, b1, b2);
            D = v.x * b1 + v.y * b2 + v.z * N_in;
            if (!(dot(D, Ng_in) > 0.0)) break;   // below the surface: absorbed
            O = ray_origin(P, Ng_in, g_shape);
            bounce_density = g_diffuse_share * v.z / WARP_PI;
        } else if (lobe == 1) {
            D = ray_reflect(Du, N_in);
#ifdef GLOSSY
            if (!glossy_direction(D, Ng_in, m3.w, D)) break;
#endif
            O = ray_origin(P, Ng_in, g_shape);
            bounce_density = 0.0;
        } else {
            D = T;
            O = ray_origin(P, -Ng_in, g_shape);
            bounce_density = 0.0;
        }
        w *= factor;
        if (depth + 1 >= ROULETTE_DEPTH) {
            float q = min(1.0, largest(w));
            if (distributed_1d(g_pixel, g_sample, 1u + g_ray_key, ROULETTE_DIMENSION) >= q) break;
            w /= q;
        }
        from_shape = g_shape;
    }
    return colour;
}
