#version 330 core
// Test shader for tests/test_texture_raster.py (twin: reference/texture.py): glsl/texture.glsl's
// lookup_coordinates of this pixel's uv = in.xy, where `in` is texel gl_FragCoord.xy of the
// RGBA32F u_inputs (unit 0); u_uv_scale and u_uv_offset as the material's.
#include "texture.glsl"

uniform sampler2D u_inputs;
out vec4 out_st;

void main() {
    vec2 uv = texelFetch(u_inputs, ivec2(gl_FragCoord.xy), 0).xy;
    out_st = vec4(lookup_coordinates(uv), 0.0, 0.0);
}
