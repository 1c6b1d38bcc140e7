// Twin: reference/output/quantise.py
// Codes from linear light by exact comparisons (renderer/core/quantise.py: the rule and its
// tables). One float texture per (transfer, bits) holds three ascending float32 tables one
// after the other, entry i at texel (i mod 2^u_table_row_bits, i div 2^u_table_row_bits); each
// starts at an offset:
//   u_decision_points  the 2^N - 1 decision points t_k of the transfer: code(L) = #{k: L >= t_k}
//   u_alpha_points     the same for the linear transfer (alpha is coverage, never encoded)
//   u_code_values      the 2^N linear values l_k of the codes (dithering chooses between two)
// Every count is taken of L clamped to [0, 1] (NaN -> 0), which changes no count.
#include "transfer.glsl"

uniform sampler2D u_tables;          // renderer/gpu/output.py, table_texture (why not an SSBO)
uniform uint u_table_row_bits;
uniform uint u_bits;                 // N, bits per channel of the codes
uniform uint u_decision_points;
uniform uint u_alpha_points;
uniform uint u_code_values;

float table(uint i) {
    uint row_mask = (1u << u_table_row_bits) - 1u;
    return texelFetch(u_tables, ivec2(int(i & row_mask), int(i >> u_table_row_bits)), 0).r;
}

// L clamped to [0, 1], NaN -> 0 (the comparison is false for NaN).
float clamp_light(float light) {
    return light >= 0.0 ? min(light, 1.0) : 0.0;
}

// How many of the 2^N - 1 ascending entries table(first ..) are <= L. The search starts
// from `guess`, the count the transfer curve estimates in float32 (exact, or one off near a
// decision point: GLSL's pow is a few ulps off), steps up while the next entry is <= L, then
// down while the one before is above it: exact whatever the guess, and two reads where a
// binary search would take N.
uint count_at_or_below(float light, uint first, float guess) {
    uint entries = (1u << u_bits) - 1u;
    uint count = uint(clamp(guess, 0.0, float(entries)));
    while (count < entries && table(first + count) <= light) {
        count++;
    }
    while (count > 0u && table(first + count - 1u) > light) {
        count--;
    }
    return count;
}

// The undithered code of R, G or B (the baseline): the nearest code in the encoded domain.
uint nearest_code(float light) {
    float clamped = clamp_light(light);
    float top = float((1u << u_bits) - 1u);
    return count_at_or_below(clamped, u_decision_points, floor(encode(clamped) * top + 0.5));
}

// The code of alpha: the nearest code of the linear transfer.
uint alpha_code(float alpha) {
    float clamped = clamp_light(alpha);
    float top = float((1u << u_bits) - 1u);
    return count_at_or_below(clamped, u_alpha_points, floor(clamped * top + 0.5));
}

// Dithering's choice between the two codes whose linear values bracket L: c0, the largest k
// with l_k <= L, and c0 + 1 when L lies more than `threshold` of the way from l_c0 to l_c0+1.
// Each operation is one float32 operation of the twin's, in its order (no fused multiply-add:
// the product is compared, never added).
uint bracketed_code(float light, float threshold) {
    float clamped = clamp_light(light);
    uint top = (1u << u_bits) - 1u;
    uint low = count_at_or_below(clamped, u_code_values + 1u, floor(encode(clamped) * float(top)));
    if (low == top) {
        return top;
    }
    float low_value = table(u_code_values + low);
    float step_value = table(u_code_values + low + 1u) - low_value;
    return clamped - low_value > threshold * step_value ? low + 1u : low;
}
