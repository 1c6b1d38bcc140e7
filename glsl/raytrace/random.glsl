// Twin: reference/raytrace/random.py
// The ray tracer's random numbers (docs/conventions.md, "Rays"): counter-based, so every
// number is a pure function of (pixel x, pixel y, sample index, bounce, seed, dimension) and
// the NumPy twin draws the very same bits. 32-bit unsigned arithmetic wraps modulo 2^32 in
// GLSL and in the twin alike.
//
// pcg_hash: the PCG hash of Jarzynski & Olano, "Hash Functions for GPU Rendering", JCGT 9(3),
// 2020 (one round of a 32-bit PCG, RXS-M-XS output permutation).

uint pcg_hash(uint v) {
    uint state = v * 747796405u + 2891336453u;
    uint word = ((state >> ((state >> 28u) + 4u)) ^ state) * 277803737u;
    return (word >> 22u) ^ word;
}

// One stream value per (pixel, sample, bounce, seed), by chained hashing (the paper's
// pcg(x + pcg(y + ...)) construction): seed first, the pixel's x last.
uint random_stream(uint x, uint y, uint sample_index, uint bounce, uint seed) {
    uint h = pcg_hash(seed);
    h = pcg_hash(h + bounce);
    h = pcg_hash(h + sample_index);
    h = pcg_hash(h + y);
    return pcg_hash(h + x);
}

// The dimension-th number of a stream (0, 1, 2, ...: e.g. the two coordinates of a direction).
uint random_uint(uint stream, uint dimension) {
    return pcg_hash(stream + dimension);
}

// A uint32 to a float in [0, 1): its top 24 bits times 2^-24. Exact in float32 (an integer
// below 2^24 times a power of two), so the twin gets the same float.
float uint_to_unit_float(uint h) {
    return float(h >> 8u) * 5.9604644775390625e-8;
}

float random_float(uint stream, uint dimension) {
    return uint_to_unit_float(random_uint(stream, dimension));
}
