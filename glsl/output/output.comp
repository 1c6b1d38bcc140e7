// Twin: reference/output/__init__.py
#version 430 core
// The output stage (docs/conventions.md, "Output"): a frame's linear colour (rgba32f, row 0 at
// the top, alpha = coverage) to N-bit codes (rgba16ui) or to encoded float colour (rgba32f,
// FLOAT_OUTPUT), one invocation per pixel in GROUP_SIZE x GROUP_SIZE work groups. The method
// is a define (renderer/core/output_settings.py, defines()), so a program holds only what it
// runs:
//   (none)                  the nearest code, quantise.glsl
//   DITHER_ORDERED=n        Bayer n x n thresholds, dither.glsl
//   DITHER_BLUE_NOISE       a void-and-cluster mask's thresholds, dither.glsl
//   HALFTONE                clustered-dot screens of inks C, M, Y, K, halftone.glsl
//   FLOAT_OUTPUT            encode(), transfer.glsl
// Alpha is always the plain nearest code of the linear transfer. Error diffusion has its own
// program (error_diffusion.comp; it is sequential); a half-tone screens here (HALFTONE).
layout(local_size_x = GROUP_SIZE, local_size_y = GROUP_SIZE) in;   // renderer/gpu/output.py's

layout(rgba32f, binding = 0) uniform readonly image2D u_linear;
#include "transfer.glsl"
#if defined(FLOAT_OUTPUT)
layout(rgba32f, binding = 1) uniform writeonly image2D u_encoded;
#else
layout(rgba16ui, binding = 1) uniform writeonly uimage2D u_codes;
#include "quantise.glsl"
#include "dither.glsl"
#if defined(HALFTONE)
#include "halftone.glsl"
#endif
#endif

void main() {
    ivec2 p = ivec2(gl_GlobalInvocationID.xy);
    if (any(greaterThanEqual(p, imageSize(u_linear)))) {
        return;
    }
    vec4 linear = imageLoad(u_linear, p);
#if defined(FLOAT_OUTPUT)
    imageStore(u_encoded, p, vec4(encode(linear.r), encode(linear.g), encode(linear.b), linear.a));
#else
    uvec4 code;
#if defined(HALFTONE)
    code.rgb = halftone_codes(linear.rgb, uvec2(p));
#elif defined(DITHER_ORDERED) || defined(DITHER_BLUE_NOISE)
    float threshold = dither_threshold(uvec2(p));
    code.r = bracketed_code(linear.r, threshold);
    code.g = bracketed_code(linear.g, threshold);
    code.b = bracketed_code(linear.b, threshold);
#else
    code.r = nearest_code(linear.r);
    code.g = nearest_code(linear.g);
    code.b = nearest_code(linear.b);
#endif
    code.a = alpha_code(linear.a);
    imageStore(u_codes, p, code);
#endif
}
