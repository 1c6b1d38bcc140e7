#version 430 core
// Test shader for tests/test_output_quantise.py (twin: reference/output/quantise.py,
// count_at_or_below): quantise.glsl's search of the decision points from any guess. Each
// invocation reads (L, guess) from texel gl_GlobalInvocationID.xy of u_probes and writes the
// count to u_counts.
layout(local_size_x = 8, local_size_y = 8) in;
#include "output/quantise.glsl"

layout(rg32f, binding = 0) uniform readonly image2D u_probes;
layout(r32ui, binding = 1) uniform writeonly uimage2D u_counts;

void main() {
    ivec2 p = ivec2(gl_GlobalInvocationID.xy);
    vec2 probe = imageLoad(u_probes, p).xy;
    imageStore(u_counts, p, uvec4(count_at_or_below(probe.x, u_decision_points, probe.y)));
}
