// Twin: reference/lighting.py
// The lighting equation of docs/conventions.md (section 2.1 of the notes), in world space:
//   I = I_a k_a + sum_l att_l I_l k_d max(N.L, 0) + sum_l att_l I_l k_s spec_l
// Compile-time constants (renderer/shaders.py injects them): NUM_DIRECTIONAL_LIGHTS and
// NUM_POINT_LIGHTS size the light arrays; an array is left out when its count is 0.

#ifndef NUM_DIRECTIONAL_LIGHTS
#define NUM_DIRECTIONAL_LIGHTS 0
#endif
#ifndef NUM_POINT_LIGHTS
#define NUM_POINT_LIGHTS 0
#endif

// The material: the notes' reflection coefficients (linear RGB) and Phong exponent n.
uniform vec3 u_ka;
uniform vec3 u_kd;
uniform vec3 u_ks;
uniform float u_n;

uniform vec3 u_ambient;              // I_a
uniform vec3 u_eye;                  // E, the camera's eye, world space

#if NUM_DIRECTIONAL_LIGHTS > 0
uniform vec3 u_directional_direction[NUM_DIRECTIONAL_LIGHTS];   // D, the way the light travels
uniform vec3 u_directional_intensity[NUM_DIRECTIONAL_LIGHTS];   // I_l
#endif
#if NUM_POINT_LIGHTS > 0
uniform vec3 u_point_position[NUM_POINT_LIGHTS];                // Q, world space
uniform vec3 u_point_intensity[NUM_POINT_LIGHTS];               // I_l
uniform vec3 u_point_attenuation[NUM_POINT_LIGHTS];             // (c, l, q)
#endif

// normalize(v), except that a zero vector stays zero (GLSL's normalize(0) is NaN): a normal
// that vanishes (singular normal matrix, opposite normals interpolated) lights as ambient.
vec3 normalize_or_zero(vec3 v) {
    return dot(v, v) > 0.0 ? normalize(v) : vec3(0.0);
}

// spec = max(R.V, 0)^n where N.L > 0 and R.V > 0, else 0: pow never sees a base <= 0.
float specular_factor(float n_dot_l, float r_dot_v, float n) {
    if (n_dot_l > 0.0 && r_dot_v > 0.0) {
        return pow(r_dot_v, n);
    }
    return 0.0;
}

// One light's diffuse and specular terms: att I_l k_d max(N.L, 0) + att I_l k_s spec.
// N, L, V are unit vectors; att_intensity is att * I_l.
vec3 light_terms(vec3 N, vec3 L, vec3 V, vec3 att_intensity) {
    float n_dot_l = dot(N, L);
    vec3 R = 2.0 * n_dot_l * N - L;                  // perfect reflection of L about N
    float spec = specular_factor(n_dot_l, dot(R, V), u_n);
    return att_intensity * u_kd * max(n_dot_l, 0.0)
         + att_intensity * u_ks * spec;
}

// The colour I at world point P with unit normal N (already flipped for a two-sided back face).
vec3 shade(vec3 P, vec3 N) {
    vec3 V = normalize_or_zero(u_eye - P);
    vec3 I = u_ambient * u_ka;
#if NUM_DIRECTIONAL_LIGHTS > 0
    for (int i = 0; i < NUM_DIRECTIONAL_LIGHTS; ++i) {
        vec3 L = normalize(-u_directional_direction[i]);
        I += light_terms(N, L, V, u_directional_intensity[i]);       // att = 1
    }
#endif
#if NUM_POINT_LIGHTS > 0
    for (int i = 0; i < NUM_POINT_LIGHTS; ++i) {
        vec3 to_light = u_point_position[i] - P;
        float d = length(to_light);
        vec3 L = d > 0.0 ? to_light / d : N;         // a light on the surface: fully incident
        vec3 c_l_q = u_point_attenuation[i];
        float att = 1.0 / (c_l_q.x + c_l_q.y * d + c_l_q.z * d * d);
        I += light_terms(N, L, V, att * u_point_intensity[i]);
    }
#endif
    return I;
}
