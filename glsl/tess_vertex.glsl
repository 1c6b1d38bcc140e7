// Twin: reference/tessellation/surface.py
#version 410 core
// The vertex stage of a tessellated object (notes 4.1; issue 34): each patch corner's
// object-space position and normal handed on to glsl/tess_control.glsl unchanged; the
// evaluation stage does the vertex stage's work (glsl/vertex_stage.glsl) on every point the
// tessellator makes.

in vec3 in_position;                 // object space
in vec3 in_normal;                   // object space, unit
out vec3 v_position;
out vec3 v_normal;

void main() {
    v_position = in_position;
    v_normal = in_normal;
}
