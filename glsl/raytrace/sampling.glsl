// Twin: reference/raytrace/sampling.py
// Where sample k of this frame lies in a pixel (docs/conventions.md, "Sample positions"; the
// constants: renderer/core/ray_sampling.py): its offset (dx, dy) from the pixel's centre, in
// [-0.5, 0.5)^2, bit for bit the twin's. SAMPLE_TABLE (regular, poisson): u_sample_offsets[k],
// the same in every pixel and frame. Otherwise stratified (random: one 1 x 1 cell; jittered;
// adaptive's two sets): samples k < FIRST_SAMPLES in cell k of a FIRST_COLUMNS x FIRST_ROWS
// grid, the others in cell k - FIRST_SAMPLES of a REST_COLUMNS x REST_ROWS grid (row by row,
// the cell number modulo the grid's cells), placed in the cell by the PCG numbers of (pixel,
// sample index u_first_sample + k, bounce 0, u_seed), dimension 0 for x and 1 for y.
// The other distributed dimensions (distributed_2d, distributed_1d: the lens, the time, a glossy
// lobe, an area light's points) follow the same pattern, shuffled per pixel, frame, ray and
// dimension by `permute` (docs/conventions.md, "Distributed sampling").
#include "raytrace/random.glsl"

#ifndef NUM_SAMPLES
#define NUM_SAMPLES 1
#endif
#ifndef FIRST_SAMPLES
#define FIRST_SAMPLES NUM_SAMPLES
#endif
#ifndef FIRST_COLUMNS                  // one sample in one 1 x 1 cell (a shader that only
#define FIRST_COLUMNS 1                 // includes this file, e.g. through camera.glsl)
#define FIRST_ROWS 1
#define REST_COLUMNS 1
#define REST_ROWS 1
#endif
uniform uint u_seed;
#ifdef SAMPLE_TABLE
uniform vec2 u_sample_offsets[NUM_SAMPLES];
#else
uniform uint u_first_sample;
#endif

// The coordinate in cell a of c at the uniform number h, in 24-bit fixed point:
// n = max(floor((a 2^24 + (h >> 8)) / c), ceil(a 2^24 / c)), so n 2^-24 lies in [a/c, (a+1)/c)
// exactly. Integer division is exact, and a < c <= 256 keeps the numerators below 2^32;
// n < 2^24, so float(n) 2^-24 is exact too. h = 2^31 gives the cell's centre (to 24 bits).
float stratum_coordinate(uint h, uint a, uint c) {
    uint base = a * 16777216u;
    uint n = max((base + (h >> 8u)) / c, (base + c - 1u) / c);
    return float(n) * 5.9604644775390625e-8;
}

// The same, minus 0.5: an offset from the pixel's centre (exact, fused or not).
float stratum_offset(uint h, uint a, uint c) {
    return stratum_coordinate(h, a, c) - 0.5;
}

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

// -- distributed dimensions ---------------------------------------------------------------------
#ifndef DIMENSION_FIRST_COLUMNS
#define DIMENSION_FIRST_COLUMNS 1
#define DIMENSION_FIRST_ROWS 1
#define DIMENSION_REST_COLUMNS 1
#define DIMENSION_REST_ROWS 1
#endif
#ifndef LIGHT_SAMPLES
#define LIGHT_SAMPLES 1
#endif
// renderer/core/ray_sampling.py: the dimensions and the streams' layout (tests/
// test_raytrace_distributed.py holds each equal to its Python name). Camera-level dimensions
// (slot 0): the pixel, the lens, the time; at a hit (slot 1 + g_ray_key): the glossy lobe and
// point light i's area, LIGHT_DIMENSION + i.
const uint PIXEL_DIMENSION = 0u;
const uint LENS_DIMENSION = 1u;
const uint TIME_DIMENSION = 2u;
const uint GLOSSY_DIMENSION = 0u;
const uint LIGHT_DIMENSION = 1u;
const uint DIMENSION_STRIDE = 64u;
const uint PERMUTATION_SALT = 0x5BD1E995u;
const uint CELL_CENTRE = 0x80000000u;           // stratum_coordinate's h of a cell's centre
const float BELOW_ONE = 0.99999994;             // 1 - 2^-24, the largest float32 below 1

// Kensler's hash permutation of [0, l) ("Correlated Multi-Jittered Sampling", Pixar Technical
// Memo 13-01, 2013): rounds of invertible integer steps on the bits of l - 1's mask, walked
// until the value falls below l (cycle walking keeps it a bijection), then rotated by p. The
// rotation is (i + p mod l) mod l, not the memo's (i + p) mod l, whose 32-bit sum may wrap
// and then break the bijection. Integer only: the twin's bits.
uint permute(uint i, uint l, uint p) {
    uint w = l - 1u;
    w |= w >> 1u;
    w |= w >> 2u;
    w |= w >> 4u;
    w |= w >> 8u;
    w |= w >> 16u;
    do {
        i ^= p;
        i *= 0xe170893du;
        i ^= p >> 16u;
        i ^= (i & w) >> 4u;
        i ^= p >> 8u;
        i *= 0x0929eb3fu;
        i ^= p >> 23u;
        i ^= (i & w) >> 1u;
        i *= 1u | p >> 27u;
        i *= 0x6935fa69u;
        i ^= (i & w) >> 11u;
        i *= 0x74dcb303u;
        i ^= (i & w) >> 2u;
        i *= 0x9e501cc3u;
        i ^= (i & w) >> 2u;
        i *= 0xc860a3dfu;
        i &= w;
        i ^= i >> 5u;
    } while (i >= l);
    return (i + p % l) % l;
}

// The first sample index of the frame as the distributed dimensions see it: the table
// patterns (regular, poisson) repeat every frame, as their pixel offsets do.
uint frame_first_sample() {
#ifdef SAMPLE_TABLE
    return 0u;
#else
    return u_first_sample;
#endif
}

// The permutation key of `dimension` at `slot` for the pixel's samples of set `which_set` in
// this frame.
uint permutation_key(uvec2 pixel, uint slot, uint dimension, uint which_set) {
    uint stream = random_stream(pixel.x, pixel.y, frame_first_sample(), slot, u_seed ^ PERMUTATION_SALT);
    return random_uint(stream, 2u * dimension + which_set);
}

// The strata grid of a set's points: one per sample, or LIGHT_SAMPLES per sample.
uvec2 dimension_grid(uint which_set, uint per_sample) {
#if LIGHT_SAMPLES > 1
    if (per_sample > 1u)
        return which_set == 0u ? uvec2(LIGHT_FIRST_COLUMNS, LIGHT_FIRST_ROWS)
                               : uvec2(LIGHT_REST_COLUMNS, LIGHT_REST_ROWS);
#endif
    return which_set == 0u ? uvec2(DIMENSION_FIRST_COLUMNS, DIMENSION_FIRST_ROWS)
                           : uvec2(DIMENSION_REST_COLUMNS, DIMENSION_REST_ROWS);
}

// Sample k's m-th point (m < per_sample: 1, or LIGHT_SAMPLES for an area light) in [0, 1)^2 of
// `dimension` at `slot` (0: the camera's dimensions; 1 + r: at the hit of ray r). Its numbers
// are 2 (DIMENSION_STRIDE dimension + m) and the next of the sample's stream at the slot.
vec2 distributed_2d(uvec2 pixel, int k, uint slot, uint dimension, uint m, uint per_sample) {
    uint stream = random_stream(pixel.x, pixel.y, frame_first_sample() + uint(k), slot, u_seed);
    uint number = 2u * (DIMENSION_STRIDE * dimension + m);
    uint h0 = random_uint(stream, number);
    uint h1 = random_uint(stream, number + 1u);
#ifdef DIMENSION_RANDOM
    return vec2(uint_to_unit_float(h0), uint_to_unit_float(h1));
#else
    uint which_set = k >= FIRST_SAMPLES ? 1u : 0u;
    uint j = uint(k) - which_set * uint(FIRST_SAMPLES);
    uvec2 grid = dimension_grid(which_set, per_sample);
    uint cell = permute(j * per_sample + m, grid.x * grid.y,
                        permutation_key(pixel, slot, dimension, which_set));
#ifdef DIMENSION_TABLE
    if (per_sample == 1u) return min(u_sample_offsets[cell] + 0.5, vec2(BELOW_ONE));
#endif
#ifdef DIMENSION_CENTRES
    h0 = CELL_CENTRE;
    h1 = CELL_CENTRE;
#endif
    return vec2(stratum_coordinate(h0, cell % grid.x, grid.x),
                stratum_coordinate(h1, cell / grid.x, grid.y));
#endif
}

// Sample k's point in [0, 1) of a one-dimensional `dimension` at `slot`: the set's n samples in
// n strata, permuted (regular: their centres; poisson: jittered, a maximal 1D Poisson set
// being the regular grid). Its number is 2 DIMENSION_STRIDE dimension of the stream.
float distributed_1d(uvec2 pixel, int k, uint slot, uint dimension) {
    uint stream = random_stream(pixel.x, pixel.y, frame_first_sample() + uint(k), slot, u_seed);
    uint h = random_uint(stream, 2u * DIMENSION_STRIDE * dimension);
#ifdef DIMENSION_RANDOM
    return uint_to_unit_float(h);
#else
    uint which_set = k >= FIRST_SAMPLES ? 1u : 0u;
    uint j = uint(k) - which_set * uint(FIRST_SAMPLES);
    uint n = which_set == 0u ? uint(FIRST_SAMPLES) : uint(NUM_SAMPLES - FIRST_SAMPLES);
    uint cell = permute(j, n, permutation_key(pixel, slot, dimension, which_set));
#ifdef DIMENSION_CENTRES
    h = CELL_CENTRE;
#endif
    return stratum_coordinate(h, cell, n);
#endif
}
