#version 330 core
// Test shader for tests/test_shadow_depth.py: depth only, nothing to write.
void main() {
}
