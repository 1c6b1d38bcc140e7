#version 330 core
// Test shader for tests/test_gl_srgb.py: each pixel writes its texel of the RGBA32F
// u_linear unchanged, so that GL's sRGB framebuffer (GL_FRAMEBUFFER_SRGB on an SRGB8_ALPHA8
// target) does the encoding the test measures.
uniform sampler2D u_linear;
out vec4 out_colour;

void main() {
    out_colour = texelFetch(u_linear, ivec2(gl_FragCoord.xy), 0);
}
