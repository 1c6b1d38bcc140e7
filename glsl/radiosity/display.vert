// Twin: reference/radiosity/display.py
#version 330 core
// Radiosity's display (notes 3.2.1, Gouraud shading; renderer/gpu/radiosity.py draws it): each
// element's corners to clip coordinates (p_clip = P V p, positions camera-relative as the
// rasteriser's), each carrying its displayed radiosity (renderer/core/radiosity.py
// corner_values) for GL to interpolate across the element, perspective-correct.
// SPECULAR (a material with k_s lit by some light: Lighting.specular): the corner's position,
// its normal (interpolated, renormalised per fragment as Phong shading does) and the element's
// k_s, n and object go on to the fragment's specular term (glsl/radiosity/specular.glsl).

uniform mat4 u_view;                 // V
uniform mat4 u_projection;           // P

in vec3 in_position;                 // world, camera-relative
in vec3 in_radiosity;                // B at this corner, linear RGB

out vec3 v_radiosity;
out float v_view_depth;              // -z_eye, the depth image's value

#ifdef SPECULAR
in vec3 in_normal;                   // the corner's normal (SpecularDisplay.normals)
in vec3 in_ks;
in float in_shininess;
in int in_object;
out vec3 v_position;
out vec3 v_normal;
flat out vec3 v_ks;
flat out float v_shininess;
flat out int v_object;
#endif

void main() {
    vec4 eye = u_view * vec4(in_position, 1.0);
    gl_Position = u_projection * eye;
    v_radiosity = in_radiosity;
    v_view_depth = -eye.z;
#ifdef SPECULAR
    v_position = in_position;
    v_normal = in_normal;
    v_ks = in_ks;
    v_shininess = in_shininess;
    v_object = in_object;
#endif
}
