// Twin: reference/tessellation/tessellator.py
#version 410 core
// The tessellator's capture harness: every vertex the primitive generator makes hands on its
// gl_TessCoord and its patch's number, which transform feedback captures (float32, int32)
// primitive by primitive, vertex by vertex. The layout comes from defines: DOMAIN_TRIANGLES,
// DOMAIN_QUADS or DOMAIN_ISOLINES; SPACING_EQUAL, SPACING_FRACTIONAL_EVEN or
// SPACING_FRACTIONAL_ODD; ORDER_CW or ORDER_CCW; POINT_MODE.

#if defined(DOMAIN_TRIANGLES)
layout(triangles) in;
#elif defined(DOMAIN_QUADS)
layout(quads) in;
#elif defined(DOMAIN_ISOLINES)
layout(isolines) in;
#endif

#if defined(SPACING_EQUAL)
layout(equal_spacing) in;
#elif defined(SPACING_FRACTIONAL_EVEN)
layout(fractional_even_spacing) in;
#elif defined(SPACING_FRACTIONAL_ODD)
layout(fractional_odd_spacing) in;
#endif

#if defined(ORDER_CW)
layout(cw) in;
#elif defined(ORDER_CCW)
layout(ccw) in;
#endif

#ifdef POINT_MODE
layout(point_mode) in;
#endif

out vec3 tess_coord;                     // gl_TessCoord
flat out int patch_id;                   // gl_PrimitiveID: which patch of the draw

void main() {
    tess_coord = gl_TessCoord;
    patch_id = gl_PrimitiveID;
}
