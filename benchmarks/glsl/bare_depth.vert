#version 330 core
// benchmarks/bench_shadows.py's bare program, pass 1: a caster straight to a light's clip
// coordinates (the matrix composed on the CPU once, outside the timed loop). Depth only.

uniform mat4 u_clip_from_model;

in vec3 in_position;

void main() {
    gl_Position = u_clip_from_model * vec4(in_position, 1.0);
}
