// Twin: reference/radiosity/display.py
#version 330 core
// Radiosity's display (notes 3.2.1, Gouraud shading; renderer/gpu/radiosity_display.py draws
// it): each element's corners to clip coordinates (p_clip = P V p, positions camera-relative as
// the rasteriser's), each carrying its displayed radiosity (renderer/core/radiosity.py
// corner_values) for GL to interpolate across the element, perspective-correct.

uniform mat4 u_view;                 // V
uniform mat4 u_projection;           // P

in vec3 in_position;                 // world, camera-relative
in vec3 in_radiosity;                // B at this corner, linear RGB

out vec3 v_radiosity;
out float v_view_depth;              // -z_eye, the depth image's value

void main() {
    vec4 eye = u_view * vec4(in_position, 1.0);
    gl_Position = u_projection * eye;
    v_radiosity = in_radiosity;
    v_view_depth = -eye.z;
}
