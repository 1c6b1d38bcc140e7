// Twin: reference/fragment.py
#version 330 core
// Per-fragment shading. Flat and Gouraud pick the colour lit for the side seen
// (gl_FrontFacing: counter-clockwise in window coordinates); Phong renormalises the
// interpolated normal, flips it for a two-sided back face, and lights the fragment.
// out_color is clamped and converted to unorm8 by GL; LINEAR_OUTPUT adds the unclamped
// float colour as a second output. Alpha is 1: the background is cleared to alpha 0.
// SHADOW_MAPS (an object that receives shadows in a scene with maps): each light's diffuse
// and specular terms are multiplied by its visibility from the shadow maps (lighting.glsl's
// SHADOWS hook, answered by shadow/lookup.glsl), looked up at this fragment's world position
// with its lit normal (flipped for a two-sided back face). Phong lights the fragment so; flat
// and Gouraud get the terms apart from geometry.glsl (one per triangle, the face normal) or
// vertex.glsl (interpolated, the interpolated normal renormalised): the ambient term plus each
// light's term times its visibility, with no lookup where the term is 0.
// TEXTURED (a textured material): the texel at the fragment's UV (glsl/texture.glsl) multiplies
// the coefficients the material names (TEXTURE_KA, TEXTURE_KD, TEXTURE_KS): Phong lights with
// them so (lighting.glsl's material_factors); flat and Gouraud get their lighting in two parts
// (the other coefficients' and the modulated ones', glsl/vertex.glsl) and add other +
// modulated * texel: the colour, the ambient term and each light's term (before its visibility
// weighs it) alike.

#ifdef SHADOW_MAPS
#define SHADOWS
#endif
#if defined(SHADING_PHONG) || defined(SHADOW_MAPS)
#include "lighting.glsl"
#endif
#ifdef SHADOW_MAPS
#include "shadow/lookup.glsl"
#endif
#ifdef TEXTURED
#include "texture.glsl"
#ifdef SHADING_FLAT
#define UV f_uv                      // from geometry.glsl (flat_varyings.glsl)
#else
in vec2 v_uv;                        // from vertex.glsl
#define UV v_uv
#endif
vec3 texel;                          // the material's texel at this fragment (main() looks it up)
#endif

#ifdef SHADOW_MAPS
// The faces (renderer/core/facets.py face_texture: two texels a face, FACES_PER_ROW a row;
// (object-space normal as wound, crease on its side), (crease on the other side, 0, 0, 0)),
// for the shadow lookup's facet normal and crease.
uniform sampler2D u_face_normals;
uniform mat3 u_normal_matrix;
uniform int u_shadow_facets;         // 1: a mesh, its facets are its surface; 0: an analytic shape
#endif

#if defined(SHADING_FLAT)
#define FLAT_VARYING in                  // from geometry.glsl, one per triangle
#include "flat_varyings.glsl"
#elif defined(SHADING_PHONG)
in vec3 v_world_position;
in vec3 v_world_normal;
#elif defined(SHADOW_MAPS)
in vec3 v_world_position;            // from vertex.glsl, interpolated
in vec3 v_world_normal;
in vec3 v_ambient;
#ifdef TEXTURED
in vec3 v_modulated_ambient;
#endif
#if NUM_DIRECTIONAL_TERMS > 0
in vec3 v_directional_terms_front[NUM_DIRECTIONAL_TERMS];
#ifdef TWO_SIDED
in vec3 v_directional_terms_back[NUM_DIRECTIONAL_TERMS];
#endif
#endif
#if NUM_POINT_TERMS > 0
in vec3 v_point_terms_front[NUM_POINT_TERMS];
#ifdef TWO_SIDED
in vec3 v_point_terms_back[NUM_POINT_TERMS];
#endif
#endif
#else
in vec3 v_color_front;               // from vertex.glsl, interpolated
#ifdef TWO_SIDED
in vec3 v_color_back;
#endif
#ifdef TEXTURED
in vec3 v_modulated_front;
#ifdef TWO_SIDED
in vec3 v_modulated_back;
#endif
#endif
#endif

// A back face seen is lit from its own side only for a two-sided material. The all-features
// build compiles that code for every material and asks u_two_sided at run time.
#ifdef ALL_FEATURES
uniform bool u_two_sided;
#define BACK_FACE_LIT (!gl_FrontFacing && u_two_sided)
#else
#define BACK_FACE_LIT (!gl_FrontFacing)
#endif

layout(location = 0) out vec4 out_color;
#ifdef LINEAR_OUTPUT
layout(location = 1) out vec4 out_linear_color;
#endif

#if defined(SHADOW_MAPS) && !defined(SHADING_PHONG)
// Light i's term in `terms` (TEXTURED: its other part plus its modulated part times the texel).
#ifdef TEXTURED
#define LIGHT_TERM(terms, rows, i) (terms[i] + terms[(rows) + (i)] * texel)
#else
#define LIGHT_TERM(terms, rows, i) terms[i]
#endif

// The terms of the side seen (`back`: a two-sided back face), each light's weighed by its
// visibility at P with the lit normal N, added to the ambient term in lighting()'s order. The
// varyings' names (AMBIENT, ...: flat's or Gouraud's) are lighting.glsl's.
// Light i's term of the side lit: KIND_BACK's where `back` (two-sided), else KIND_FRONT's.
#ifdef TWO_SIDED
#define SIDED_TERM(KIND, ROWS, i) (back ? LIGHT_TERM(KIND##_BACK, ROWS, i) : LIGHT_TERM(KIND##_FRONT, ROWS, i))
#else
#define SIDED_TERM(KIND, ROWS, i) LIGHT_TERM(KIND##_FRONT, ROWS, i)
#endif
vec3 shadowed_terms(vec3 P, vec3 N, bool back) {
#ifdef TEXTURED
    vec3 color = AMBIENT + MODULATED_AMBIENT * texel;
#else
    vec3 color = AMBIENT;
#endif
#if NUM_DIRECTIONAL_TERMS > 0
    for (int i = 0; i < DIRECTIONAL_LIGHTS; ++i)
        color += shadowed_directional(i, P, N, SIDED_TERM(DIRECTIONAL_TERMS, DIRECTIONAL_TERM_ROWS, i));
#endif
#if NUM_POINT_TERMS > 0
    for (int i = 0; i < POINT_LIGHTS; ++i)
        color += shadowed_point(i, P, N, SIDED_TERM(POINT_TERMS, POINT_TERM_ROWS, i));
#endif
    return color;
}
#endif

void main() {
#ifdef TEXTURED
    texel = material_texel(UV);
#endif
#if defined(SHADING_PHONG) || defined(SHADOW_MAPS)
#if defined(SHADING_PHONG)
    vec3 P = v_world_position;
    vec3 N = normalize_or_zero(v_world_normal);
#elif defined(SHADING_FLAT)
    vec3 P = f_world_position;
    vec3 N = f_face_normal;
#else
    vec3 P = v_world_position;
    vec3 N = normalize_or_zero(v_world_normal);
#endif
    bool back = false;
#ifdef TWO_SIDED
    if (BACK_FACE_LIT) {
        N = -N;                      // the back face is seen: light its side
        back = true;
    }
#endif
#ifdef SHADOW_MAPS
    // The facet under the fragment (gl_PrimitiveID: the face's index in the indexed draw,
    // whichever part of it clipping left; flat's geometry stage passes it on): its normal in
    // world space on the side N lights (flat: its face normal, N itself), and how steeply its
    // neighbours rise on that side. An analytic shape's triangles only stand in for its smooth
    // surface (u_shadow_facets 0): its normal is N, its crease how steeply the facet tilts off N.
    // A tessellated sphere (TESSELLATED): N, and no crease. Its maps hold its icosphere, whose
    // facets lie inside the sphere, so no point of the tessellated surface lies behind its own
    // caster's depth; and gl_PrimitiveID numbers its patches, not the triangles drawn.
#ifdef TESSELLATED
    shadow_facet_normal = N;
    shadow_crease = 0.0;
#else
    ivec2 at = ivec2(2 * (gl_PrimitiveID % FACES_PER_ROW), gl_PrimitiveID / FACES_PER_ROW);
    vec4 face = texelFetch(u_face_normals, at, 0);
    vec3 wound = normalize_or_zero(u_normal_matrix * face.xyz);
    bool lit_side = dot(wound, N) >= 0.0;
    shadow_facet_normal = N;
    if (u_shadow_facets != 0) {
#ifndef SHADING_FLAT
        shadow_facet_normal = lit_side ? wound : -wound;
#endif
        shadow_crease = lit_side ? face.w : texelFetch(u_face_normals, at + ivec2(1, 0), 0).x;
    } else {
        // The facet tilts off N by the angle whose cosine is |N.F|: it rises above N's plane
        // at that slope (tan), as a crease's neighbour does (shadow_settings.CREASE_CAP).
        float c = abs(dot(wound, N));
        shadow_crease = c > 0.0 ? min(sqrt(max(1.0 - c * c, 0.0)) / c, SHADOW_CREASE_CAP) : SHADOW_CREASE_CAP;
    }
#endif
#endif
#if defined(SHADING_PHONG)
#ifdef TEXTURED
    material_factors(texel, vec3(1.0));
#endif
    vec3 color = lighting(P, N);
#else
    vec3 color = shadowed_terms(P, N, back);
#endif
#else
    // The colours lit per face (flat: geometry.glsl's f_*) or per vertex (Gouraud: vertex.glsl's v_*).
#ifdef SHADING_FLAT
#define LIT(name) f_##name
#else
#define LIT(name) v_##name
#endif
#ifdef TWO_SIDED
    vec3 color = BACK_FACE_LIT ? LIT(color_back) : LIT(color_front);
#ifdef TEXTURED
    color += (BACK_FACE_LIT ? LIT(modulated_back) : LIT(modulated_front)) * texel;
#endif
#else
    vec3 color = LIT(color_front);
#ifdef TEXTURED
    color += LIT(modulated_front) * texel;
#endif
#endif
#endif
    out_color = vec4(color, 1.0);
#ifdef LINEAR_OUTPUT
    out_linear_color = vec4(color, 1.0);
#endif
}
