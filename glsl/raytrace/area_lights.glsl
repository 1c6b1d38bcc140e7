// Twin: reference/raytrace/area_lights.py
// Area lights, the ray tracer's soft shadows (docs/conventions.md, "Area lights"): included by
// trace.glsl, whose light_visibility_at, g_pixel, g_sample and g_ray_key it uses, with
// lighting.glsl's point_term_at and sampling.glsl's distributed_2d (warp.glsl: the disc and
// sphere maps). Compiled under AREA_LIGHTS (renderer/core/light_areas.py).
#include "raytrace/sampling.glsl"
#include "raytrace/warp.glsl"

#if defined(AREA_LIGHTS) && NUM_POINT_LIGHTS > 0
// Area lights (docs/conventions.md, "Area lights"; the uniform: renderer/core/light_areas.py).
// Point light i's area is u_point_position[i] + p.x a_0 + p.y a_1 + p.z a_2, the axes a_j in
// rows 3i .. 3i + 2 of u_point_area and p a point of the unit shape named by row 3i's w
// (AREA_NONE: no area, the point light's own code). Row 3i + 1's w: 1 where the area has a size,
// a one-sided Lambertian emitter (area_emission); a rectangle's or disc's row 3i + 2: its unit
// normal (its points' p.z is 0, so the offset is the same).
uniform vec4 u_point_area[3 * NUM_POINT_LIGHTS];
const float AREA_NONE = 0.0;
const float AREA_RECTANGLE = 1.0;
const float AREA_DISC = 2.0;

bool has_area(int i) {
    return u_point_area[3 * i].w != AREA_NONE;
}

// The point of light i's area at u in [0, 1)^2: p = (2u - 1, 0) on the rectangle, the
// concentric map's (x, y, 0) on the disc, square_to_sphere(u) on the sphere. An area of size
// 0 has zero axes: the light's position exactly.
vec3 area_light_point(int i, vec2 u) {
    float shape = u_point_area[3 * i].w;
    vec3 p = shape == AREA_RECTANGLE ? vec3(2.0 * u - 1.0, 0.0)
           : shape == AREA_DISC ? vec3(square_to_disc(u), 0.0) : square_to_sphere(u);
    vec3 offset = p.x * u_point_area[3 * i].xyz + p.y * u_point_area[3 * i + 1].xyz
                + p.z * u_point_area[3 * i + 2].xyz;
    return u_point_position[i] + offset;
}

// Lambert's cosine law at point Q of light i's area (drawn at u) towards P: the cosine between
// the emitting normal (a rectangle's or disc's `normal`; a sphere's outward normal, the unit
// point square_to_sphere(u), times 4: the positive cosine's mean over the sphere is 1/4, so
// that far away the sphere is the point light) and P - Q; 0 behind (one-sided). 1 for an area
// of size 0: the isotropic point light, bit for bit.
float area_emission(int i, vec2 u, vec3 Q, vec3 P) {
    if (u_point_area[3 * i + 1].w == 0.0) return 1.0;
    bool planar = u_point_area[3 * i].w == AREA_RECTANGLE || u_point_area[3 * i].w == AREA_DISC;
    vec3 n = planar ? u_point_area[3 * i + 2].xyz : square_to_sphere(u);
    vec3 to_P = P - Q;
    float c = dot(n, to_P);
    if (!(c > 0.0)) return 0.0;
    c = c / sqrt(dot(to_P, to_P));
    return planar ? c : 4.0 * c;
}

// Light i's term at P: the mean over its LIGHT_SAMPLES points q_m (the numbers of dimension
// LIGHT + i at this ray's slot, m of LIGHT_SAMPLES) of point_term_at(q_m) times area_emission,
// each times the visibility of q_m (SHADOWS; no shadow ray where the term is 0, and 0 where the facet is
// turned from q_m: trace.glsl's facet_turned_from), summed in m order.
vec3 area_light_term(int i, vec3 P, vec3 N, vec3 V) {
    vec3 sum = vec3(0.0);
    for (int m = 0; m < LIGHT_SAMPLES; ++m) {
        vec2 u = distributed_2d(g_pixel, g_sample, 1u + g_ray_key, LIGHT_DIMENSION + uint(i),
                                uint(m), uint(LIGHT_SAMPLES));
        vec3 Q = area_light_point(i, u);
        vec3 term = point_term_at(i, Q, P, N, V) * area_emission(i, u, Q, P);
#ifdef SHADOWS
        term = term != vec3(0.0) && !facet_turned_from(N, Q - P) ? light_visibility_at(Q, P) * term
                                                                 : vec3(0.0);
#endif
        sum += term;
    }
    return sum / float(LIGHT_SAMPLES);
}
#endif
