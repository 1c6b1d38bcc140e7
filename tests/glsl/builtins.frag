#version 330 core
// Test shader for tests/test_glsl_builtins.py: GLSL's vector built-ins on two float textures'
// vectors (a, b at each pixel), for their twin reference/glsl_builtins.py. out_a: (dot(a, b),
// length(a), cross(a, b).x, cross(a, b).y); out_b: (normalize(a), cross(a, b).z).
uniform sampler2D u_a;
uniform sampler2D u_b;
layout(location = 0) out vec4 out_a;
layout(location = 1) out vec4 out_b;

void main() {
    ivec2 pixel = ivec2(gl_FragCoord.xy);
    vec3 a = texelFetch(u_a, pixel, 0).xyz;
    vec3 b = texelFetch(u_b, pixel, 0).xyz;
    vec3 c = cross(a, b);
    out_a = vec4(dot(a, b), length(a), c.x, c.y);
    out_b = vec4(normalize(a), c.z);
}
