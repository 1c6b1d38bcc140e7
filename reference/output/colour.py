"""# Twin: glsl/output/colour.glsl

CIE XYZ, luminance and chromaticity of linear RGB (notes 1.2 "Colour"), in float64, with the
matrix renderer/core/colour.py derives from the sRGB primaries and D65. `colour_planes` is the
twin of the whole pass, glsl/output/colour.comp (renderer/gpu/colour.py).

Inputs:  rgb (..., 3) linear light (Frame.linear's RGB: unclamped, any float dtype).
Outputs: float64 arrays of the same leading shape: XYZ (..., 3), Y (...), x, y, z (..., 3).
"""

from __future__ import annotations

import numpy as np

from renderer.core.colour import D65_CHROMATICITY, LUMINANCE_WEIGHTS, RGB_TO_XYZ, XYZ_TO_RGB


def rgb_to_xyz(rgb) -> np.ndarray:
    return np.asarray(rgb, dtype=np.float64) @ RGB_TO_XYZ.T


def xyz_to_rgb(xyz) -> np.ndarray:
    return np.asarray(xyz, dtype=np.float64) @ XYZ_TO_RGB.T


def luminance(rgb) -> np.ndarray:
    """CIE Y: the weights 0.2126, 0.7152, 0.0722 (to four places) of R, G, B."""
    return np.asarray(rgb, dtype=np.float64) @ LUMINANCE_WEIGHTS


def chromaticity(xyz) -> np.ndarray:
    """x, y, z = X, Y, Z / (X + Y + Z) (x + y + z = 1); where there is no light (a sum <= 0:
    black, or a non-physical negative colour) the white point's, D65 (colour-science's
    XYZ_to_xy gives (0, 0) there)."""
    xyz = np.asarray(xyz, dtype=np.float64)
    total = xyz.sum(axis=-1, keepdims=True)
    lit = total > 0.0
    with np.errstate(divide="ignore", invalid="ignore"):
        return np.where(lit, xyz / np.where(lit, total, 1.0), D65_CHROMATICITY)


def colour_planes(linear) -> tuple[np.ndarray, np.ndarray]:
    """The pass on a frame's linear colour (H, W, 4): (XYZ with alpha (H, W, 4), chromaticity
    x, y, z (H, W, 3)), float64, row 0 at the top as given."""
    linear = np.asarray(linear)
    xyz = rgb_to_xyz(linear[..., :3])
    return np.concatenate([xyz, linear[..., 3:4].astype(np.float64)], axis=-1), chromaticity(xyz)
