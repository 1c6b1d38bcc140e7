// Twin: reference/raytrace/optics.py
// Reflection, refraction, Schlick's Fresnel approximation and the self-intersection offset
// (docs/conventions.md, "Rays"). D is the incoming direction (travelling towards the surface),
// N the unit normal on the incoming side (dot(D, N) <= 0; the caller flips an outward normal
// when the ray leaves a solid), eta = n1 / n2 (the index on the incoming side over the other).
// Named ray_* so as not to shadow GLSL's reflect and refract.

// R = D - 2 (D.N) N: the mirror image of D (any length) about the plane of unit N.
vec3 ray_reflect(vec3 D, vec3 N) {
    return D - 2.0 * dot(D, N) * N;
}

// Snell's law, n1 sin(theta_i) = n2 sin(theta_t), for unit D and N with dot(D, N) <= 0:
// cos_i = -D.N, k = 1 - eta^2 (1 - cos_i^2) = cos_t^2. k < 0 is total internal reflection:
// returns false and T = ray_reflect(D, N); else true and the unit T = eta D + (eta cos_i - sqrt(k)) N.
bool ray_refract(vec3 D, vec3 N, float eta, out vec3 T) {
    float cos_i = -dot(D, N);
    float k = 1.0 - eta * eta * (1.0 - cos_i * cos_i);
    if (k < 0.0) {
        T = ray_reflect(D, N);
        return false;
    }
    T = eta * D + (eta * cos_i - sqrt(k)) * N;
    return true;
}

// Schlick (1994): F = R0 + (1 - R0) (1 - cos)^5 with R0 = ((n1 - n2) / (n1 + n2))^2
// = ((1 - eta) / (1 + eta))^2, cos the cosine of the angle on the less dense side: cos_i when
// n1 <= n2, cos_t when n1 > n2; F = 1 under total internal reflection.
float fresnel_schlick(vec3 D, vec3 N, float eta) {
    float r0 = (1.0 - eta) / (1.0 + eta);
    r0 = r0 * r0;
    float c = -dot(D, N);
    if (eta > 1.0) {
        float k = 1.0 - eta * eta * (1.0 - c * c);
        if (k < 0.0) return 1.0;
        c = sqrt(k);
    }
    float m = 1.0 - c;
    float m2 = m * m;
    return r0 + (1.0 - r0) * (m2 * m2 * m);
}

// The Fresnel equations for an unpolarised ray at a dielectric boundary, eta = n1 / n2:
// r_s = (eta cos_i - cos_t) / (eta cos_i + cos_t), r_p = (cos_i - eta cos_t) / (cos_i + eta cos_t),
// F = (r_s^2 + r_p^2) / 2, cos_t = sqrt(1 - eta^2 (1 - cos_i^2)); F = 1 under total internal
// reflection.
float fresnel_exact(vec3 D, vec3 N, float eta) {
    float c = -dot(D, N);
    float k = 1.0 - eta * eta * (1.0 - c * c);
    if (k < 0.0) return 1.0;
    float t = sqrt(k);
    float rs = (eta * c - t) / (eta * c + t);
    float rp = (c - eta * t) / (c + eta * t);
    return 0.5 * (rs * rs + rp * rp);
}

// The self-intersection offset of Waechter and Binder, "A Fast and Robust Method for Avoiding
// Self-Intersection", Ray Tracing Gems ch. 6 (2019): the hit point p moves along the geometric
// normal n (unit, on the side the new ray leaves to) by int_scale * n units in the last place of
// each coordinate (integer arithmetic on the float bits, so the step scales with |p|); within
// `origin` of 0, where ulps get tiny, by float_scale * n instead.
const float RAY_OFFSET_ORIGIN = 1.0 / 32.0;
const float RAY_OFFSET_FLOAT_SCALE = 1.0 / 65536.0;
const float RAY_OFFSET_INT_SCALE = 256.0;

vec3 offset_ray_origin(vec3 p, vec3 n) {
    ivec3 of_i = ivec3(RAY_OFFSET_INT_SCALE * n);           // truncation towards zero
    ivec3 sign = ivec3(1) - 2 * ivec3(lessThan(p, vec3(0.0)));  // -1 where p < 0 (not -0.0)
    vec3 p_i = intBitsToFloat(floatBitsToInt(p) + sign * of_i);
    vec3 p_f = p + RAY_OFFSET_FLOAT_SCALE * n;
    return mix(p_i, p_f, lessThan(abs(p), vec3(RAY_OFFSET_ORIGIN)));
}
