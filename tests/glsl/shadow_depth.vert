#version 330 core
// Test shader for tests/test_shadow_depth.py: the depth pass's vertex stage as issue 15's design
// states it (glsl/shadow/depth.vert): light clip coordinates from model coordinates.
uniform mat4 u_clip_from_model;
in vec3 in_position;

void main() {
    gl_Position = u_clip_from_model * vec4(in_position, 1.0);
}
