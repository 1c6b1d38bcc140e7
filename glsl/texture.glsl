// Twin: reference/texture.py
// The material lookup (fragment stage, TEXTURED only): the texel of the material's texture
// at the fragment's UV, whose RGB (linear) multiplies the coefficients the material names
// (glsl/lighting.glsl, material_factors; docs/conventions.md, "Textures").
// The lookup is at st = uv * u_uv_scale + u_uv_offset, two float32 operations in that order
// (lookup_coordinates; llvmpipe fuses them into no fma: its NIR lowers ffma and LLVM contracts
// no plain fmul and fadd; tests/test_texture_raster.py holds it), through texture(): GL takes the level of detail from st's
// differences over the fragment's 2x2 quad, its helper pixels included. Wrap, filter and
// mip levels are the texture unit's sampler object and texture (renderer/gpu/textures.py);
// the twin samples as llvmpipe does (reference/sampler.py).

uniform sampler2D u_texture;         // the material's texture, on MATERIAL_TEXTURE_UNIT
uniform vec2 u_uv_scale;             // (s_u, s_v)
uniform vec2 u_uv_offset;            // (o_u, o_v)

// st = uv * u_uv_scale + u_uv_offset, rounded after the product and after the sum.
vec2 lookup_coordinates(vec2 uv) {
    vec2 st = uv * u_uv_scale;
    return st + u_uv_offset;
}

vec3 material_texel(vec2 uv) {
    return texture(u_texture, lookup_coordinates(uv)).rgb;
}
