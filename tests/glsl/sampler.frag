#version 330 core
// Test shader for tests/test_sampler_gl.py (twin: reference/sampler.py): texture() of
// u_texture (unit 0) at this pixel's (u, v) = in.xy, or textureLod(..., in.z) with
// EXPLICIT_LOD, where `in` is texel gl_FragCoord.xy of the RGBA32F u_inputs (unit 1). The
// implicit LOD then differences exactly the uploaded coordinates over each 2x2 quad.
uniform sampler2D u_texture;
uniform sampler2D u_inputs;
out vec4 out_colour;

void main() {
    vec4 inputs = texelFetch(u_inputs, ivec2(gl_FragCoord.xy), 0);
#ifdef EXPLICIT_LOD
    out_colour = textureLod(u_texture, inputs.xy, inputs.z);
#else
    out_colour = texture(u_texture, inputs.xy);
#endif
}
