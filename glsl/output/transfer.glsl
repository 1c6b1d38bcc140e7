// Twin: reference/output/transfer.py
// The transfer curve in float32: float output's value (exr, npy: each RGB channel's V(L),
// unquantised), and where the output is quantised, the guess its exact search starts from
// (quantise.glsl). renderer/core/quantise.py's encode: linear keeps L >= 0 unclamped; sRGB and gamma apply
// the curve to max(L, 0), above 1 too. Negative L and NaN become 0. GLSL's pow is llvmpipe's
// exp2(log2(x) y) (docs/llvmpipe/output.md, section 2): a few ulps from the float64 curve,
// not bit for bit; tests/test_output_transfer.py states the bound.

uniform float u_exponent;            // 1 / 2.4 (sRGB) or 1 / gamma, in float32
uniform vec4 u_srgb;                 // sRGB: linear limit, slope, 1 + a, a (IEC 61966-2-1)

float encode(float light) {
    float l = light >= 0.0 ? light : 0.0;          // NaN -> 0 (the comparison is false)
#if defined(TRANSFER_SRGB)
    return l <= u_srgb.x ? u_srgb.y * l : u_srgb.z * pow(l, u_exponent) - u_srgb.w;
#elif defined(TRANSFER_GAMMA)
    return pow(l, u_exponent);
#else
    return l;
#endif
}
