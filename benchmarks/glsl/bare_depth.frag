#version 330 core
// benchmarks/bench_shadows.py's bare program, pass 1: no colour, the depth test writes the map.

void main() {
}
