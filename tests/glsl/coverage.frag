#version 330
// Test shader for tests/test_rasterizer.py: red marks coverage, green marks a front face.
out vec4 out_color;

void main() {
    out_color = vec4(1.0, gl_FrontFacing ? 1.0 : 0.0, 0.0, 1.0);
}
