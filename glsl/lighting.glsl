// Twin: reference/lighting.py
// The lighting equation of docs/conventions.md (section 2.1 of the notes), in world space:
//   I = I_a k_a + sum_l att_l I_l k_d max(N.L, 0) + sum_l att_l I_l k_s spec_l
// Compile-time constants (renderer/gpu/shaders.py injects them): NUM_DIRECTIONAL_LIGHTS and
// NUM_POINT_LIGHTS size the light arrays; an array is left out when its count is 0.
// SPECULAR compiles the k_s term in; without it (every k_s is 0) neither R, V nor pow exist.
// ALL_FEATURES (the build that does not specialise, renderer/gpu/shaders.py) keeps the arrays at
// their full size and reads how many lights there are from uniforms at run time.
// The ray tracer (glsl/raytrace/trace.glsl) adds two switches; without them this file compiles
// to exactly the rasteriser's code:
//   MATERIAL_VARIABLES: u_ka, u_kd, u_ks, u_n and u_eye are global variables the caller sets
//     per hit (the hit's material; the viewer is the ray's origin) instead of uniforms;
//   SHADOWS: each light's diffuse and specular terms are multiplied by its visibility, 0 or 1,
//     from light_visibility_directional(i, P, N) / light_visibility_point(i, P, N), which the
//     including shader defines (shadow rays); a point in shadow keeps only the ambient term.
//     A light whose terms are 0 at P (behind the surface, or a material with k_d = k_s = 0)
//     casts no shadow ray: its visibility could change nothing. The rasteriser's fragment
//     stage defines SHADOWS too, answered by shadow maps (glsl/shadow/lookup.glsl);
//   AREA_LIGHTS: a point light with an area (has_area(i)) lights by area_light_term(i, P, N,
//     V); the including shader defines both (its samples on the area, each point_term_at a
//     sampled point, shadowed, averaged); the others light as without it.
// The rasteriser's textured materials add one (renderer/gpu/shaders.py, glsl/texture.glsl):
//   TEXTURED: the coefficients lit are u_ka, u_kd and u_ks each times a factor, which the
//     caller sets with material_factors(modulated, other): `modulated` for the coefficients
//     the texel modulates (TEXTURE_KA, TEXTURE_KD, TEXTURE_KS), `other` for the rest. Phong
//     lights once with (texel, 1); flat and Gouraud, which light before the texel is known,
//     light each part alone (material_part: OTHER_PART (0, 1), MODULATED_PART (1, 0)) and
//     hand both on (glsl/vertex.glsl, glsl/geometry.glsl); a receiver of shadows hands each
//     light's term on in TERM_PARTS rows of its array (NUM_DIRECTIONAL_TERMS = TERM_PARTS x
//     the lights, renderer/gpu/shaders.py): OTHER_PART's rows first, then MODULATED_PART's.
// Each light's term is a function of its own (directional_term, point_term), which flat and
// Gouraud receivers of shadows also call to keep the terms apart (keep_light_terms) and hand
// them on (hand_on_light_terms, in the stage that defines LIGHT_TERMS_OUT).

#ifndef NUM_DIRECTIONAL_LIGHTS
#define NUM_DIRECTIONAL_LIGHTS 0
#endif
#ifndef NUM_POINT_LIGHTS
#define NUM_POINT_LIGHTS 0
#endif

// The material: the notes' reflection coefficients (linear RGB) and Phong exponent n.
#ifdef MATERIAL_VARIABLES
vec3 u_ka;
vec3 u_kd;
#ifdef SPECULAR
vec3 u_ks;
float u_n;
vec3 u_eye;                          // the viewer: the ray's origin
#endif
#else
uniform vec3 u_ka;
uniform vec3 u_kd;
#ifdef SPECULAR
uniform vec3 u_ks;
uniform float u_n;
uniform vec3 u_eye;                  // E, the camera's eye, world space
#endif
#endif

uniform vec3 u_ambient;              // I_a

// The coefficients as lit (TEXTURED: times the factors material_factors set).
#ifdef TEXTURED
vec3 ka_factor = vec3(1.0);
vec3 kd_factor = vec3(1.0);
vec3 ks_factor = vec3(1.0);
#define MATERIAL_KA (u_ka * ka_factor)
#define MATERIAL_KD (u_kd * kd_factor)
#define MATERIAL_KS (u_ks * ks_factor)

void material_factors(vec3 modulated, vec3 other) {
#ifdef TEXTURE_KA
    ka_factor = modulated;
#else
    ka_factor = other;
#endif
#ifdef TEXTURE_KD
    kd_factor = modulated;
#else
    kd_factor = other;
#endif
#ifdef TEXTURE_KS
    ks_factor = modulated;
#else
    ks_factor = other;
#endif
}

#define OTHER_PART 0
#define MODULATED_PART 1
#define TERM_PARTS 2
void material_part(int part) {
    float modulated = float(part == MODULATED_PART);
    material_factors(vec3(modulated), vec3(1.0 - modulated));
}
#else
#define MATERIAL_KA u_ka
#define MATERIAL_KD u_kd
#define MATERIAL_KS u_ks
#define OTHER_PART 0
#define TERM_PARTS 1
#endif
#ifdef NUM_DIRECTIONAL_TERMS
#define DIRECTIONAL_TERM_ROWS (NUM_DIRECTIONAL_TERMS / TERM_PARTS)
#define POINT_TERM_ROWS (NUM_POINT_TERMS / TERM_PARTS)
#endif

#ifdef ALL_FEATURES
uniform int u_num_directional_lights;
uniform int u_num_point_lights;
#define DIRECTIONAL_LIGHTS u_num_directional_lights
#define POINT_LIGHTS u_num_point_lights
#else
#define DIRECTIONAL_LIGHTS NUM_DIRECTIONAL_LIGHTS
#define POINT_LIGHTS NUM_POINT_LIGHTS
#endif

#if NUM_DIRECTIONAL_LIGHTS > 0
uniform vec3 u_directional_direction[NUM_DIRECTIONAL_LIGHTS];   // D, the way the light travels
uniform vec3 u_directional_intensity[NUM_DIRECTIONAL_LIGHTS];   // I_l
#endif
#if NUM_POINT_LIGHTS > 0
uniform vec3 u_point_position[NUM_POINT_LIGHTS];                // Q, world space
uniform vec3 u_point_intensity[NUM_POINT_LIGHTS];               // I_l
uniform vec3 u_point_attenuation[NUM_POINT_LIGHTS];             // (c, l, q)
#endif

#ifdef SHADOWS
float light_visibility_directional(int i, vec3 P, vec3 N);
float light_visibility_point(int i, vec3 P, vec3 N);
#endif
#if defined(AREA_LIGHTS) && NUM_POINT_LIGHTS > 0
bool has_area(int i);
vec3 area_light_term(int i, vec3 P, vec3 N, vec3 V);
#endif

// normalize(v), except that a zero vector stays zero (GLSL's normalize(0) is NaN): a normal
// that vanishes (singular normal matrix, opposite normals interpolated) lights as ambient.
vec3 normalize_or_zero(vec3 v) {
    return dot(v, v) > 0.0 ? normalize(v) : vec3(0.0);
}

#ifdef SPECULAR
// spec = max(R.V, 0)^n where N.L > 0 and R.V > 0, else 0: pow never sees a base <= 0.
float specular_term(float n_dot_l, float r_dot_v, float n) {
    if (n_dot_l > 0.0 && r_dot_v > 0.0) {
        return pow(r_dot_v, n);
    }
    return 0.0;
}
#endif

// One light's diffuse and specular terms: att I_l k_d max(N.L, 0) + att I_l k_s spec.
// N, L, V are unit vectors (V is unused without SPECULAR); att_intensity is att * I_l.
vec3 light_contribution(vec3 N, vec3 L, vec3 V, vec3 att_intensity) {
    float n_dot_l = dot(N, L);
    vec3 I = att_intensity * MATERIAL_KD * max(n_dot_l, 0.0);
#ifdef SPECULAR
    vec3 R = 2.0 * n_dot_l * N - L;                  // perfect reflection of L about N
    I += att_intensity * MATERIAL_KS * specular_term(n_dot_l, dot(R, V), u_n);
#endif
    return I;
}

// V, the unit vector from P to the eye (only the specular term looks at it).
vec3 view_vector(vec3 P) {
#ifdef SPECULAR
    return normalize_or_zero(u_eye - P);
#else
    return vec3(0.0);
#endif
}

// The ambient term I_a k_a.
vec3 ambient_term() {
    return u_ambient * MATERIAL_KA;
}

// The term of light i at P with unit normal N (its diffuse and specular terms): what
// lighting() adds per light, and what flat and Gouraud receivers of shadows keep apart
// (glsl/vertex.glsl, glsl/geometry.glsl) to weigh by visibility per fragment.
#if NUM_DIRECTIONAL_LIGHTS > 0
vec3 directional_term(int i, vec3 N, vec3 V) {
    vec3 L = normalize(-u_directional_direction[i]);
    return light_contribution(N, L, V, u_directional_intensity[i]);         // att = 1
}
#endif
#if NUM_POINT_LIGHTS > 0
// Light i's term as if it shone from Q (its position, or a point of its area).
vec3 point_term_at(int i, vec3 Q, vec3 P, vec3 N, vec3 V) {
    vec3 to_light = Q - P;
    float d = length(to_light);
    vec3 L = d > 0.0 ? to_light / d : N;             // a light on the surface: fully incident
    vec3 c_l_q = u_point_attenuation[i];
    float att = 1.0 / (c_l_q.x + c_l_q.y * d + c_l_q.z * d * d);
    return light_contribution(N, L, V, att * u_point_intensity[i]);
}

vec3 point_term(int i, vec3 P, vec3 N, vec3 V) {
    return point_term_at(i, u_point_position[i], P, N, V);
}
#endif

#ifdef NUM_DIRECTIONAL_TERMS
// Flat and Gouraud receivers of shadows (NUM_DIRECTIONAL_TERMS and NUM_POINT_TERMS defined)
// keep the terms apart: keep_light_terms(P, N, V) puts the ambient term and each light's term
// lit with N (and, two-sided, with -N) into these, a row per light and part (TERM_PARTS: a
// textured material's modulated coefficients and the others, each lit alone), for the stage
// to hand on (glsl/vertex.glsl, glsl/geometry.glsl).
vec3 kept_ambient[TERM_PARTS];
#if NUM_DIRECTIONAL_TERMS > 0
vec3 kept_directional_front[NUM_DIRECTIONAL_TERMS];
#ifdef TWO_SIDED
vec3 kept_directional_back[NUM_DIRECTIONAL_TERMS];
#endif
#endif
#if NUM_POINT_TERMS > 0
vec3 kept_point_front[NUM_POINT_TERMS];
#ifdef TWO_SIDED
vec3 kept_point_back[NUM_POINT_TERMS];
#endif
#endif

void keep_part(vec3 P, vec3 N, vec3 V, int part) {
    kept_ambient[part] = ambient_term();
#if NUM_DIRECTIONAL_TERMS > 0
    for (int i = 0; i < DIRECTIONAL_LIGHTS; ++i) {
        int row = part * DIRECTIONAL_TERM_ROWS + i;
        kept_directional_front[row] = directional_term(i, N, V);
#ifdef TWO_SIDED
        kept_directional_back[row] = directional_term(i, -N, V);
#endif
    }
#endif
#if NUM_POINT_TERMS > 0
    for (int i = 0; i < POINT_LIGHTS; ++i) {
        int row = part * POINT_TERM_ROWS + i;
        kept_point_front[row] = point_term(i, P, N, V);
#ifdef TWO_SIDED
        kept_point_back[row] = point_term(i, P, -N, V);
#endif
    }
#endif
}

void keep_light_terms(vec3 P, vec3 N, vec3 V) {
#ifdef TEXTURED
    material_part(MODULATED_PART);
    keep_part(P, N, V, MODULATED_PART);
    material_part(OTHER_PART);
#endif
    keep_part(P, N, V, OTHER_PART);
}

// The varyings that carry the kept terms to fragment.glsl (its shadowed_terms reads them by
// these names): geometry.glsl's, one per triangle (flat; glsl/flat_varyings.glsl), or
// vertex.glsl's, interpolated (Gouraud).
#ifdef SHADING_FLAT
#define AMBIENT f_ambient
#define MODULATED_AMBIENT f_modulated_ambient
#define DIRECTIONAL_TERMS_FRONT f_directional_terms_front
#define DIRECTIONAL_TERMS_BACK f_directional_terms_back
#define POINT_TERMS_FRONT f_point_terms_front
#define POINT_TERMS_BACK f_point_terms_back
#else
#define AMBIENT v_ambient
#define MODULATED_AMBIENT v_modulated_ambient
#define DIRECTIONAL_TERMS_FRONT v_directional_terms_front
#define DIRECTIONAL_TERMS_BACK v_directional_terms_back
#define POINT_TERMS_FRONT v_point_terms_front
#define POINT_TERMS_BACK v_point_terms_back
#endif

#ifdef LIGHT_TERMS_OUT
// The stage that keeps the terms hands them on (vertex.glsl; geometry.glsl for each vertex it
// emits): it defines LIGHT_TERMS_OUT and declares those outs before including this file.
void hand_on_light_terms() {
    AMBIENT = kept_ambient[OTHER_PART];
#ifdef TEXTURED
    MODULATED_AMBIENT = kept_ambient[MODULATED_PART];
#endif
#if NUM_DIRECTIONAL_TERMS > 0
    DIRECTIONAL_TERMS_FRONT = kept_directional_front;
#ifdef TWO_SIDED
    DIRECTIONAL_TERMS_BACK = kept_directional_back;
#endif
#endif
#if NUM_POINT_TERMS > 0
    POINT_TERMS_FRONT = kept_point_front;
#ifdef TWO_SIDED
    POINT_TERMS_BACK = kept_point_back;
#endif
#endif
}
#endif
#endif

#ifdef SHADOWS
// A light's term times its visibility at P (lit normal N); no shadow ray where the term is 0.
#if NUM_DIRECTIONAL_LIGHTS > 0
vec3 shadowed_directional(int i, vec3 P, vec3 N, vec3 term) {
    return term != vec3(0.0) ? light_visibility_directional(i, P, N) * term : vec3(0.0);
}
#endif
#if NUM_POINT_LIGHTS > 0
vec3 shadowed_point(int i, vec3 P, vec3 N, vec3 term) {
    return term != vec3(0.0) ? light_visibility_point(i, P, N) * term : vec3(0.0);
}
#endif
#endif

#if NUM_POINT_LIGHTS > 0
// What point light i adds at P: its term, shadowed where SHADOWS; an area light's samples.
vec3 lit_point(int i, vec3 P, vec3 N, vec3 V) {
#ifdef AREA_LIGHTS
    if (has_area(i)) return area_light_term(i, P, N, V);
#endif
#ifdef SHADOWS
    return shadowed_point(i, P, N, point_term(i, P, N, V));
#else
    return point_term(i, P, N, V);
#endif
}
#endif

// The colour I at world point P with unit normal N (already flipped for a two-sided back face).
vec3 lighting(vec3 P, vec3 N) {
    vec3 V = view_vector(P);
    vec3 I = ambient_term();
#if NUM_DIRECTIONAL_LIGHTS > 0
    for (int i = 0; i < DIRECTIONAL_LIGHTS; ++i) {
#ifdef SHADOWS
        I += shadowed_directional(i, P, N, directional_term(i, N, V));
#else
        I += directional_term(i, N, V);
#endif
    }
#endif
#if NUM_POINT_LIGHTS > 0
    for (int i = 0; i < POINT_LIGHTS; ++i) {
        I += lit_point(i, P, N, V);
    }
#endif
    return I;
}
