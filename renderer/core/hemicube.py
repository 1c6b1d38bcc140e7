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

from renderer.core.gl_rules import REVERSED_Z_DEPTH
from renderer.core.transforms import perspective


# An item buffer's pixel: 0 where nothing is seen, else the element's index + 1, with this bit
# set where the hemicube sees the element's back (glsl/radiosity/item_buffer.frag).
ITEM_BACK_SHIFT = 31
ITEM_BACK_BIT = 1 << ITEM_BACK_SHIFT
ITEM_INDEX_MASK = ITEM_BACK_BIT - 1


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


def pixel_centres(face: Face, resolution: int, rows: int | None = None) -> np.ndarray:
    """(rows, columns, 3): each pixel's centre on the unit hemicube, in the element's frame,
    row 0 at the top of the face's image (towards `up`), column 0 at its left; `rows` N for the
    whole face (a light's cube, renderer/core/light_buffers.py), else face_shape's."""
    n = _check(resolution)
    rows, cols = face_shape(face, n) if rows is None else (rows, n)
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


def weights(resolution: int) -> np.ndarray:
    """(5, N, N) float64: the delta form factors of the five faces in FACES' order, each drawn
    as a full N x N image (a side face's image is the whole 90-degree view; its upper N / 2 rows
    are the face, the lower half, below the element's plane, weighs 0), scaled so that the
    whole hemicube sums to exactly 1. The scale (1 / (1 + ~0.542 / N^2)) is within the
    midpoint rule's own error; it makes a closed room's rows of form factors sum to 1, so that
    energy is conserved exactly and a white furnace gives E / (1 - rho) to rounding."""
    n = _check(resolution)
    table = np.zeros((len(FACES), n, n))
    for k, face in enumerate(FACES):
        rows, _ = face_shape(face, n)
        table[k, :rows] = delta_form_factors(face, n)
    return table / table.sum()


def face_views(frames: np.ndarray, centres: np.ndarray, origin=(0.0, 0.0, 0.0), faces=FACES) -> np.ndarray:
    """(E, F, 4, 4) float64: for each element (its frame's rows u, v, n in world coordinates and
    its centre) the view matrix of each face of `faces` (FACES): the camera at the centre looking along
    the face's forward with its up at the top (transforms.look_at's convention: forward to -z,
    up to +y), of points given relative to `origin` (as the GPU's float32 positions are)."""
    frames = np.asarray(frames, np.float64)
    forward = np.array([f.forward for f in faces], np.float64) @ frames          # (E, F, 3)
    up = np.array([f.up for f in faces], np.float64) @ frames
    right = np.cross(forward, up)
    rotation = np.stack([right, up, -forward], axis=-2)                          # (E, 5, 3, 3)
    eye = np.asarray(centres, np.float64) - np.asarray(origin, np.float64)
    views = np.zeros(rotation.shape[:2] + (4, 4))
    views[..., :3, :3] = rotation
    views[..., :3, 3] = -np.einsum("efij,ej->efi", rotation, eye)
    views[..., 3, 3] = 1.0
    return views


def projection(near: float, far: float) -> np.ndarray:
    """(4, 4): every face's projection, a 90-degree square frustum (transforms.perspective):
    the face's N x N image spans [-1, 1]^2 at distance 1. Depth is reversed-Z (DEPTH_MAPPING),
    whose float32 window depth keeps about 1e-7 of relative precision at every distance, so
    that `near` can be a small fraction of the smallest element (`depth_range`)."""
    return perspective(np.pi / 2, 1.0, near, far, reversed_z=True)


DEPTH_MAPPING = REVERSED_Z_DEPTH
# The near plane as a fraction of the shortest element edge: what lies nearer the hemicube's
# centre than that is not seen (a neighbour's sliver, about this fraction of its form factor).
NEAR_FRACTION = 1e-3


def depth_range(shortest_edge: float, diameter: float) -> tuple[float, float]:
    """(near, far) of every hemicube of elements whose shortest edge and whose bounding box's
    diagonal are given: near NEAR_FRACTION of that edge, far beyond every element."""
    return NEAR_FRACTION * shortest_edge, 2.0 * diameter + shortest_edge


def clip_from_world(frames, centres, origin, near: float, far: float) -> np.ndarray:
    """(E, 5, 4, 4) float64: projection @ face_views, each face's matrix from positions
    relative to `origin` to its clip coordinates."""
    return projection(near, far) @ face_views(frames, centres, origin)
