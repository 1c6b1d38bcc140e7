// Twin: reference/shadow/lookup.py
// The shadow-map lookup (docs/conventions.md, "Shadows"; the rules: renderer/core/shadows.py and
// renderer/core/shadow_settings.py): whether light i reaches the surface point P with unit normal N
// (the normal that is lit), as lighting.glsl's SHADOWS hook asks: 1 lit, 0 in shadow, a fraction
// where a filter straddles a shadow edge. The point is first moved by the bias rule, then compared
// with the depth the light's depth pass stored (glsl/shadow/depth.vert) through GL's depth-compare
// sampler: a tap is lit where its reference depth is <= the stored one (LEQUAL), and LINEAR
// filtering blends the four nearest texels' comparisons bilinearly (percentage-closer filtering).
// Every map is a layer of its light kind's array texture (u_directional_shadow_maps,
// u_point_shadow_maps; layers of side u_*_shadow_map_size, a power of two), drawn from texel
// (0, 0); a point light has six, one per cube face, each widened so that no tap leaves its map.
// Coordinates are camera-relative world coordinates, as lighting.glsl's, whose light counts
// and light uniforms (directions, positions) this reads.
// The facet (docs/conventions.md, "The facet normal"; renderer/core/facets.py): a point whose
// facet is turned from the light (its geometric normal, on the lit side, shadow_facet_normal,
// which fragment.glsl sets before lighting) is not reached by it, as a shadow ray from there
// is blocked by the solid behind; the bias moves the point along the facet's normal, and by
// the normal term only where the light's map holds the object's own texels (its bit in
// u_shadow_self_*: ShadowPlan.self_masks).

// SHADOW_MAX_SLOPE (shadow_settings.MAX_SLOPE: tan(theta) is capped here), SHADOW_SQRT2
// (shadow_settings.SQRT2: the normal offset's move across the map) and SHADOW_CREASE_CAP
// (renderer/core/facets.py CREASE_CAP: a crease's slope is taken up to it) come from Python,
// defined before this file (renderer/gpu/shaders.py, FILE_CONSTANTS).

#include "lighting.glsl"

vec3 shadow_facet_normal;            // the fragment's facet normal on the lit side (fragment.glsl)
float shadow_crease;                 // how steeply its neighbours rise on that side (facets.py)
uniform int u_shadow_self_directional;   // bit i: this object is in directional light i's map
uniform int u_shadow_self_point;         // bit i: ... in point light i's cube

#if NUM_DIRECTIONAL_LIGHTS > 0
uniform sampler2DArrayShadow u_directional_shadow_maps;
uniform float u_directional_shadow_map_size;                       // S of its layers
uniform mat4 u_directional_shadow_matrix[NUM_DIRECTIONAL_LIGHTS];  // P -> (u, v, z_w) in its layer
uniform vec4 u_directional_shadow[NUM_DIRECTIONAL_LIGHTS];         // (layer, texel size, kernel, R/S or 0)
uniform vec4 u_directional_shadow_bias[NUM_DIRECTIONAL_LIGHTS];    // (normal, constant, slope) texels
#endif
#if NUM_POINT_LIGHTS > 0
uniform sampler2DArrayShadow u_point_shadow_maps;
uniform float u_point_shadow_map_size;                             // S of its layers
uniform vec4 u_point_shadow[NUM_POINT_LIGHTS];             // (drawn, R / S, kernel, R)
uniform vec4 u_point_shadow_depth[NUM_POINT_LIGHTS];       // (A, B, near, far): z_w = A + B / m
uniform vec4 u_point_shadow_bias[NUM_POINT_LIGHTS];        // (normal, constant, slope) texels
uniform vec4 u_point_shadow_tiles[6 * NUM_POINT_LIGHTS];   // per face (centre x, y, half, layer or -1)
#endif

// The receiver point moved before it is compared (shadow_settings.BiasRule): along the facet
// normal N by normal * (|N.X| + |N.Y|) + lift texels (X, Y the map's axes) and towards the
// light L by constant + slope * min(tan(theta), SHADOW_MAX_SLOPE) texels; t is the world size
// of a texel.
//
// The crease lift (shadow_settings.crease_lift): where the map holds the receiver's own texels
// (`own`), its point is lifted as high as a neighbouring facet rising at the crease's slope can
// stand within the texels the lookup reads (the filter's reach plus the normal offset's move).
float crease_lift(float own, int kernel, float normal) {
    float reach = kernel == 1 ? 0.5 : 0.5 * float(kernel);
    return own * shadow_crease * (reach + normal * SHADOW_SQRT2);
}
vec3 shadow_bias_point(vec3 P, vec3 N, vec3 L, vec3 X, vec3 Y, float t, vec4 bias, float lift) {
    float c = clamp(dot(N, L), 0.0, 1.0);
    float s = sqrt(1.0 - c * c);
    float tan_theta = c > 0.0 ? min(s / c, SHADOW_MAX_SLOPE) : SHADOW_MAX_SLOPE;
    float normal = bias.x * (abs(dot(N, X)) + abs(dot(N, Y))) + lift;
    float toward = bias.y + bias.z * tan_theta;
    return P + t * (normal * N + toward * L);
}

// The filter's kernel: SHADOW_KERNEL when every map of the scene has the same filter
// (renderer/gpu/shaders.py defines it), so that the taps' loops have constant bounds and are
// unrolled (loops bounded by a uniform cost a shadowed frame a quarter of its time on
// llvmpipe: benchmarks/bench_shadows.py); else the light's own, from its uniform.
#ifdef SHADOW_KERNEL
#define LIGHT_KERNEL(params) SHADOW_KERNEL
#else
#define LIGHT_KERNEL(params) int(params.z)
#endif

// The filter (shadow_settings.FILTERS, tap_offsets): kernel 1 is the nearest texel's comparison,
// read through the LINEAR sampler at that texel's centre (exact: S is a power of two, so the
// centre's weight is 1); K x K PCF is the mean of (K-1)^2 bilinear comparisons on a unit grid
// centred on the point, j (the map's y) outer.
float shadow_filter(sampler2DArrayShadow maps, float S, vec3 uvz, float layer, int kernel) {
    if (kernel == 1) {
        return texture(maps, vec4((floor(uvz.xy * S) + 0.5) / S, layer, uvz.z));
    }
    float sum = 0.0;
    float first = -0.5 * float(kernel - 2);
    for (int j = 0; j < kernel - 1; ++j) {
        for (int i = 0; i < kernel - 1; ++i) {
            vec2 offset = vec2(first + float(i), first + float(j));
            sum += texture(maps, vec4(uvz.xy + offset / S, layer, uvz.z));
        }
    }
    return sum / float((kernel - 1) * (kernel - 1));
}

#if NUM_DIRECTIONAL_LIGHTS > 0
float light_visibility_directional(int i, vec3 P, vec3 N) {
    vec3 L = normalize(-u_directional_direction[i]);
    if (dot(shadow_facet_normal, L) < 0.0) {
        return 0.0;                  // the facet is turned from the light
    }
    vec4 p = u_directional_shadow[i];
    if (p.w == 0.0) {
        return 1.0;                  // no pass this frame: nothing can shadow the receivers
    }
    mat4 M = u_directional_shadow_matrix[i];
    vec3 X = normalize(vec3(M[0][0], M[1][0], M[2][0]));     // row 0 of M: the map's x axis
    vec3 Y = normalize(vec3(M[0][1], M[1][1], M[2][1]));     // row 1: its y axis
    float own = float((u_shadow_self_directional >> i) & 1);  // no texel of its own: no normal offset
    vec4 bias = u_directional_shadow_bias[i];
    bias.x *= own;
    vec3 Q = shadow_bias_point(P, shadow_facet_normal, L, X, Y, p.y, bias,
                               crease_lift(own, LIGHT_KERNEL(p), bias.x));
    vec3 uvz = (M * vec4(Q, 1.0)).xyz;
    if (any(lessThan(uvz.xy, vec2(0.0))) || any(greaterThan(uvz.xy, vec2(p.w)))) {
        return 1.0;                  // outside the map, which holds every caster: nothing there
    }
    return shadow_filter(u_directional_shadow_maps, u_directional_shadow_map_size, uvz, p.x,
                         LIGHT_KERNEL(p));
}
#endif

#if NUM_POINT_LIGHTS > 0
// The cube (shadows.CUBE_FACE_ROTATIONS): face f's right, up and axis (= -back) vectors.
const vec3 CUBE_FACE_RIGHT[6] = vec3[6](vec3(0, 0, -1), vec3(0, 0, 1), vec3(1, 0, 0),
                                        vec3(1, 0, 0), vec3(1, 0, 0), vec3(-1, 0, 0));
const vec3 CUBE_FACE_UP[6] = vec3[6](vec3(0, 1, 0), vec3(0, 1, 0), vec3(0, 0, -1),
                                     vec3(0, 0, 1), vec3(0, 1, 0), vec3(0, 1, 0));
const vec3 CUBE_FACE_AXIS[6] = vec3[6](vec3(1, 0, 0), vec3(-1, 0, 0), vec3(0, 1, 0),
                                       vec3(0, -1, 0), vec3(0, 0, 1), vec3(0, 0, -1));

// The face a direction d from the light falls on: its major axis, ties to the earlier axis
// (x, then y, then z); a negative component picks the odd face (+x 0, -x 1, +y 2, ...).
int cube_face(vec3 d) {
    vec3 a = abs(d);
    if (a.x >= a.y && a.x >= a.z) {
        return d.x < 0.0 ? 1 : 0;
    }
    if (a.y >= a.z) {
        return d.y < 0.0 ? 3 : 2;
    }
    return d.z < 0.0 ? 5 : 4;
}

float light_visibility_point(int i, vec3 P, vec3 N) {
    vec3 light = u_point_position[i];
    vec3 to_light = light - P;
    if (dot(to_light, to_light) == 0.0) {
        return 1.0;                  // a light on the surface: fully incident (lighting.glsl)
    }
    vec3 L = normalize(to_light);
    if (dot(shadow_facet_normal, L) < 0.0) {
        return 0.0;                  // the facet is turned from the light
    }
    vec4 p = u_point_shadow[i];      // (drawn, R / S, kernel, R)
    if (p.x == 0.0) {
        return 1.0;                  // no pass this frame
    }
    // The face is P's own, also for the moved point Q: the bias is sized with that face's axes,
    // and its guard band holds Q (at most the normal offset across the map from P). Reading the
    // face Q falls on instead would meet another face's axes at a seam: acne there.
    int f = cube_face(-to_light);
    vec4 face = u_point_shadow_tiles[6 * i + f];   // (centre x, y, half, layer; -1: not drawn)
    if (face.w < 0.0) {
        return 1.0;                  // the face holds no caster-receiver pair: not drawn
    }
    float t = 2.0 * dot(CUBE_FACE_AXIS[f], -to_light) * face.z / p.w;    // a texel at P's distance
    float own = float((u_shadow_self_point >> i) & 1);        // no texel of its own: no normal offset
    vec4 bias = u_point_shadow_bias[i];
    bias.x *= own;
    vec3 Q = shadow_bias_point(P, shadow_facet_normal, L, CUBE_FACE_RIGHT[f], CUBE_FACE_UP[f], t,
                               bias, crease_lift(own, LIGHT_KERNEL(p), bias.x));
    vec3 d = Q - light;
    float m = dot(CUBE_FACE_AXIS[f], d);
    // The face's map covers the square of tangent coordinates within half of its centre.
    vec2 tangent = vec2(dot(CUBE_FACE_RIGHT[f], d), dot(CUBE_FACE_UP[f], d)) / m;
    vec2 uv = (0.5 * (tangent - face.xy) / face.z + 0.5) * p.y;
    if (any(lessThan(uv, vec2(0.0))) || any(greaterThan(uv, vec2(p.y)))) {
        return 1.0;                  // outside the fitted square, which holds every pair's shadow
    }
    vec4 depth = u_point_shadow_depth[i];
    return shadow_filter(u_point_shadow_maps, u_point_shadow_map_size, vec3(uv, depth.x + depth.y / m),
                         face.w, LIGHT_KERNEL(p));
}
#endif
