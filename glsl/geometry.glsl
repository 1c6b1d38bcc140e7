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

layout(triangles) in;
layout(triangle_strip, max_vertices = 3) out;

in vec3 v_world_position[];
#ifdef TEXTURED
in vec2 v_uv[];
#endif
#define FLAT_VARYING out
#include "flat_varyings.glsl"

#define LIGHT_TERMS_OUT                  // lighting.glsl's hand_on_light_terms writes the f_ terms
#include "lighting.glsl"

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
        hand_on_light_terms();
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
