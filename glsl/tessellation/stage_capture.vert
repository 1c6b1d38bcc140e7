// Twin: reference/tessellation/evaluation.py
#version 410 core
// The tessellation stages' capture harness (tests/test_tessellation_stages.py): each patch
// corner's object-space position and normal handed on to glsl/tess_control.glsl unchanged.

in vec3 in_position;
in vec3 in_normal;
out vec3 v_position;
out vec3 v_normal;

void main() {
    v_position = in_position;
    v_normal = in_normal;
}
