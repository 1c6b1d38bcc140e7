"""The matrices of the notes (section 3.2), the camera and the projections.

Column vectors, `p' = M p`; every matrix is a (4, 4) float64 array indexed [row, column]
as printed in the notes. Angles are radians here (scene files use degrees).
docs/conventions.md states how these map onto GLSL and pyrr.
"""

from __future__ import annotations

import math

import numpy as np


def identity() -> np.ndarray:
    return np.eye(4)


def scale(mx: float, my: float, mz: float) -> np.ndarray:
    """Scale about the origin by m_x, m_y, m_z (notes: Scale)."""
    return np.diag([mx, my, mz, 1.0])


def translate(x0: float, y0: float, z0: float) -> np.ndarray:
    """Translate by (x0, y0, z0) (notes: Translation)."""
    m = np.eye(4)
    m[:3, 3] = (x0, y0, z0)
    return m


def rotate_x(theta: float) -> np.ndarray:
    """Rotation about the x axis, the notes' matrix."""
    c, s = math.cos(theta), math.sin(theta)
    return np.array([[1, 0, 0, 0], [0, c, -s, 0], [0, s, c, 0], [0, 0, 0, 1]], dtype=float)


def rotate_y(theta: float) -> np.ndarray:
    """Rotation about the y axis, the notes' matrix exactly (a positive angle turns +x towards +z)."""
    c, s = math.cos(theta), math.sin(theta)
    return np.array([[c, 0, -s, 0], [0, 1, 0, 0], [s, 0, c, 0], [0, 0, 0, 1]], dtype=float)


def rotate_z(theta: float) -> np.ndarray:
    """Rotation about the z axis, the notes' matrix."""
    c, s = math.cos(theta), math.sin(theta)
    return np.array([[c, -s, 0, 0], [s, c, 0, 0], [0, 0, 1, 0], [0, 0, 0, 1]], dtype=float)


SHEAR_FACTORS = ("xy", "xz", "yx", "yz", "zx", "zy")


def shear(xy: float = 0.0, xz: float = 0.0, yx: float = 0.0,
          yz: float = 0.0, zx: float = 0.0, zy: float = 0.0) -> np.ndarray:
    """Shear; factor `ab` adds `factor * b` to `a` (the notes' x-shear is `shear(xy=a)`)."""
    m = np.eye(4)
    axis = {"x": 0, "y": 1, "z": 2}
    for name, value in zip(SHEAR_FACTORS, (xy, xz, yx, yz, zx, zy)):
        m[axis[name[0]], axis[name[1]]] = value
    return m


def model_matrix(scale_xyz=(1.0, 1.0, 1.0), shear_factors=None,
                 rotate_xyz=(0.0, 0.0, 0.0), translate_xyz=(0.0, 0.0, 0.0)) -> np.ndarray:
    """The notes' order: scale, (shear,) rotate about x, y, z, then translate.

    M = T · Rz · Ry · Rx · H · S, so S acts on the point first. `rotate_xyz` is radians.
    """
    rx, ry, rz = rotate_xyz
    return (translate(*translate_xyz) @ rotate_z(rz) @ rotate_y(ry) @ rotate_x(rx)
            @ shear(**(shear_factors or {})) @ scale(*scale_xyz))


def normal_matrix(model: np.ndarray) -> np.ndarray:
    """(3, 3) inverse-transpose of the model matrix's linear part: normals stay perpendicular
    to surfaces under non-uniform scale and shear."""
    return np.linalg.inv(model[:3, :3]).T


def look_at(eye, look, up) -> np.ndarray:
    """View matrix: eye to the origin, look - eye to -z, up (made perpendicular) to +y.

    The notes' camera steps (translate eye to origin, align el with the z axis, align up
    with +y) with GL's choice of looking down -z. The caller checks that up is not parallel
    to the view direction (renderer/scene.py validates cameras).
    """
    eye, look, up = (np.asarray(v, dtype=float) for v in (eye, look, up))
    forward = look - eye
    forward = forward / np.linalg.norm(forward)
    right = np.cross(forward, up)
    right = right / np.linalg.norm(right)
    true_up = np.cross(right, forward)
    rotation = np.eye(4)
    rotation[0, :3] = right
    rotation[1, :3] = true_up
    rotation[2, :3] = -forward
    return rotation @ translate(*(-eye))


def perspective(fov_y: float, aspect: float, near: float, far: float) -> np.ndarray:
    """GL's perspective projection (gluPerspective); fov_y is the full vertical angle in radians.

    The notes' projection matrix maps (x, y, z) to (x d/z, y d/z); this is the same divide by
    depth, with GL's -z viewing axis and depth mapped to [-1, 1] between near and far.
    """
    f = 1.0 / math.tan(fov_y / 2.0)
    return np.array([
        [f / aspect, 0, 0, 0],
        [0, f, 0, 0],
        [0, 0, (far + near) / (near - far), 2 * far * near / (near - far)],
        [0, 0, -1, 0],
    ], dtype=float)


def orthographic(height: float, aspect: float, near: float, far: float) -> np.ndarray:
    """GL's parallel projection (glOrtho) of a view volume `height` tall, `height*aspect` wide."""
    half_h = height / 2.0
    half_w = half_h * aspect
    return np.array([
        [1 / half_w, 0, 0, 0],
        [0, 1 / half_h, 0, 0],
        [0, 0, -2 / (far - near), -(far + near) / (far - near)],
        [0, 0, 0, 1],
    ], dtype=float)


def jitter(dx: float, dy: float, width: int, height: int) -> np.ndarray:
    """The projection jitter J for a sample offset (dx, dy) pixels from the pixel centre, in
    GL window coordinates (x right, y up): J P samples pixel (i, j) at (i + 0.5 + dx,
    j + 0.5 + dy) of the image P gives. J is the clip-space translation
    x -= (2 dx / W) w, y -= (2 dy / H) w, i.e. the image moves by (-dx, -dy) pixels
    (docs/conventions.md, "Sample positions")."""
    m = np.eye(4)
    m[0, 3] = -2.0 * dx / width
    m[1, 3] = -2.0 * dy / height
    return m


def to_glsl(m: np.ndarray) -> bytes:
    """Bytes for a GLSL matN uniform (column-major float32), so GLSL `M * v` equals `M @ v`."""
    return np.ascontiguousarray(np.asarray(m, dtype=np.float64).T, dtype=np.float32).tobytes()
