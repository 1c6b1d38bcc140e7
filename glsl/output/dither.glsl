// Twin: reference/output/dither.py
// The threshold T in (0, 1) of pixel p for ordered and blue-noise dithering; the code is then
// bracketed_code(L, T) (quantise.glsl), the same T for R, G and B. p = (column, image row from
// the top): the pass reads the frame with row 0 at the top (docs/conventions.md, "Output").

#if defined(DITHER_ORDERED)
// Bayer's matrix of side n = DITHER_ORDERED (2, 4 or 8): M(x, y) interleaves the bits of
// x XOR y and y, lowest bits first into the highest places (the bit-reverse of the
// interleave), so M2 = [[0, 2], [3, 1]] (row y = 0 first). T = (M + 1/2) / n^2, exact.
float dither_threshold(uvec2 p) {
    uint n = uint(DITHER_ORDERED);
    uint x = p.x & (n - 1u), y = p.y & (n - 1u);
    uint a = x ^ y;
    uint m = 0u;
    for (uint bit = 1u; bit < n; bit <<= 1u) {
        m = (m << 2u) | ((a & bit) != 0u ? 2u : 0u) | ((y & bit) != 0u ? 1u : 0u);
    }
    return (float(m) + 0.5) / float(n * n);
}
#elif defined(DITHER_BLUE_NOISE)
// A void-and-cluster mask of ranks (renderer/core/blue_noise.py), tiled from (0, 0):
// T = (rank + 1/2) / size^2, exact.
layout(std430, binding = 1) readonly buffer BlueNoise { uint blue_noise_ranks[]; };
uniform uint u_blue_noise_size;

float dither_threshold(uvec2 p) {
    uint size = u_blue_noise_size;
    uint rank = blue_noise_ranks[(p.y % size) * size + p.x % size];
    return (float(rank) + 0.5) / float(size * size);
}
#endif
