// Twin: reference/geometry.py
#version 330 core
// Flat shading (linked only with SHADING_FLAT): one colour per triangle, lit at its centroid
// (p0 + p1 + p2) / 3 with the face normal normalize((p1 - p0) x (p2 - p0)) of the world
// positions in the mesh's vertex order. TWO_SIDED also lights the back side with -N; the
// fragment shader picks by facing. Positions pass through unchanged, so clipping and
// rasterisation are those of the triangle as drawn.
// SHADOW_MAPS: the face's lighting is kept apart as the vertex stage's Gouraud terms are (the
// ambient term and each light's term, one per triangle), with the face normal and the
// interpolated world position, for fragment.glsl to weigh each light's term by its
// visibility per fragment.
// TEXTURED: the vertices' UVs pass through (f_uv, interpolated), and the face's lighting is
// kept apart by coefficient as the vertex stage's Gouraud lighting is (glsl/vertex.glsl):
// f_modulated_* beside f_color_*, or with SHADOW_MAPS each light's term in TERM_PARTS rows
// and f_modulated_ambient beside f_ambient.

#include "lighting.glsl"

layout(triangles) in;
layout(triangle_strip, max_vertices = 3) out;

in vec3 v_world_position[];
#ifdef TEXTURED
in vec2 v_uv[];
out vec2 f_uv;
#endif

#ifdef SHADOW_MAPS
out vec3 f_world_position;           // where fragment.glsl looks the maps up
flat out vec3 f_face_normal;
flat out vec3 f_ambient;             // I_a k_a
#ifdef TEXTURED
flat out vec3 f_modulated_ambient;   // I_a k_a where the texel modulates k_a, else 0
#endif
#if NUM_DIRECTIONAL_TERMS > 0
flat out vec3 f_directional_terms_front[NUM_DIRECTIONAL_TERMS];
#ifdef TWO_SIDED
flat out vec3 f_directional_terms_back[NUM_DIRECTIONAL_TERMS];
#endif
#endif
#if NUM_POINT_TERMS > 0
flat out vec3 f_point_terms_front[NUM_POINT_TERMS];
#ifdef TWO_SIDED
flat out vec3 f_point_terms_back[NUM_POINT_TERMS];
#endif
#endif
#else
flat out vec3 f_color_front;         // lit with N (TEXTURED: the unmodulated coefficients')
#ifdef TWO_SIDED
flat out vec3 f_color_back;          // lit with -N
#endif
#ifdef TEXTURED
flat out vec3 f_modulated_front;     // the modulated coefficients' terms, lit with N
#ifdef TWO_SIDED
flat out vec3 f_modulated_back;
#endif
#endif
#endif

void main() {
    vec3 p0 = v_world_position[0];
    vec3 p1 = v_world_position[1];
    vec3 p2 = v_world_position[2];
    vec3 face_normal = normalize_or_zero(cross(p1 - p0, p2 - p0));
    vec3 face_centroid = (p0 + p1 + p2) / 3.0;
#ifdef SHADOW_MAPS
    keep_light_terms(face_centroid, face_normal, view_vector(face_centroid));
#else
#ifdef TEXTURED
    material_part(MODULATED_PART);
    vec3 modulated_front = lighting(face_centroid, face_normal);
#ifdef TWO_SIDED
    vec3 modulated_back = lighting(face_centroid, -face_normal);
#endif
    material_part(OTHER_PART);
#endif
    vec3 front_color = lighting(face_centroid, face_normal);
#ifdef TWO_SIDED
    vec3 back_color = lighting(face_centroid, -face_normal);
#endif
#endif
    for (int i = 0; i < 3; ++i) {
        gl_Position = gl_in[i].gl_Position;
#ifdef TEXTURED
        f_uv = v_uv[i];
#endif
#ifdef SHADOW_MAPS
        gl_PrimitiveID = gl_PrimitiveIDIn;      // the face, for fragment.glsl's face texture
        f_world_position = v_world_position[i];
        f_face_normal = face_normal;
        f_ambient = kept_ambient[OTHER_PART];
#ifdef TEXTURED
        f_modulated_ambient = kept_ambient[MODULATED_PART];
#endif
#if NUM_DIRECTIONAL_TERMS > 0
        f_directional_terms_front = kept_directional_front;
#ifdef TWO_SIDED
        f_directional_terms_back = kept_directional_back;
#endif
#endif
#if NUM_POINT_TERMS > 0
        f_point_terms_front = kept_point_front;
#ifdef TWO_SIDED
        f_point_terms_back = kept_point_back;
#endif
#endif
#else
        f_color_front = front_color;
#ifdef TWO_SIDED
        f_color_back = back_color;
#endif
#ifdef TEXTURED
        f_modulated_front = modulated_front;
#ifdef TWO_SIDED
        f_modulated_back = modulated_back;
#endif
#endif
#endif
        EmitVertex();
    }
    EndPrimitive();
}
