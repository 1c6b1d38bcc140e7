// Twin: reference/tessellation/surface.py
#version 410 core
// The vertex stage of a tessellated object (notes 4.1; issue 34): each patch corner's
// object-space position and normal (and for PN triangles whether the edge opposite it stays
// straight: renderer/core/tessellation.py pn_patches) handed on to glsl/tess_control.glsl; the
// evaluation stage does the vertex stage's work (glsl/vertex_stage.glsl) on every point the
// tessellator makes.

in vec3 in_position;                 // object space
in vec3 in_normal;                   // object space, unit
out vec3 v_position;
out vec3 v_normal;
#ifdef SURFACE_PN
in float in_straight;                // 1.0: the patch's edge opposite this corner stays straight
out float v_straight;
#endif
#ifdef SURFACE_DISPLACED
in vec2 in_uv;                       // where the height image is read
out vec2 v_uv;
#endif

void main() {
    v_position = in_position;
    v_normal = in_normal;
#ifdef SURFACE_PN
    v_straight = in_straight;
#endif
#ifdef SURFACE_DISPLACED
    v_uv = in_uv;
#endif
}
