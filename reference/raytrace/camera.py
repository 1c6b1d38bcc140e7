"""# Twin: glsl/raytrace/camera.glsl

The camera's primary rays (docs/conventions.md, "Rays"), vectorised over window points: the ray
P = O + s D through the window point (x_w, y_w) (GL window coordinates, row 0 at the bottom;
pixel (i, j) with sample offset (dx, dy) is (i + 0.5 + dx, j + 0.5 + dy)), with O and D affine
in the window point, their coefficients the uniforms of renderer/core/camera_rays.py.

Inputs:  window (..., 2) window points; uniforms as camera_ray_uniforms returns them.
Output:  (O, D), (..., 3) each, in the dtype of `window` (float64 for integer input), as the
         GLSL's mat3 * vec3: each component the sum a x_w + b y_w + c in that order.
"""

from __future__ import annotations

import numpy as np


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
