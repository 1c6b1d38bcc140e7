"""How deep the ray tracer recurses (docs/conventions.md, "Depth"): the `max_depth` knob's
limit and Hall and Greenberg's adaptive tree-depth control ("A Testbed for Realistic Image
Synthesis", IEEE CG&A 3(8), 1983), which both twins apply identically: a secondary ray whose
weight is below RAY_WEIGHT_CUTOFF in every channel is not spawned (reference/raytrace/trace.py;
glsl/raytrace/trace.glsl's TRACE_WEIGHT_CUTOFF, which must equal it).

Why 2^-9: a ray's weight multiplies the radiance it brings back, so a ray of weight below 2^-9
brings a colour of 1 (white, the top of the 8-bit range) less than 1/512 < 1/510, under half
an 8-bit step of the frame. Why it bounds the work: the energy rule k_r + k_t <= 1 gives each
ray's children weights that sum to at most its own in each channel (k_r + k_t F and
k_t (1 - F)), so the rays of one depth have weights summing to at most 1 per channel, 3 in
all, and at most 3 / RAY_WEIGHT_CUTOFF = 1536 of them can reach the cut-off: depth d holds at
most min(2^d, 1536) rays (max_rays).
"""

DEFAULT_MAX_DEPTH = 4
# The deepest recursion asked for that is not absurd. The cut-off ends a chain of bounces
# with k_r <= 2^(-9/64) = 0.907 before depth 64 anyway, so only near-perfect mirrors facing
# each other go further; the GLSL's stack (MAX_DEPTH + 2 entries per fragment) and its loop
# bound (max_rays) grow with it.
MAX_DEPTH_LIMIT = 64
RAY_WEIGHT_CUTOFF = 2.0 ** -9
RAYS_PER_DEPTH = 3 * 512            # 3 / RAY_WEIGHT_CUTOFF: the GLSL's TRACE_RAYS_PER_DEPTH


def max_rays(max_depth: int) -> int:
    """The most rays one camera ray's tree can hold (the GLSL's TRACE_MAX_RAYS, its loop
    bound): the sum over depths 0 to max_depth of min(2^d, RAYS_PER_DEPTH)."""
    return sum(min(2 ** d, RAYS_PER_DEPTH) for d in range(max_depth + 1))
