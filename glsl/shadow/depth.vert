// Twin: reference/shadow/depth.py
#version 330 core
// The light-view depth pass (docs/conventions.md, "Shadows"; renderer/gpu/shadow_maps.py draws
// it): a caster's vertices straight to the light's clip coordinates. u_clip_from_model is the
// pass's clip_from_world times the object's camera-relative model matrix, composed in float64
// on the CPU (renderer/core/shadows.py ShadowPass) so that one float32 product remains here.
// Standard depth mapping, GL_LESS, no culling; only the depth buffer (the map's layer) is written.

uniform mat4 u_clip_from_model;

in vec3 in_position;                 // object space

void main() {
    gl_Position = u_clip_from_model * vec4(in_position, 1.0);
}
