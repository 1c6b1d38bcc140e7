"""CIE colour of the renderer's linear RGB (notes 1.2 "Colour"): the sRGB primaries and white
point, the matrix from linear RGB to CIE XYZ that they define, and the luminance weights.

Linear RGB here is the frame's linear colour (Frame.linear): light in sRGB's primaries, before
any transfer curve. XYZ is CIE 1931 (2-degree observer) tristimulus, scaled so that RGB white
(1, 1, 1) has Y = 1 and the chromaticity of D65.

The matrix is DERIVED, in float64, from the primaries' and the white point's chromaticities
(SMPTE RP 177's normalised primary matrix): IEC 61966-2-1 prints it rounded to four places
(0.4124, 0.3576, 0.1805 / 0.2126, 0.7152, 0.0722 / 0.0193, 0.1192, 0.9505), and that rounded
matrix is colour-science's default for sRGB; ours differs from it by up to 5e-5 and is what
colour-science's own `normalised_primary_matrix` gives (tests/test_colour.py). Its middle row is
the luminance weights, Rec. 709's 0.2126, 0.7152, 0.0722 to four places.

Both twins read these: reference/output/colour.py (float64) and glsl/output/colour.glsl (the
matrix as a float32 uniform, through renderer/gpu/colour.py).
"""

from __future__ import annotations

import numpy as np

# ITU-R BT.709 / IEC 61966-2-1 primaries (red, green, blue) and the D65 white point, CIE xy.
SRGB_PRIMARIES_XY = ((0.64, 0.33), (0.30, 0.60), (0.15, 0.06))
D65_XY = (0.3127, 0.3290)


def xy_to_xyz_direction(xy) -> np.ndarray:
    """(..., 2) chromaticity -> (..., 3) XYZ with Y = 1: (x / y, 1, (1 - x - y) / y)."""
    xy = np.asarray(xy, dtype=np.float64)
    x, y = xy[..., 0], xy[..., 1]
    return np.stack([x / y, np.ones_like(x), (1.0 - x - y) / y], axis=-1)


def normalised_primary_matrix(primaries_xy, white_xy) -> np.ndarray:
    """(3, 3) float64 M with XYZ = M @ rgb: column i is primary i's XYZ, each scaled so that
    the three add up to the white point's XYZ at Y = 1 (SMPTE RP 177, section 3.3)."""
    primaries = np.array([(x, y, 1.0 - x - y) for x, y in primaries_xy], dtype=np.float64).T
    white = xy_to_xyz_direction(white_xy)
    return primaries * np.linalg.solve(primaries, white)   # columns scaled by the solution


def _read_only(array: np.ndarray) -> np.ndarray:
    array.flags.writeable = False
    return array


RGB_TO_XYZ = _read_only(normalised_primary_matrix(SRGB_PRIMARIES_XY, D65_XY))
XYZ_TO_RGB = _read_only(np.linalg.inv(RGB_TO_XYZ))
LUMINANCE_WEIGHTS = RGB_TO_XYZ[1]             # Y of each primary: 0.2126, 0.7152, 0.0722
D65_CHROMATICITY = _read_only(np.array([*D65_XY, 1.0 - sum(D65_XY)]))   # x, y, z of white
