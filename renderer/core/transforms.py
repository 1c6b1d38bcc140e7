"""The matrices of the notes (section 3.2), the camera and the projections.

Column vectors, `p' = M p`; every matrix is a (4, 4) float64 array indexed [row, column]
as printed in the notes. Angles are radians here (scene files use degrees).
docs/conventions.md states how these map onto GLSL and pyrr.
"""

from __future__ import annotations

import math

import numpy as np

from renderer.core import gl_rules


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
    """(3, 3) normal matrix of the model matrix's linear part A: sign(det A) times the
    cofactor matrix of A, scaled to the Frobenius norm of a rotation (sqrt 3).

    The cofactor matrix equals det(A) A^-T, so where A is invertible this is A^-T up to a
    positive factor (a rotation's is the rotation itself; normals are renormalised after it,
    only directions matter), and unlike A^-T it is defined for a singular A (a zero scale):
    a normal then keeps only its component across the flattened axis. The scaling, in
    float64, keeps extreme non-uniform scales (1000 : 0.001) well inside float32 range.
    A matrix of rank 1 or 0 (two axes flattened: nothing with area is drawn) gives zero.
    """
    a = np.asarray(model, dtype=np.float64)[:3, :3]
    cofactor = np.cross(a[[1, 2, 0]], a[[2, 0, 1]])    # row i: a_j x a_k of A's rows, i j k cyclic
    det = float(np.dot(a[0], cofactor[0]))
    norm = np.linalg.norm(cofactor)
    if norm == 0:
        return cofactor
    return cofactor * ((-1.0 if det < 0 else 1.0) * math.sqrt(3.0) / norm)


# |forward x up| below this (unit vectors: the sine of the angle between them) means up is
# parallel to the view direction, and look_at falls back to another up vector.
PARALLEL_TOLERANCE = 1e-6


def fallback_up(forward: np.ndarray) -> np.ndarray:
    """The up vector used when the given one is parallel to the view direction: the world
    axis least aligned with `forward` (on a tie the later one: z before y before x)."""
    alignment = np.abs(forward)
    axis = 2 - int(np.argmin(alignment[::-1]))
    return np.eye(3)[axis]


def look_at_rotation(eye, look, up) -> np.ndarray:
    """The rotation part of the view matrix: look - eye to -z, up (made perpendicular) to +y.

    When up is zero or parallel to the view direction, `fallback_up(forward)` is used instead,
    so that every camera with eye != look has a view (docs/conventions.md, "Camera").
    """
    eye, look, up = (np.asarray(v, dtype=float) for v in (eye, look, up))
    forward = look - eye
    forward = forward / np.linalg.norm(forward)
    up_length = np.linalg.norm(up)
    right = np.cross(forward, up / up_length) if up_length > 0 else np.zeros(3)
    if np.linalg.norm(right) < PARALLEL_TOLERANCE:
        right = np.cross(forward, fallback_up(forward))
    right = right / np.linalg.norm(right)
    true_up = np.cross(right, forward)
    rotation = np.eye(4)
    rotation[0, :3] = right
    rotation[1, :3] = true_up
    rotation[2, :3] = -forward
    return rotation


def look_at(eye, look, up) -> np.ndarray:
    """View matrix: eye to the origin, look - eye to -z, up (made perpendicular) to +y.

    The notes' camera steps (translate eye to origin, align el with the z axis, align up
    with +y) with GL's choice of looking down -z. Up parallel to the view direction falls
    back to `fallback_up` (see look_at_rotation).
    """
    return look_at_rotation(eye, look, up) @ translate(*(-np.asarray(eye, dtype=float)))


def depth_row(near: float, far: float, *, perspective: bool, reversed_z: bool) -> np.ndarray:
    """Row 2 of a projection matrix (z_clip from the eye-space point): the near plane to
    z_ndc = a_n and the far plane to a_f, the depth mapping's (core/gl_rules.py: -1 and 1 for
    GL's default, 1 and 0 for reversed-Z, where a float32 depth buffer keeps about 1e-7
    relative precision at every distance). With perspective, w_clip = -z_eye and
    z_ndc = -A - B / z_eye; with a parallel projection, w_clip = 1 and z_ndc = A z_eye + B.
    Solving for z_eye = -near and -far gives (A, B) below.
    """
    mapping = gl_rules.depth_mapping(reversed_z)
    n, f = float(near), float(far)
    a_n, a_f = mapping.ndc_near, mapping.ndc_far
    if perspective:
        return np.array([0.0, 0.0, (a_n * n - a_f * f) / (f - n), (a_n - a_f) * n * f / (f - n)])
    return np.array([0.0, 0.0, (a_n - a_f) / (f - n), (a_n * f - a_f * n) / (f - n)])


def perspective(fov_y: float, aspect: float, near: float, far: float,
                reversed_z: bool = False) -> np.ndarray:
    """GL's perspective projection (gluPerspective); fov_y is the full vertical angle in radians.

    The notes' projection matrix maps (x, y, z) to (x d/z, y d/z); this is the same divide by
    depth, with GL's -z viewing axis and depth mapped by `depth_row`.
    """
    f = 1.0 / math.tan(fov_y / 2.0)
    return np.array([
        [f / aspect, 0, 0, 0],
        [0, f, 0, 0],
        depth_row(near, far, perspective=True, reversed_z=reversed_z),
        [0, 0, -1, 0],
    ], dtype=float)


def orthographic(height: float, aspect: float, near: float, far: float,
                 reversed_z: bool = False) -> np.ndarray:
    """GL's parallel projection (glOrtho) of a view volume `height` tall, `height*aspect` wide;
    depth mapped by `depth_row`."""
    half_h = height / 2.0
    half_w = half_h * aspect
    return np.array([
        [1 / half_w, 0, 0, 0],
        [0, 1 / half_h, 0, 0],
        depth_row(near, far, perspective=False, reversed_z=reversed_z),
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
    """Bytes for a GLSL matN uniform (column-major float32), so GLSL `M * v` equals `M @ v`;
    for an array of matrices (..., N, N) each one is transposed."""
    return np.ascontiguousarray(np.swapaxes(np.asarray(m, dtype=np.float64), -1, -2),
                                dtype=np.float32).tobytes()
