// Twin: reference/output/error_diffusion.py
#version 430 core
// Error diffusion (Floyd-Steinberg, Jarvis-Judice-Ninke) in linear light, one dispatch per
// wavefront t = x + s y (renderer/core/error_kernels.py): every pixel of the wavefront pulls
// the errors its kernel's earlier neighbours left in the error image, which earlier dispatches
// wrote (the pass puts a memory barrier between dispatches). One invocation per pixel of the
// wavefront, rows u_wavefront.y .. u_wavefront.z. The rule, op for op, is in the twin's
// docstring; the error image has a zero border u_reach wide (left, right, top), so no tap
// needs a test, and a source's share of its error comes from a table by its distances to
// the image's edges (renormalised there: error_kernels.sender_weights). Alpha is the plain
// nearest code of the linear transfer, as in output.comp.
layout(local_size_x = WAVEFRONT_GROUP) in;      // renderer/gpu/output.py's, as MAX_TAPS

layout(rgba32f, binding = 0) uniform readonly image2D u_linear;
layout(rgba16ui, binding = 1) uniform writeonly uimage2D u_codes;
layout(rgba32f, binding = 2) uniform image2D u_error;
#include "quantise.glsl"

// The shares (error_kernels.sender_weights): tap k of a source at `left`, `right` and `below`
// pixels from the edges at texel (k, (left (r + 1) + right) (r + 1) + below), r = u_reach. A
// texture, not an SSBO: renderer/gpu/output.py says why.
uniform sampler2D u_shares;

uniform ivec3 u_wavefront;            // (t, first row, last row)
uniform int u_skew;                   // s
uniform int u_reach;                  // r: how far an error travels, the border's width
uniform int u_taps;
uniform ivec2 u_tap_offset[MAX_TAPS]; // pull form: the sources, in the order they are added

// The share of its error the source pixel s sends along tap k (error_kernels.sender_sides).
float share(ivec2 s, int k) {
    ivec2 size = imageSize(u_linear);
    ivec3 sides = clamp(ivec3(s.x, size.x - 1 - s.x, size.y - 1 - s.y), 0, u_reach);
    int side = u_reach + 1;
    return texelFetch(u_shares, ivec2(k, (sides.x * side + sides.y) * side + sides.z), 0).r;
}

void main() {
    int y = u_wavefront.y + int(gl_GlobalInvocationID.x);
    if (y > u_wavefront.z) {
        return;
    }
    ivec2 p = ivec2(u_wavefront.x - u_skew * y, y);
    ivec2 here = p + ivec2(u_reach);
    vec3 incoming = vec3(0.0);
    for (int k = 0; k < u_taps; ++k) {
        ivec2 source = p + u_tap_offset[k];
        incoming = incoming + share(source, k) * imageLoad(u_error, source + ivec2(u_reach)).rgb;
    }
    vec4 linear = imageLoad(u_linear, p);
    vec3 target = vec3(clamp_light(linear.r), clamp_light(linear.g), clamp_light(linear.b)) + incoming;
    uvec4 code;
    code.r = bracketed_code(target.r, 0.5);
    code.g = bracketed_code(target.g, 0.5);
    code.b = bracketed_code(target.b, 0.5);
    code.a = alpha_code(linear.a);
    vec3 chosen = vec3(table(u_code_values + code.r), table(u_code_values + code.g),
                       table(u_code_values + code.b));
    imageStore(u_error, here, vec4(target - chosen, 0.0));
    imageStore(u_codes, p, code);
}
