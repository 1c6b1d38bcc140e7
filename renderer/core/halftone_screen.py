"""The half-tone screens' geometry, written once for both twins (glsl/output/halftone.glsl,
reference/output/halftone.py): each ink's screen is a grid of square cells `cell` pixels wide
turned by its angle, given to the shaders as two float32 numbers per ink.

A pixel centre (px, py) (x = column + 0.5, y = image row from the top + 0.5) has cell
coordinates u = px cs + py sn, v = py cs - px sn, with cs = cos(a) / cell and sn = sin(a) / cell:
the screen's axes turned by a, in cells. cs and sn are computed here in float64 and rounded to
float32 once, so that both twins multiply by the very same numbers (no trigonometry on the GPU).
"""

from __future__ import annotations

import math

import numpy as np

from renderer.core.output_settings import INK_ANGLES, Halftone

INKS = ("c", "m", "y", "k")        # the order of the rows of `screen_basis` (and of the GLSL's)


def screen_basis(halftone: Halftone) -> np.ndarray:
    """(4, 2) float32: per ink of INKS, (cs, sn) = (cos(a) / cell, sin(a) / cell) with
    a = halftone.angle + INK_ANGLES[ink] degrees."""
    basis = np.empty((len(INKS), 2), dtype=np.float32)
    for row, ink in enumerate(INKS):
        angle = math.radians(halftone.angle + INK_ANGLES[ink])
        basis[row] = (math.cos(angle) / halftone.cell, math.sin(angle) / halftone.cell)
    return basis
