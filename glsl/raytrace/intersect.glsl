// Twin: reference/raytrace/intersect.py
// Ray intersections (docs/conventions.md, "Rays"): the ray P = O + s D (D need not be unit
// length; s is then in units of |D|) against a plane P.N + d = 0, a sphere
// (P - C).(P - C) - r^2 = 0 and a triangle ABC. Each returns whether the nearest hit with
// s_min < s < s_max exists; `s` is that hit's parameter, or s_max on a miss (so a caller that
// passes the nearest hit so far as s_max keeps it on a miss). One ray per call.

// Plane P.N + d = 0 (N need not be unit): s = -(O.N + d) / (D.N). A ray parallel to the plane
// (D.N == 0, also a ray inside it) misses.
bool ray_plane(vec3 O, vec3 D, vec3 N, float d, float s_min, float s_max, out float s) {
    float denominator = dot(D, N);
    s = s_max;
    if (denominator == 0.0) return false;
    float hit = -(dot(O, N) + d) / denominator;
    if (!(hit > s_min && hit < s_max)) return false;
    s = hit;
    return true;
}

vec3 plane_normal(vec3 N) {
    return normalize(N);
}

// The sphere's discriminant in the robust form of Haines, Guenther and Akenine-Moeller,
// "Precision Improvements for Ray/Sphere Intersection", Ray Tracing Gems ch. 7 (2019), eq. 7.6
// with b = (O - C).D (half the textbook b):
//   b^2 - a c = a (r^2 - |f - (b / a) D|^2),  f = O - C, a = D.D, c = f.f - r^2.
// Returns r^2 - |f - (b/a) D|^2 (the squared distance from the centre to the ray, subtracted
// from r^2): its sign is the discriminant's, and it does not cancel catastrophically as
// b^2 - a c does when the sphere is far away or small against its distance.
float sphere_discriminant(vec3 O, vec3 D, vec3 C, float r) {
    vec3 f = O - C;
    float a = dot(D, D);
    float b = dot(f, D);
    vec3 l = f - (b / a) * D;
    return r * r - dot(l, l);
}

// Roots as the chapter's eq. 7.7 and 7.8 (Press et al.): q = -(b + sign(b) sqrt(a delta)),
// s0 = c / q, s1 = q / a; no subtraction of nearly equal numbers. A tangent ray (delta == 0)
// hits. From inside the sphere the nearer root is behind (s <= s_min): the far root is the hit.
bool ray_sphere(vec3 O, vec3 D, vec3 C, float r, float s_min, float s_max, out float s) {
    vec3 f = O - C;
    float a = dot(D, D);
    float b = dot(f, D);
    float c = dot(f, f) - r * r;
    vec3 l = f - (b / a) * D;
    float delta = r * r - dot(l, l);
    s = s_max;
    if (delta < 0.0) return false;
    float q = -(b + (b >= 0.0 ? 1.0 : -1.0) * sqrt(a * delta));
    float s0 = c / q;
    float s1 = q / a;
    float near = min(s0, s1);
    float far = max(s0, s1);
    if (near > s_min && near < s_max) { s = near; return true; }
    if (far > s_min && far < s_max) { s = far; return true; }
    return false;
}

// A ray that starts on the sphere (a secondary or shadow ray leaving a point of it, with no
// offset): its origin is the root c / q (c = 0 on the surface, up to the rounding of
// f.f - r^2, which cancels there), so the one other point of the sphere it can meet is the
// root s1 = q / a, ahead (s1 > 0) when the ray goes inwards (b < 0) and behind when it leaves
// outwards (q <= 0): a sphere is convex. c is not used.
bool ray_sphere_from_surface(vec3 O, vec3 D, vec3 C, float r, float s_min, float s_max,
                             out float s) {
    vec3 f = O - C;
    float a = dot(D, D);
    float b = dot(f, D);
    vec3 l = f - (b / a) * D;
    float delta = r * r - dot(l, l);
    s = s_max;
    if (delta < 0.0) return false;
    float far = -(b + (b >= 0.0 ? 1.0 : -1.0) * sqrt(a * delta)) / a;
    if (!(far > s_min && far < s_max)) return false;
    s = far;
    return true;
}

// The outward unit normal at a point P on the sphere.
vec3 sphere_normal(vec3 P, vec3 C, float r) {
    return (P - C) / r;
}

// Triangle ABC: Moeller and Trumbore, "Fast, Minimum Storage Ray/Triangle Intersection",
// JGT 2(1), 1997. The hit point is (1 - u - v) A + u B + v C. The triangle is closed: a hit
// on an edge (u == 0, v == 0 or u + v == 1) or a vertex counts. Both faces are hit. A ray
// parallel to its plane (det == 0; also a degenerate triangle) misses.
bool ray_triangle(vec3 O, vec3 D, vec3 A, vec3 B, vec3 C, float s_min, float s_max,
                  out float s, out vec2 uv) {
    vec3 e1 = B - A;
    vec3 e2 = C - A;
    vec3 p = cross(D, e2);
    float det = dot(e1, p);
    s = s_max;
    uv = vec2(0.0);
    if (det == 0.0) return false;
    vec3 t = O - A;
    float u = dot(t, p) / det;
    vec3 q = cross(t, e1);
    float v = dot(D, q) / det;
    float hit = dot(e2, q) / det;
    if (!(u >= 0.0 && v >= 0.0 && u + v <= 1.0 && hit > s_min && hit < s_max)) return false;
    s = hit;
    uv = vec2(u, v);
    return true;
}

// The unit geometric normal of ABC, on the side from which A, B, C run counter-clockwise.
vec3 triangle_normal(vec3 A, vec3 B, vec3 C) {
    return normalize(cross(B - A, C - A));
}
