// Twin: reference/vertex.py
// The vertex stage's work on one object-space point (notes 4.1; 3.2.1 Gouraud shading): what
// glsl/vertex.glsl does to each vertex of a mesh, and glsl/tess_evaluation.glsl to each point
// the tessellator makes (TESSELLATED). Included by both; its outputs, per SHADING_*, are the
// next stage's inputs (vertex.glsl's header says what each mode hands on).

uniform mat4 u_model;                // M_world
uniform mat3 u_normal_matrix;        // sign(det A) cof(A), A = M_world[:3, :3], scaled
uniform mat4 u_view;                 // V
uniform mat4 u_projection;           // P

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


void vertex_stage(vec3 object_position, vec3 object_normal) {
    vec4 world_position = u_model * vec4(object_position, 1.0);
    gl_Position = u_projection * (u_view * world_position);        // p_clip = P V M p
#if defined(SHADING_FLAT)
    v_world_position = world_position.xyz;
#else
    vec3 world_normal = normalize_or_zero(u_normal_matrix * object_normal);
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
