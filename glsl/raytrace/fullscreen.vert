#version 330 core
// The ray tracer's pass (renderer/gpu/raytracer.py, with raytrace.frag) and the viewer's shadow-map view (glsl/viewer/shadow_map.frag): one triangle that covers the viewport, from gl_VertexID (no vertex buffer).
void main() {
    vec2 corner = vec2(float((gl_VertexID & 1) << 2) - 1.0, float((gl_VertexID & 2) << 1) - 1.0);
    gl_Position = vec4(corner, 0.0, 1.0);
}
