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
// TEXTURED (a textured material, glsl/texture.glsl): the vertex's UV is handed on too
// (perspective-correct), and Gouraud's lighting is kept apart by coefficient, the terms of
// the coefficients the texel modulates (lighting.glsl's material_factors(1, 0)) from the
// others' (factors (0, 1)): v_modulated_* beside v_color_*, and with SHADOW_MAPS each
// light's term twice in its array (TERM_PARTS rows a light: the others' rows first, then
// the modulated ones') and v_modulated_ambient beside v_ambient. fragment.glsl adds them
// up as other + modulated * texel.

uniform mat4 u_model;                // M_world
uniform mat3 u_normal_matrix;        // sign(det A) cof(A), A = M_world[:3, :3], scaled
uniform mat4 u_view;                 // V
uniform mat4 u_projection;           // P

in vec3 in_position;                 // object space
in vec3 in_normal;                   // object space, unit
#ifdef TEXTURED
in vec2 in_uv;                       // (u, v), docs/conventions.md "Texture coordinates"
out vec2 v_uv;
#endif

#if defined(SHADING_FLAT)
out vec3 v_world_position;
#elif defined(SHADING_GOURAUD) && defined(SHADOW_MAPS)
#define LIGHT_TERMS_OUT              // lighting.glsl's hand_on_light_terms writes the v_ terms
out vec3 v_world_position;           // where fragment.glsl looks the maps up
out vec3 v_world_normal;
out vec3 v_ambient;                  // I_a k_a
#ifdef TEXTURED
out vec3 v_modulated_ambient;        // I_a k_a where the texel modulates k_a, else 0
#endif
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
out vec3 v_color_front;              // lit with N (TEXTURED: the unmodulated coefficients')
#ifdef TWO_SIDED
out vec3 v_color_back;               // lit with -N
#endif
#ifdef TEXTURED
out vec3 v_modulated_front;          // the modulated coefficients' terms, lit with N
#ifdef TWO_SIDED
out vec3 v_modulated_back;
#endif
#endif
#elif defined(SHADING_PHONG)
out vec3 v_world_position;
out vec3 v_world_normal;
#else
#error "define one of SHADING_FLAT, SHADING_GOURAUD, SHADING_PHONG"
#endif

#include "lighting.glsl"

void main() {
    vec4 world_position = u_model * vec4(in_position, 1.0);
    gl_Position = u_projection * (u_view * world_position);        // p_clip = P V M p
#ifdef TEXTURED
    v_uv = in_uv;
#endif
#if defined(SHADING_FLAT)
    v_world_position = world_position.xyz;
#else
    vec3 world_normal = normalize_or_zero(u_normal_matrix * in_normal);
#if defined(SHADING_GOURAUD) && defined(SHADOW_MAPS)
    v_world_position = world_position.xyz;
    v_world_normal = world_normal;
    keep_light_terms(world_position.xyz, world_normal, view_vector(world_position.xyz));
    hand_on_light_terms();
#elif defined(SHADING_GOURAUD)
#ifdef TEXTURED
    material_part(MODULATED_PART);
    v_modulated_front = lighting(world_position.xyz, world_normal);
#ifdef TWO_SIDED
    v_modulated_back = lighting(world_position.xyz, -world_normal);
#endif
    material_part(OTHER_PART);
#endif
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
