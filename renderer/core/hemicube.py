"""The hemicube (Cohen and Greenberg, "The Hemi-Cube: A Radiosity Solution for Complex
Environments", SIGGRAPH 1985): how a patch's form factors to every other element are read off
five rasterised images, and the delta form factor each pixel of them weighs (issue 33). One
definition for the GPU path and its twin; both draw the same item buffers and weigh them with
these tables.

The frame: the element's centre at the origin, its unit normal n = +z, tangents u = +x and
v = +y. The unit hemicube has its top face on z = 1 over [-1, 1]² and four side faces on
x = ±1 and y = ±1 over z in [0, 1]. At a resolution of N pixels (N even) across a face, the
top face is N × N pixels of side 2/N and each side face the upper half of one, N / 2 rows of N.

Each face is an image as a camera at the origin sees it looking along the face's `forward`
with `up` at the top (FACES), row 0 at the top as in every array the project hands out, and a
pixel's centre on the face at half-integer steps. The delta form factor of a pixel of area ΔA
centred at (x, y, 1) on the top face, and at (1, y, z) on a side face (and so by symmetry on the
others), is the fraction of the element's energy leaving through it (a point on the element
seeing the pixel):

    top:   ΔF = ΔA / (π (x² + y² + 1)²)
    side:  ΔF = z ΔA / (π (y² + z² + 1)²)

They sum to 1 up to the midpoint rule's error, which falls as 1/N²
(tests/test_hemicube.py). A form factor F_ij is the sum of the ΔF of the pixels through which
element j is seen, element i's hemicube placed at its centre.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np


@dataclass(frozen=True)
class Face:
    name: str
    forward: tuple[float, float, float]         # in the element's frame (u, v, n)
    up: tuple[float, float, float]


# The five faces in the order the item buffers are drawn: the top, then the sides around it.
FACES = (Face("top", (0, 0, 1), (0, 1, 0)),
         Face("+u", (1, 0, 0), (0, 0, 1)),
         Face("+v", (0, 1, 0), (0, 0, 1)),
         Face("-u", (-1, 0, 0), (0, 0, 1)),
         Face("-v", (0, -1, 0), (0, 0, 1)))


def _check(resolution: int) -> int:
    if resolution < 2 or resolution % 2:
        raise ValueError(f"a hemicube's resolution must be an even number of at least 2, got {resolution}")
    return int(resolution)


def face_shape(face: Face, resolution: int) -> tuple[int, int]:
    """(rows, columns) of a face's image: N × N on top, the upper half N / 2 × N on a side."""
    n = _check(resolution)
    return (n, n) if face.name == "top" else (n // 2, n)


def pixel_centres(face: Face, resolution: int) -> np.ndarray:
    """(rows, columns, 3): each pixel's centre on the unit hemicube, in the element's frame,
    row 0 at the top of the face's image (towards `up`), column 0 at its left."""
    n = _check(resolution)
    rows, cols = face_shape(face, n)
    forward, up = np.array(face.forward, float), np.array(face.up, float)
    right = np.cross(forward, up)                   # a camera looking along forward, up at the top
    across = -1 + (2 * np.arange(cols) + 1) / n     # left to right
    down = 1 - (2 * np.arange(rows) + 1) / n        # top to bottom (a side face: z from 1 to 0)
    return (forward + across[None, :, None] * right + down[:, None, None] * up).astype(float)


def delta_form_factors(face: Face, resolution: int) -> np.ndarray:
    """(rows, columns): each pixel's delta form factor (module docstring), float64."""
    p = pixel_centres(face, resolution)
    area = (2.0 / resolution) ** 2
    r2 = (p * p).sum(-1)                            # x² + y² + 1 on top, 1 + y² + z² on a side
    return p[..., 2] * area / (np.pi * r2 * r2)     # cos at the element (z / r) × cos at the
                                                    # pixel (1 / r) / (π r²): z / (π r⁴)
