// Twin: reference/raytrace/warp.py
// Warps of a uniform point u in [0, 1)^2 (distributed_2d's, sampling.glsl) onto the domains the
// distributed effects sample (docs/conventions.md, "Distributed sampling"): the unit disc (a
// lens, a disc light), the cosine-weighted hemisphere (the path tracer's diffuse bounce), the
// unit sphere (a sphere light), a Phong lobe (glossy reflection); and
// an orthonormal basis about a direction. They use sin, cos, pow and sqrt, so the GPU and the
// twin agree within a few ulps here, not bit for bit (their inputs are bit for bit).

const float WARP_PI = 3.14159265358979;
const float WARP_TWO_PI = 6.28318530717959;
const float WARP_QUARTER_PI = 0.785398163397448;

// Shirley and Chiu's concentric map ("A Low Distortion Map Between Disk and Square", JGT 2(3),
// 1997, as pbrt-v4's SampleUniformDiskConcentric): the square [-1, 1]^2 onto the unit disc,
// square rings to circles, uniform density 1/pi; u = (0.5, 0.5) is the centre exactly.
vec2 square_to_disc(vec2 u) {
    vec2 o = 2.0 * u - 1.0;
    if (o.x == 0.0 && o.y == 0.0) return vec2(0.0);
    float r, theta;
    if (abs(o.x) > abs(o.y)) {
        r = o.x;
        theta = WARP_QUARTER_PI * (o.y / o.x);
    } else {
        r = o.y;
        theta = 2.0 * WARP_QUARTER_PI - WARP_QUARTER_PI * (o.x / o.y);
    }
    return r * vec2(cos(theta), sin(theta));
}

// Cosine-weighted on the hemisphere about +z (Malley's method), density cos(alpha) / pi: the
// concentric disc point lifted to the hemisphere, z = sqrt(max(0, 1 - x^2 - y^2)).
vec3 square_to_cosine_hemisphere(vec2 u) {
    vec2 p = square_to_disc(u);
    return vec3(p, sqrt(max(0.0, 1.0 - dot(p, p))));
}

// Uniform on the unit sphere, density 1/(4 pi): z = 1 - 2 u0, phi = 2 pi u1.
vec3 square_to_sphere(vec2 u) {
    float z = 1.0 - 2.0 * u.x;
    float r = sqrt(max(0.0, 1.0 - z * z));
    float phi = WARP_TWO_PI * u.y;
    return vec3(r * cos(phi), r * sin(phi), z);
}

// -log(1 - u) for u in [0, 1), accurate relative to itself for small u too: llvmpipe's log
// has an absolute error of about 1e-7 near 1, which log(1 - u) would make a large relative one
// where u is small. Below 1/16 the Taylor series u (1 + u/2 + ... + u^5/6) (truncation below
// (1/16)^6 / 7 < 2^-26 relative), above it log.
float warp_minus_log_1m(float u) {
    if (u >= 0.0625) return -log(1.0 - u);
    return u * (1.0 + u * (1.0 / 2.0 + u * (1.0 / 3.0 + u * (1.0 / 4.0 + u * (1.0 / 5.0 + u / 6.0)))));
}

// 1 - exp(-t) for t >= 0, accurate relative to itself for small t too (1 - exp(-t) cancels
// there): below ln 2 the series t (1 - t/2 (1 - t/3 (... (1 - t/9)))) (truncation below
// (ln 2)^9 / 10! < 2^-26 relative), above it 1 - exp(-t) (which loses at most a factor 2).
float warp_one_minus_exp(float t) {
    if (t >= 0.693147180559945) return 1.0 - exp(-t);
    float s = 1.0 - t / 9.0;
    s = 1.0 - t / 8.0 * s;
    s = 1.0 - t / 7.0 * s;
    s = 1.0 - t / 6.0 * s;
    s = 1.0 - t / 5.0 * s;
    s = 1.0 - t / 4.0 * s;
    s = 1.0 - t / 3.0 * s;
    s = 1.0 - t / 2.0 * s;
    return t * s;
}

// A direction about +z with the normalised Phong lobe's density (e + 1)/(2 pi) cos^e(alpha)
// (e = 0: the uniform hemisphere): cos alpha = (1 - u0)^(1/(e + 1)), phi = 2 pi u1. Computed as
// 1 - cos alpha = 1 - exp(-t), t = -log(1 - u0) / (e + 1), and sin alpha = sqrt((1 - cos)
// (1 + cos)), so that a narrow lobe (cos alpha near 1) keeps its angle's relative precision:
// sqrt(1 - cos^2) of a rounded cos would quantise it (e = 1e6: by 6 %) and turn pow's few
// ulps into a thousand (docs/conventions.md, "Glossy reflection").
vec3 square_to_phong_lobe(vec2 u, float exponent) {
    float t = warp_minus_log_1m(u.x) / (exponent + 1.0);
    float one_minus_cos = warp_one_minus_exp(t);
    float cos_alpha = 1.0 - one_minus_cos;
    float sin_alpha = sqrt(one_minus_cos * (2.0 - one_minus_cos));
    float phi = WARP_TWO_PI * u.y;
    return vec3(sin_alpha * cos(phi), sin_alpha * sin(phi), cos_alpha);
}

// b1, b2 with (b1, b2, n) a right-handed orthonormal basis for unit n: Duff, Burgess,
// Christensen, Hery, Kensler, Liani and Villemin, "Building an Orthonormal Basis, Revisited",
// JCGT 6(1), 2017 (branchless but for the sign; n.z = 0 counts as positive).
void orthonormal_basis(vec3 n, out vec3 b1, out vec3 b2) {
    float s = n.z >= 0.0 ? 1.0 : -1.0;
    float a = -1.0 / (s + n.z);
    float b = n.x * n.y * a;
    b1 = vec3(1.0 + s * n.x * n.x * a, s * b, -s * n.x);
    b2 = vec3(b, s + n.y * n.y * a, -n.y);
}
