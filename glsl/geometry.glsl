// Twin: reference/geometry.py
#version 330 core
// Flat shading (linked only with SHADING_FLAT): one colour per triangle, lit at its centroid
// (p0 + p1 + p2) / 3 with the face normal normalize((p1 - p0) x (p2 - p0)) of the world
// positions in the mesh's vertex order. TWO_SIDED also lights the back side with -N; the
// fragment shader picks by facing. Positions pass through unchanged, so clipping and
// rasterisation are those of the triangle as drawn.

#include "lighting.glsl"

layout(triangles) in;
layout(triangle_strip, max_vertices = 3) out;

in vec3 v_world_position[];

flat out vec3 f_color_front;         // lit with N
#ifdef TWO_SIDED
flat out vec3 f_color_back;          // lit with -N
#endif

void main() {
    vec3 p0 = v_world_position[0];
    vec3 p1 = v_world_position[1];
    vec3 p2 = v_world_position[2];
    vec3 face_normal = normalize_or_zero(cross(p1 - p0, p2 - p0));
    vec3 face_centroid = (p0 + p1 + p2) / 3.0;
    vec3 front_color = lighting(face_centroid, face_normal);
#ifdef TWO_SIDED
    vec3 back_color = lighting(face_centroid, -face_normal);
#endif
    for (int i = 0; i < 3; ++i) {
        gl_Position = gl_in[i].gl_Position;
        f_color_front = front_color;
#ifdef TWO_SIDED
        f_color_back = back_color;
#endif
        EmitVertex();
    }
    EndPrimitive();
}
