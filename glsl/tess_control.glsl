// Twin: reference/tessellation/control.py
#version 410 core
// Tessellation control (notes 4.1; issue 34): each triangle patch of a curved surface passes
// its corners on and asks for the levels that keep the surface's deviation from its chords
// under u_target_error pixels (renderer/core/tessellation.py states the rule and derives it).
// gl_TessLevelOuter[i] is the edge opposite corner i (GL's triangle domain: the edge u = 0
// joins corners 1 and 2); each edge's level depends on its two end points alone, symmetrically,
// so the two patches sharing an edge compute it from the same bits and no crack opens.

layout(vertices = 3) out;

uniform mat4 u_model;                // M_world
uniform mat4 u_view;                 // V
uniform mat4 u_projection;           // P
uniform float u_viewport_height;     // H, pixels
uniform float u_target_error;        // pixels
uniform float u_surface_radius;      // R in world units (0: flat, level 1)
uniform float u_max_level;
uniform float u_fixed_level;         // > 0: this level on every edge and inside (not by need)

in vec3 v_position[];                // object space
in vec3 v_normal[];
out vec3 c_position[];
out vec3 c_normal[];

float edge_level(vec3 a, vec3 b) {
    if (u_fixed_level > 0.0)
        return u_fixed_level;
    float R = u_surface_radius;
    if (!(R > 0.0))
        return 1.0;
    vec4 mid = u_projection * (u_view * vec4((a + b) * 0.5, 1.0));
    if (!(mid.w > 0.0))
        return u_max_level;                                   // at or behind the eye
    float pixels_per_unit = u_viewport_height * u_projection[1][1] / (2.0 * mid.w);
    float s = u_target_error / pixels_per_unit / R;           // e / R
    if (!(s < 1.0))
        return 1.0;
    vec3 chord_vector = a - b;
    float c2 = dot(chord_vector, chord_vector);
    float c = sqrt(c2);
    float d = sqrt(max(R * R - c2 * 0.25, 0.0));
    if (!(d > 0.0))
        return u_max_level;                                   // a chord across the sphere
    float level = c * (1.0 - s) / (2.0 * d * sqrt(s * (2.0 - s)));
    return clamp(level, 1.0, u_max_level);
}

void main() {
    c_position[gl_InvocationID] = v_position[gl_InvocationID];
    c_normal[gl_InvocationID] = v_normal[gl_InvocationID];
    if (gl_InvocationID == 0) {
        vec3 p0 = (u_model * vec4(v_position[0], 1.0)).xyz;
        vec3 p1 = (u_model * vec4(v_position[1], 1.0)).xyz;
        vec3 p2 = (u_model * vec4(v_position[2], 1.0)).xyz;
        float outer0 = edge_level(p1, p2);
        float outer1 = edge_level(p2, p0);
        float outer2 = edge_level(p0, p1);
        gl_TessLevelOuter[0] = outer0;
        gl_TessLevelOuter[1] = outer1;
        gl_TessLevelOuter[2] = outer2;
        gl_TessLevelInner[0] = max(max(outer0, outer1), outer2);
    }
}
