// Twin: reference/tessellation/tessellator.py
#version 410 core
// The tessellator's capture harness: each patch (of one vertex) asks for the levels its vertex
// carries, as float32, unchanged.

layout(vertices = 1) out;

in vec4 v_outer[];
in vec2 v_inner[];

void main() {
    gl_TessLevelOuter[0] = v_outer[0].x;
    gl_TessLevelOuter[1] = v_outer[0].y;
    gl_TessLevelOuter[2] = v_outer[0].z;
    gl_TessLevelOuter[3] = v_outer[0].w;
    gl_TessLevelInner[0] = v_inner[0].x;
    gl_TessLevelInner[1] = v_inner[0].y;
}
