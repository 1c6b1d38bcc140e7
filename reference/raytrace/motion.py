"""# Twin: glsl/raytrace/motion.glsl

Motion blur's rule (docs/conventions.md, "Motion blur"; the data: renderer/core/motion.py),
vectorised over rays, in the dtype of the time given (float32 as the GLSL, float64 for the
ground truth): an object moving with velocity v and angular velocity w (unit axis k, rate |w|
radians per unit time, about the axis through its centre c) has at time t each point X at

    X(t) = X + (R(t |w|) - I)(X - c) + t v,   (R(a) - I) x = sin(a) k x x + (1 - cos a) k x (k x x)

in this displacement form so that t = 0 is exact (every term is 0, and X + 0 is X). The inverse,
into the object's time-0 frame: Y - t v + (R(-t |w|) - I)(Y - t v - c), sin negated. The GLSL's
order of operations; its sin and cos agree with NumPy's within a few ulps, so moved points agree
within rounding, not bit for bit (at t = 0 both are exact).
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from reference.glsl_builtins import cross as _cross, dot as _dot


@dataclass(frozen=True)
class Motion:
    """One object's motion at each ray's time (motion_at): arrays (..., 3) or (...,)."""
    centre: np.ndarray
    shift: np.ndarray            # t v
    axis: np.ndarray
    sine: np.ndarray             # sin(t |w|)
    versine: np.ndarray          # 1 - cos(t |w|)


def motion_time(shutter, u):
    """The time of camera samples whose TIME numbers are u: open + u (close - open), in u's
    dtype (shutter [0, 0]: 0 exactly)."""
    u = np.asarray(u)
    t = u.dtype.type
    open_, close = t(shutter[0]), t(shutter[1])
    return open_ + u * (close - open_)


def motion_at(rows, time) -> Motion:
    """The motion at times `time` (...,) of an object whose rows (3, 4) are (c, rate), (v, 0),
    (axis, 0) (renderer/core/motion.py, SceneMotion.rows), in the dtype of `time`."""
    time = np.asarray(time)
    t = time.dtype.type
    rows = np.asarray(rows).astype(t)
    angle = time * rows[0, 3]
    return Motion(rows[0, :3], time[..., None] * rows[1, :3], rows[2, :3], np.sin(angle)[..., None],
                  t(1) - np.cos(angle)[..., None])


def motion_turn(m: Motion, sine, x):
    """(R - I) x for the rotation whose sine is `sine` (m.sine forwards, -m.sine backwards)."""
    kx = _cross(np.broadcast_to(m.axis, np.shape(x)), x)
    return sine * kx + m.versine * _cross(np.broadcast_to(m.axis, kx.shape), kx)


def motion_point(m: Motion, X):
    """Points of the object at time 0 where they are at the motion's time."""
    return X + motion_turn(m, m.sine, X - m.centre) + m.shift


def motion_point_back(m: Motion, Y):
    """Points at the motion's time where they were at time 0 (motion_point's inverse)."""
    Y0 = Y - m.shift
    return Y0 + motion_turn(m, -m.sine, Y0 - m.centre)


def motion_direction(m: Motion, D):
    """Directions (normals) of the object turned with it."""
    return D + motion_turn(m, m.sine, D)


def motion_direction_back(m: Motion, D):
    return D + motion_turn(m, -m.sine, D)


def motion_plane(m: Motion, N, d):
    """(N_t, d_t): the plane P.N + d = 0 of the object at the motion's time, N_t = R N and
    d_t = d - N_t.(t v) - ((R - I) N).c (d where t = 0)."""
    turned = motion_turn(m, m.sine, np.broadcast_to(N, np.shape(m.shift)))
    N_t = N + turned
    return N_t, d - _dot(N_t, m.shift) - _dot(turned, np.broadcast_to(m.centre, turned.shape))
