// Twin: reference/output/quantise.py
// Codes from linear light by exact comparisons (renderer/core/quantise.py: the rule and its
// tables). One SSBO per (transfer, bits) holds three sorted float32 tables, each at an offset:
//   u_decision_points  the 2^N - 1 decision points t_k of the transfer: code(L) = #{k: L >= t_k}
//   u_alpha_points     the same for the linear transfer (alpha is coverage, never encoded)
//   u_code_values      the 2^N linear values l_k of the codes (dithering chooses between two)
// A comparison with NaN is false, so NaN counts as 0 everywhere.

layout(std430, binding = 0) readonly buffer QuantiseTables { float tables[]; };
uniform uint u_bits;                 // N, bits per channel of the codes
uniform uint u_decision_points;
uniform uint u_alpha_points;
uniform uint u_code_values;

// How many of the 2^N - 1 ascending entries tables[first ..] are <= L: a binary search by
// halving steps (2^(N-1), ..., 2, 1 add up to 2^N - 1, so no index leaves the table).
uint count_at_or_below(float light, uint first) {
    uint count = 0u;
    for (uint step = 1u << (u_bits - 1u); step > 0u; step >>= 1u) {
        if (light >= tables[first + count + step - 1u]) {
            count += step;
        }
    }
    return count;
}

// The undithered code (the baseline): the nearest code in the encoded domain.
uint nearest_code(float light, uint decision_points) {
    return count_at_or_below(light, decision_points);
}

// L clamped to [0, 1], NaN -> 0 (the comparison is false for NaN).
float clamp_light(float light) {
    return light >= 0.0 ? min(light, 1.0) : 0.0;
}

// Dithering's choice between the two codes whose linear values bracket L: c0, the largest k
// with l_k <= L, and c0 + 1 when L lies more than `threshold` of the way from l_c0 to l_c0+1.
// Each operation is one float32 operation of the twin's, in its order (no fused multiply-add:
// the product is compared, never added).
uint bracketed_code(float light, float threshold) {
    float clamped = clamp_light(light);
    uint low = count_at_or_below(clamped, u_code_values + 1u);    // l_0 = 0 <= L always
    uint top = (1u << u_bits) - 1u;
    if (low == top) {
        return top;
    }
    float low_value = tables[u_code_values + low];
    float step_value = tables[u_code_values + low + 1u] - low_value;
    return clamped - low_value > threshold * step_value ? low + 1u : low;
}
