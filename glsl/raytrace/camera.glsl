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
