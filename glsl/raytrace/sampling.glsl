// Twin: reference/raytrace/sampling.py
// Where sample k of this frame lies in a pixel (docs/conventions.md, "Sample positions"; the
// constants: renderer/core/ray_sampling.py): its offset (dx, dy) from the pixel's centre, in
// [-0.5, 0.5)^2, bit for bit the twin's. SAMPLE_TABLE (regular, poisson): u_sample_offsets[k],
// the same in every pixel and frame. Otherwise stratified (random: one 1 x 1 cell; jittered;
// adaptive's two sets): samples k < FIRST_SAMPLES in cell k of a FIRST_COLUMNS x FIRST_ROWS
// grid, the others in cell k - FIRST_SAMPLES of a REST_COLUMNS x REST_ROWS grid (row by row,
// the cell number modulo the grid's cells), placed in the cell by the PCG numbers of (pixel,
// sample index u_first_sample + k, bounce 0, u_seed), dimension 0 for x and 1 for y.
#include "raytrace/random.glsl"

#ifndef NUM_SAMPLES
#define NUM_SAMPLES 1
#endif
#ifndef FIRST_SAMPLES
#define FIRST_SAMPLES NUM_SAMPLES
#endif
#ifdef SAMPLE_TABLE
uniform vec2 u_sample_offsets[NUM_SAMPLES];
#else
uniform uint u_seed;
uniform uint u_first_sample;

// The coordinate (minus 0.5) in cell a of c at the uniform number h, in 24-bit fixed point:
// n = max(floor((a 2^24 + (h >> 8)) / c), ceil(a 2^24 / c)), so n 2^-24 lies in [a/c, (a+1)/c)
// exactly. Integer division is exact, and a < c <= 256 keeps the numerators below 2^32;
// n < 2^24, so float(n) 2^-24 - 0.5 is exact too (fused or not).
float stratum_offset(uint h, uint a, uint c) {
    uint base = a * 16777216u;
    uint n = max((base + (h >> 8u)) / c, (base + c - 1u) / c);
    return float(n) * 5.9604644775390625e-8 - 0.5;
}
#endif

vec2 sample_offset(uvec2 pixel, int k) {
#ifdef SAMPLE_TABLE
    return u_sample_offsets[k];
#else
    uint j = uint(k);
    uvec2 grid = uvec2(FIRST_COLUMNS, FIRST_ROWS);
    if (k >= FIRST_SAMPLES) {
        j -= uint(FIRST_SAMPLES);
        grid = uvec2(REST_COLUMNS, REST_ROWS);
    }
    j %= grid.x * grid.y;                  // random: every sample in the one 1 x 1 cell
    uint stream = random_stream(pixel.x, pixel.y, u_first_sample + uint(k), 0u, u_seed);
    return vec2(stratum_offset(random_uint(stream, 0u), j % grid.x, grid.x),
                stratum_offset(random_uint(stream, 1u), j / grid.x, grid.y));
#endif
}
