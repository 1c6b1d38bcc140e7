// Twin: reference/radiosity/item_buffer.py
#version 330 core
// Radiosity's item buffers (notes 2, indirect illumination; renderer/gpu/item_buffers.py draws
// them): every element's triangle, once per hemicube face of the batch (one instance a face),
// to that face's clip coordinates. u_clip_from_world holds one matrix a face, four RGBA32F
// texels (its columns), composed in float64 on the CPU (renderer/core/hemicube.py face_views
// and projection) so that one float32 product remains here, the twin's.

uniform sampler2D u_clip_from_world;     // (4 * faces) x 1 texels: face f's columns at 4f .. 4f+3

in vec3 in_position;                     // world, relative to the elements' centre

flat out int v_face;

void main() {
    int f = gl_InstanceID;
    mat4 clip_from_world = mat4(texelFetch(u_clip_from_world, ivec2(4 * f + 0, 0), 0),
                                texelFetch(u_clip_from_world, ivec2(4 * f + 1, 0), 0),
                                texelFetch(u_clip_from_world, ivec2(4 * f + 2, 0), 0),
                                texelFetch(u_clip_from_world, ivec2(4 * f + 3, 0), 0));
    gl_Position = clip_from_world * vec4(in_position, 1.0);
    v_face = f;
}
