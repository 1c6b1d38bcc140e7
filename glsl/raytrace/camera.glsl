// Twin: reference/raytrace/camera.py
// The camera's primary rays (docs/conventions.md, "Rays"): the ray P = O + s D through the window
// point (x_w, y_w) (GL window coordinates, row 0 at the bottom; pixel (i, j) with sample offset
// (dx, dy) is (i + 0.5 + dx, j + 0.5 + dy), gl_FragCoord.xy + offset), in camera-relative world
// space. O and D are affine in the window point; their coefficients are the per-frame uniforms
// of renderer/core/camera_rays.py, computed in float64 from the inverse of the rasteriser's P V:
// perspective O = 0 (the eye), parallel D = the view direction; s is the view depth.
uniform mat3 u_ray_origin;       // O = u_ray_origin * (x_w, y_w, 1)
uniform mat3 u_ray_direction;    // D = u_ray_direction * (x_w, y_w, 1)

void camera_ray(vec2 window, out vec3 O, out vec3 D) {
    vec3 w = vec3(window, 1.0);
    O = u_ray_origin * w;
    D = u_ray_direction * w;
}

// The thin lens (docs/conventions.md, "Depth of field"; uniforms: renderer/core/camera_rays.py,
// lens_uniforms): the ray through lens point l of the unit disc starts at O + offset,
// offset = l.x u_lens_right + l.y u_lens_up (across the view axis), and meets the pinhole ray
// O + s D on the focus plane s = f: D' = D - offset / f, so s stays the view depth.
#include "raytrace/sampling.glsl"
#include "raytrace/warp.glsl"
uniform vec3 u_lens_right;       // a * the camera's unit right vector
uniform vec3 u_lens_up;          // a * its unit up vector
uniform float u_inverse_focus;   // 1 / f

void thin_lens_ray(vec2 l, inout vec3 O, inout vec3 D) {
    vec3 offset = l.x * u_lens_right + l.y * u_lens_up;
    O = O + offset;
    D = D - offset * u_inverse_focus;
}

// The lens point of sample k: the concentric map of the sampling layer's point of the lens
// dimension at slot 0 (the camera's).

vec2 lens_point(uvec2 pixel, int k) {
    return square_to_disc(distributed_2d(pixel, k, 0u, LENS_DIMENSION, 0u, 1u));
}
