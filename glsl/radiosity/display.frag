// Twin: reference/radiosity/display.py
#version 330 core
// The interpolated radiosity is the pixel's linear colour, opaque; the view depth beside it. An
// element reflects and emits from its front only: its back, seen, is black.

in vec3 v_radiosity;
in float v_view_depth;

layout(location = 0) out vec4 out_color;
layout(location = 1) out float out_view_depth;

void main() {
    out_color = vec4(gl_FrontFacing ? v_radiosity : vec3(0.0), 1.0);
    out_view_depth = v_view_depth;
}
