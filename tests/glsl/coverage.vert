#version 330
// Test shader for tests/test_rasterizer.py: positions arrive already in normalized device
// coordinates, so the rasteriser sees exactly the window coordinates the test chose.
in vec2 in_position;

void main() {
    gl_Position = vec4(in_position, 0.0, 1.0);
}
