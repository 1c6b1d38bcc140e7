// Twin: reference/vertex.py
#version 330 core
// Vertex processing: object space to world space (M) and on to clip space (P V), normals by
// the normal matrix (the cofactor matrix of M's linear part, renderer/core/transforms.py), renormalised.
// SHADING_FLAT:    hands the world position on to geometry.glsl, which lights the face.
// SHADING_GOURAUD: lights the vertex here (front colour; back colour too if TWO_SIDED); with
//                  SHADOW_MAPS it keeps the lighting equation's terms apart instead (the
//                  ambient term and each light's term, front and back) and hands on the world
//                  position and normal, for fragment.glsl to weigh each light's term by its
//                  visibility per fragment (fixed-function GL's ARB_shadow, per light).
// SHADING_PHONG:   hands world position and normal on to fragment.glsl.
// TEXTURED (a textured material, glsl/texture.glsl): the vertex's UV is handed on too
// (perspective-correct), and Gouraud's lighting is kept apart by coefficient, the terms of
// the coefficients the texel modulates (lighting.glsl's material_factors(1, 0)) from the
// others' (factors (0, 1)): v_modulated_* beside v_color_*, and with SHADOW_MAPS each
// light's term twice in its array (TERM_PARTS rows a light: the others' rows first, then
// the modulated ones') and v_modulated_ambient beside v_ambient. fragment.glsl adds them
// up as other + modulated * texel.

// The work itself is glsl/vertex_stage.glsl, which glsl/tess_evaluation.glsl runs too.

in vec3 in_position;                 // object space
in vec3 in_normal;                   // object space, unit

#ifdef TEXTURED
in vec2 in_uv;                       // (u, v), docs/conventions.md "Texture coordinates"
out vec2 v_uv;
#endif

#include "vertex_stage.glsl"

void main() {
#ifdef TEXTURED
    v_uv = in_uv;
#endif
    vertex_stage(in_position, in_normal);
}
