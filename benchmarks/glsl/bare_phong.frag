#version 330 core
// benchmarks/bench_shadows.py's bare program, pass 2: Phong with one depth-compare lookup per
// light (LINEAR: pcf2x2's one bilinear comparison), the least "the same two passes" can do.
// The lookup point moves one texel along the facet's normal and a quarter towards the light
// (a fixed normal offset, not the project's bias rule); a facet turned from the light is
// shadowed (issue 28's facet rule), its normal taken from the screen derivatives, the
// cheapest way (the renderer reads it and the crease from a face texture instead). The benchmark defines NUM_DIRECTIONAL_LIGHTS,
// NUM_POINT_LIGHTS, and SPECULAR, TWO_SIDED as the material asks. Uniform names are the
// project's, so that its values (renderer/core/uniforms.py, ShadowPlan.uniforms) are written
// once before the timed frames.

uniform vec3 u_ka;
uniform vec3 u_kd;
#ifdef SPECULAR
uniform vec3 u_ks;
uniform float u_n;
uniform vec3 u_eye;
#endif
uniform vec3 u_ambient;

#if NUM_DIRECTIONAL_LIGHTS > 0
uniform sampler2DArrayShadow u_directional_shadow_maps;
uniform vec3 u_directional_direction[NUM_DIRECTIONAL_LIGHTS];
uniform vec3 u_directional_intensity[NUM_DIRECTIONAL_LIGHTS];
uniform mat4 u_directional_shadow_matrix[NUM_DIRECTIONAL_LIGHTS];
uniform vec4 u_directional_shadow[NUM_DIRECTIONAL_LIGHTS];      // (layer, texel, kernel, R/S or 0)
#endif
#if NUM_POINT_LIGHTS > 0
uniform sampler2DArrayShadow u_point_shadow_maps;
uniform vec3 u_point_position[NUM_POINT_LIGHTS];
uniform vec3 u_point_intensity[NUM_POINT_LIGHTS];
uniform vec3 u_point_attenuation[NUM_POINT_LIGHTS];
uniform vec4 u_point_shadow[NUM_POINT_LIGHTS];                  // (drawn, R / S, kernel, R)
uniform vec4 u_point_shadow_depth[NUM_POINT_LIGHTS];            // (A, B, near, far)
uniform vec4 u_point_shadow_tiles[6 * NUM_POINT_LIGHTS];        // per face (centre x, y, half, layer or -1)
const vec3 FACE_RIGHT[6] = vec3[6](vec3(0, 0, -1), vec3(0, 0, 1), vec3(1, 0, 0),
                                   vec3(1, 0, 0), vec3(1, 0, 0), vec3(-1, 0, 0));
const vec3 FACE_UP[6] = vec3[6](vec3(0, 1, 0), vec3(0, 1, 0), vec3(0, 0, -1),
                                vec3(0, 0, 1), vec3(0, 1, 0), vec3(0, 1, 0));
const vec3 FACE_AXIS[6] = vec3[6](vec3(1, 0, 0), vec3(-1, 0, 0), vec3(0, 1, 0),
                                  vec3(0, -1, 0), vec3(0, 0, 1), vec3(0, 0, -1));
#endif

in vec3 v_world_position;
in vec3 v_world_normal;

out vec4 out_color;

vec3 shade(vec3 N, vec3 L, vec3 V, vec3 intensity) {
    float n_dot_l = dot(N, L);
    vec3 I = intensity * u_kd * max(n_dot_l, 0.0);
#ifdef SPECULAR
    float r_dot_v = dot(2.0 * n_dot_l * N - L, V);
    if (n_dot_l > 0.0 && r_dot_v > 0.0) {
        I += intensity * u_ks * pow(r_dot_v, u_n);
    }
#endif
    return I;
}

void main() {
    vec3 P = v_world_position;
    vec3 N = normalize(v_world_normal);
#ifdef TWO_SIDED
    if (!gl_FrontFacing) {
        N = -N;
    }
#endif
#ifdef SPECULAR
    vec3 V = normalize(u_eye - P);
#else
    vec3 V = vec3(0.0);
#endif
    vec3 color = u_ambient * u_ka;
    // The facet rule (docs/conventions.md, "The facet normal") in its cheapest form: the
    // facet's normal from the position's screen derivatives, on N's side.
    vec3 F = normalize(cross(dFdx(P), dFdy(P)));
    F = dot(F, N) < 0.0 ? -F : F;
#if NUM_DIRECTIONAL_LIGHTS > 0
    for (int i = 0; i < NUM_DIRECTIONAL_LIGHTS; ++i) {
        vec3 L = normalize(-u_directional_direction[i]);
        vec3 term = shade(N, L, V, u_directional_intensity[i]);
        vec4 p = u_directional_shadow[i];
        if (dot(F, L) < 0.0) {
            term = vec3(0.0);
        } else if (p.w != 0.0 && dot(N, L) > 0.0) {
            vec3 q = (u_directional_shadow_matrix[i] * vec4(P + p.y * (F + 0.25 * L), 1.0)).xyz;
            term *= texture(u_directional_shadow_maps, vec4(q.xy, p.x, q.z));
        }
        color += term;
    }
#endif
#if NUM_POINT_LIGHTS > 0
    for (int i = 0; i < NUM_POINT_LIGHTS; ++i) {
        vec3 to_light = u_point_position[i] - P;
        float distance = length(to_light);
        vec3 L = to_light / distance;
        vec3 c = u_point_attenuation[i];
        vec3 term = shade(N, L, V, u_point_intensity[i] / (c.x + distance * (c.y + distance * c.z)));
        vec4 p = u_point_shadow[i];
        if (dot(F, L) < 0.0) {
            term = vec3(0.0);
        } else if (p.x != 0.0 && dot(N, L) > 0.0) {
            vec3 a = abs(to_light);
            int f = a.x >= a.y && a.x >= a.z ? (to_light.x > 0.0 ? 1 : 0)
                  : (a.y >= a.z ? (to_light.y > 0.0 ? 3 : 2) : (to_light.z > 0.0 ? 5 : 4));
            vec4 tile = u_point_shadow_tiles[6 * i + f];
            if (tile.w >= 0.0) {
                float texel = 2.0 * max(a.x, max(a.y, a.z)) * tile.z / p.w;
                vec3 d = P + texel * (F + 0.25 * L) - u_point_position[i];
                float m = dot(FACE_AXIS[f], d);
                vec2 tangent = vec2(dot(FACE_RIGHT[f], d), dot(FACE_UP[f], d)) / m;
                vec2 uv = (0.5 * (tangent - tile.xy) / tile.z + 0.5) * p.y;
                vec4 z = u_point_shadow_depth[i];
                term *= texture(u_point_shadow_maps, vec4(uv, tile.w, z.x + z.y / m));
            }
        }
        color += term;
    }
#endif
    out_color = vec4(color, 1.0);
}
