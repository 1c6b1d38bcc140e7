// Twin: reference/vertex.py
#version 330 core
// Vertex processing: object space to world space (M) and on to clip space (P V), normals by
// the normal matrix (the cofactor matrix of M's linear part, renderer/core/transforms.py), renormalised.
// SHADING_FLAT:    hands the world position on to geometry.glsl, which lights the face.
// SHADING_GOURAUD: lights the vertex here (front colour; back colour too if TWO_SIDED); with
//                  SHADOW_MAPS it keeps the lighting equation's terms apart instead (the
//                  ambient term and each light's term, front and back) and hands on the world
//                  position and normal, for fragment.glsl to weigh each light's term by its
//                  visibility per fragment (fixed-function GL's ARB_shadow, per light).
// SHADING_PHONG:   hands world position and normal on to fragment.glsl.

#include "lighting.glsl"

uniform mat4 u_model;                // M_world
uniform mat3 u_normal_matrix;        // sign(det A) cof(A), A = M_world[:3, :3], scaled
uniform mat4 u_view;                 // V
uniform mat4 u_projection;           // P

in vec3 in_position;                 // object space
in vec3 in_normal;                   // object space, unit

#if defined(SHADING_FLAT)
out vec3 v_world_position;
#elif defined(SHADING_GOURAUD) && defined(SHADOW_MAPS)
out vec3 v_world_position;           // where fragment.glsl looks the maps up
out vec3 v_world_normal;
out vec3 v_ambient;                  // I_a k_a
#if NUM_DIRECTIONAL_TERMS > 0
out vec3 v_directional_terms_front[NUM_DIRECTIONAL_TERMS];   // directional_term, lit with N
#ifdef TWO_SIDED
out vec3 v_directional_terms_back[NUM_DIRECTIONAL_TERMS];    // lit with -N
#endif
#endif
#if NUM_POINT_TERMS > 0
out vec3 v_point_terms_front[NUM_POINT_TERMS];               // point_term, lit with N
#ifdef TWO_SIDED
out vec3 v_point_terms_back[NUM_POINT_TERMS];
#endif
#endif
#elif defined(SHADING_GOURAUD)
out vec3 v_color_front;              // lit with N
#ifdef TWO_SIDED
out vec3 v_color_back;               // lit with -N
#endif
#elif defined(SHADING_PHONG)
out vec3 v_world_position;
out vec3 v_world_normal;
#else
#error "define one of SHADING_FLAT, SHADING_GOURAUD, SHADING_PHONG"
#endif

void main() {
    vec4 world_position = u_model * vec4(in_position, 1.0);
    gl_Position = u_projection * (u_view * world_position);        // p_clip = P V M p
#if defined(SHADING_FLAT)
    v_world_position = world_position.xyz;
#else
    vec3 world_normal = normalize_or_zero(u_normal_matrix * in_normal);
#if defined(SHADING_GOURAUD) && defined(SHADOW_MAPS)
    v_world_position = world_position.xyz;
    v_world_normal = world_normal;
    v_ambient = ambient_term();
    vec3 V = view_vector(world_position.xyz);
#if NUM_DIRECTIONAL_TERMS > 0
    for (int i = 0; i < DIRECTIONAL_LIGHTS; ++i) {
        v_directional_terms_front[i] = directional_term(i, world_normal, V);
#ifdef TWO_SIDED
        v_directional_terms_back[i] = directional_term(i, -world_normal, V);
#endif
    }
#endif
#if NUM_POINT_TERMS > 0
    for (int i = 0; i < POINT_LIGHTS; ++i) {
        v_point_terms_front[i] = point_term(i, world_position.xyz, world_normal, V);
#ifdef TWO_SIDED
        v_point_terms_back[i] = point_term(i, world_position.xyz, -world_normal, V);
#endif
    }
#endif
#elif defined(SHADING_GOURAUD)
    v_color_front = lighting(world_position.xyz, world_normal);
#ifdef TWO_SIDED
    v_color_back = lighting(world_position.xyz, -world_normal);
#endif
#else
    v_world_position = world_position.xyz;
    v_world_normal = world_normal;
#endif
#endif
}
