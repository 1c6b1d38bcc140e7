// Twin: reference/texture.py
// The material lookup (fragment stage, TEXTURED only): the texel of the material's texture
// at the fragment's UV, whose RGB (linear) multiplies the coefficients the material names
// (glsl/lighting.glsl, material_factors; docs/conventions.md, "Textures").
// The lookup is at st = uv * u_uv_scale + u_uv_offset, two float32 operations in that order
// (written as two statements; llvmpipe fuses neither: its NIR lowers ffma and LLVM contracts
// no plain fmul and fadd), through texture(): GL takes the level of detail from st's
// differences over the fragment's 2x2 quad, its helper pixels included. Wrap, filter and
// mip levels are the texture unit's sampler object and texture (renderer/gpu/textures.py);
// the twin samples as llvmpipe does (reference/sampler.py).

uniform sampler2D u_texture;         // the material's texture, on MATERIAL_TEXTURE_UNIT
uniform vec2 u_uv_scale;             // (s_u, s_v)
uniform vec2 u_uv_offset;            // (o_u, o_v)

vec3 material_texel(vec2 uv) {
    vec2 st = uv * u_uv_scale;
    st = st + u_uv_offset;
    return texture(u_texture, st).rgb;
}
