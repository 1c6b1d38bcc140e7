"""The camera's primary rays (docs/conventions.md, "Rays"), as per-frame uniforms both ray-tracer
twins read (glsl/raytrace/camera.glsl, reference/raytrace/camera.py).

The rays are derived from the very matrices the rasteriser uses: the inverse of `P V` (view a
rotation: camera-relative coordinates, the eye at 0; P possibly jittered), in float64. The
window point (x_w, y_w) (GL window coordinates, row 0 at the bottom; pixel (i, j) sampled at
(i + 0.5 + dx, j + 0.5 + dy)) is unprojected through it, so the ray through a window point
contains exactly the points the rasteriser maps to that window point. Both the origin O and the
direction D of the ray P = O + s D are affine in (x_w, y_w):

    O = U_O (x_w, y_w, 1),   D = U_D (x_w, y_w, 1)     (U_O, U_D: 3 x 3, columns a, b, c)

- perspective: O = 0 (the eye), D the point of the pixel's ray at view depth 1 (z_eye = -1);
- parallel: D = the unit view direction, O the pixel's point on the plane through the eye
  perpendicular to the view axis (z_eye = 0).

Either way D's component along the unit view direction is 1, so s is the view depth -z_eye of
P = O + s D: the rasteriser's clip volume in depth is near < s < far.
"""

from __future__ import annotations

import numpy as np

# name -> GLSL type
CAMERA_RAY_UNIFORMS = {
    "u_ray_origin": "mat3",          # U_O: O = U_O (x_w, y_w, 1)
    "u_ray_direction": "mat3",       # U_D: D = U_D (x_w, y_w, 1)
}


def is_perspective(projection: np.ndarray) -> bool:
    """A projection's bottom row: (0, 0, -1, 0) for perspective, (0, 0, 0, 1) for parallel
    (a jitter leaves it alone)."""
    row = np.asarray(projection, dtype=np.float64)[3]
    if np.array_equal(row, [0, 0, -1, 0]):
        return True
    if np.array_equal(row, [0, 0, 0, 1]):
        return False
    raise ValueError(f"not a perspective or parallel projection: bottom row {row.tolist()}")


def camera_ray_uniforms(view, projection, width: int, height: int) -> dict[str, np.ndarray]:
    """{"u_ray_origin": U_O, "u_ray_direction": U_D}, (3, 3) float64 each, for an image of
    width x height pixels from the camera-relative `view` (a rotation) and `projection` (as
    `Scene.matrices(...)` gives them, jittered or not)."""
    view = np.asarray(view, dtype=np.float64)
    projection = np.asarray(projection, dtype=np.float64)
    inverse = np.linalg.inv(projection @ view)
    # The homogeneous point of NDC (2 x_w / W - 1, 2 y_w / H - 1, z_ndc = 0, 1), affine in (x_w, y_w):
    # h = a x_w + b y_w + c.
    a = inverse[:, 0] * (2.0 / width)
    b = inverse[:, 1] * (2.0 / height)
    c = inverse[:, 3] - inverse[:, 0] - inverse[:, 1]
    forward = -view[2, :3]                                  # the unit view direction, world
    columns = np.stack([a, b, c], axis=1)                   # (4, 3)
    if is_perspective(projection):
        # the points h.xyz / h.w lie on a plane of constant view depth (h.w and forward . h.xyz do
        # not vary with x_w, y_w); scaled to view depth 1: D = h.xyz / (forward . h.xyz)
        depth = forward @ c[:3]
        direction = columns[:3] / depth
        origin = np.zeros((3, 3))
    else:
        # h.w = 1; the point moved along the view axis onto the plane through the eye
        to_plane = np.eye(3) - np.outer(forward, forward)
        origin = to_plane @ (columns[:3] / c[3])
        direction = np.zeros((3, 3))
        direction[:, 2] = forward
    return {"u_ray_origin": origin, "u_ray_direction": direction}


# -- the thin lens (docs/conventions.md, "Depth of field") ---------------------------------------

# name -> GLSL type
LENS_UNIFORMS = {
    "u_lens_right": "vec3",          # a * the camera's unit right vector (camera-relative world)
    "u_lens_up": "vec3",             # a * its unit up vector
    "u_inverse_focus": "float",      # 1 / f, f the view depth in focus
}


def lens_uniforms(view, aperture: float, focus: float) -> dict[str, np.ndarray]:
    """{"u_lens_right", "u_lens_up", "u_inverse_focus"} in float64 for a lens of radius
    `aperture` focused at view depth `focus`, from the camera-relative `view` (a rotation: its
    rows 0 and 1 are the unit right and up vectors in world coordinates). The lens point
    l in the unit disc moves a camera ray P = O + s D to O' = O + offset, D' = D - offset / f,
    offset = l.x u_lens_right + l.y u_lens_up: across the view axis, so D' keeps D's
    component 1 along it (s stays the view depth), and O' + f D' = O + f D (the focus plane's
    point is the pinhole ray's). Aperture 0 gives zero vectors: O', D' = O, D exactly."""
    view = np.asarray(view, dtype=np.float64)
    return {"u_lens_right": float(aperture) * view[0, :3],
            "u_lens_up": float(aperture) * view[1, :3],
            "u_inverse_focus": np.float64(1.0 / float(focus))}
