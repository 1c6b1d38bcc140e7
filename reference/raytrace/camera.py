"""# Twin: glsl/raytrace/camera.glsl

The camera's primary rays (docs/conventions.md, "Rays"), vectorised over window points: the ray
P = O + s D through the window point (x_w, y_w) (GL window coordinates, row 0 at the bottom;
pixel (i, j) with sample offset (dx, dy) is (i + 0.5 + dx, j + 0.5 + dy)), with O and D affine
in the window point, their coefficients the uniforms of renderer/core/camera_rays.py.

Inputs:  window (..., 2) window points; uniforms as camera_ray_uniforms returns them.
Output:  (O, D), (..., 3) each, in the dtype of `window` (float64 for integer input), as the
         GLSL's mat3 * vec3: each component the sum a x_w + b y_w + c in that order.

The thin lens (docs/conventions.md, "Depth of field"): `thin_lens_ray` moves a camera ray's
origin to its lens point and turns it through the same point of the focus plane, with the
uniforms of renderer/core/camera_rays.py's lens_uniforms, in the GLSL's order.
"""

from __future__ import annotations

import numpy as np

from reference.raytrace.sampling import distributed_2d
from reference.raytrace.warp import square_to_disc
from renderer.core.ray_sampling import LENS_DIMENSION


def pixel_windows(width: int, height: int, sample_offset=(0.0, 0.0), dtype=np.float64) -> np.ndarray:
    """(height, width, 2) window points (i + 0.5 + dx, j + 0.5 + dy) of every pixel, row j = 0
    (the bottom row, as GL) first."""
    i = np.arange(width, dtype=np.float64) + 0.5 + sample_offset[0]
    j = np.arange(height, dtype=np.float64) + 0.5 + sample_offset[1]
    x, y = np.meshgrid(i, j)
    return np.stack([x, y], axis=-1).astype(dtype)


def camera_ray(window, uniforms):
    """(O, D) of the rays through `window` points (..., 2)."""
    window = np.asarray(window)
    dtype = window.dtype if window.dtype.kind == "f" else np.dtype(np.float64)
    window = window.astype(dtype)
    x, y = window[..., 0:1], window[..., 1:2]

    def affine(matrix):
        m = np.asarray(matrix, dtype=dtype)
        return x * m[:, 0] + y * m[:, 1] + m[:, 2]

    return affine(uniforms["u_ray_origin"]), affine(uniforms["u_ray_direction"])


def thin_lens_ray(lens, O, D, uniforms):
    """(O', D') of the rays (O, D) (..., 3) through the lens points `lens` (..., 2) of the unit
    disc: offset = l.x u_lens_right + l.y u_lens_up, O' = O + offset, D' = D - offset
    u_inverse_focus, in the dtype of O."""
    dtype = np.asarray(O).dtype
    lens = np.asarray(lens).astype(dtype)
    right, up = (np.asarray(uniforms[name], dtype) for name in ("u_lens_right", "u_lens_up"))
    offset = lens[..., 0:1] * right + lens[..., 1:2] * up
    return O + offset, D - offset * dtype.type(uniforms["u_inverse_focus"])


def lens_point(x, y, k: int, first_sample: int, sampling, dtype=np.float32) -> np.ndarray:
    """(..., 2) the lens point in the unit disc of samples k at pixels (x, y) (broadcast): the
    concentric map of the sampling layer's point of LENS_DIMENSION at slot 0 (the camera's),
    in `dtype`."""
    u = distributed_2d(x, y, k, first_sample, sampling, 0, LENS_DIMENSION)
    return square_to_disc(np.asarray(u).astype(dtype))
