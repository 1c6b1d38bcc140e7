// Twin: reference/raytrace/warp.py
// Warps of a uniform point u in [0, 1)^2 (distributed_2d's, sampling.glsl) onto the domains the
// distributed effects sample (docs/conventions.md, "Distributed sampling"): the unit disc (a
// lens, a disc light), the unit sphere (a sphere light), a Phong lobe (glossy reflection); and
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

// Uniform on the unit sphere, density 1/(4 pi): z = 1 - 2 u0, phi = 2 pi u1.
vec3 square_to_sphere(vec2 u) {
    float z = 1.0 - 2.0 * u.x;
    float r = sqrt(max(0.0, 1.0 - z * z));
    float phi = WARP_TWO_PI * u.y;
    return vec3(r * cos(phi), r * sin(phi), z);
}

// A direction about +z with the normalised Phong lobe's density (e + 1)/(2 pi) cos^e(alpha)
// (e = 0: the uniform hemisphere): cos alpha = (1 - u0)^(1/(e + 1)) (1 - u0 in (0, 1], so pow
// never sees 0), phi = 2 pi u1.
vec3 square_to_phong_lobe(vec2 u, float exponent) {
    float cos_alpha = pow(1.0 - u.x, 1.0 / (exponent + 1.0));
    float sin_alpha = sqrt(max(0.0, 1.0 - cos_alpha * cos_alpha));
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
