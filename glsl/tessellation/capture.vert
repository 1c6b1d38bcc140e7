// Twin: reference/tessellation/tessellator.py
#version 410 core
// The tessellator's capture harness (tests/tessellation_capture.py): one vertex a patch, which
// carries the patch's tessellation levels to the control shader, so that one draw of many
// patches holds many sets of levels.

in vec4 in_outer;                        // gl_TessLevelOuter[0..3]
in vec2 in_inner;                        // gl_TessLevelInner[0..1]

out vec4 v_outer;
out vec2 v_inner;

void main() {
    v_outer = in_outer;
    v_inner = in_inner;
}
