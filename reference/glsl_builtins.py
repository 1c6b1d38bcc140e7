"""GLSL's vector built-ins as llvmpipe computes them, for the twins that mirror a shader's
arithmetic (the ray tracer's, the path tracer's, the lighting equation's). Probed bit for bit on
EGL and OSMesa (tests/test_glsl_builtins.py, tests/glsl/builtins.frag):

- dot(a, b): the three products summed z first, (z + y) + x: NIR scalarises the reduction from
  its last component. Summed x first, a third of the results are an ulp or so off;
- normalize(v): v times the reciprocal of sqrt(dot(v, v)), each correctly rounded; v / sqrt(...)
  is a quarter of the time an ulp off;
- length(v): sqrt(dot(v, v));
- cross(a, b): each component a product less a product, no fused multiply-add (llvmpipe fuses
  none: its NIR options lower ffma to a multiply and an add);
- matrix_times(m, v), GLSL's m * v: column by column, ((c0 x + c1 y) + c2 z) + c3 w, each
  product and sum rounded in turn (as reference/radiosity/item_buffer.py measured for M * p).

In float64 (the twins' ground truth) the same formulas in float64. A result of the GPU's that
differs from its twin's by an ulp decides the same way except at a boundary (a ray through a
triangle's edge, a corner where two walls meet), where one path may go one way and the other
the other; these keep the twins on the same side.
"""

from __future__ import annotations

import numpy as np


def dot(a, b):
    """GLSL's dot over the last axis, z first."""
    return a[..., 2] * b[..., 2] + a[..., 1] * b[..., 1] + a[..., 0] * b[..., 0]


def length(v):
    return np.sqrt(dot(v, v))


def normalize(v):
    """GLSL's normalize over the last axis: v * (1 / length(v))."""
    v = np.asarray(v)
    return v * (v.dtype.type(1) / length(v))[..., None]


def cross(a, b):
    return np.stack([a[..., 1] * b[..., 2] - a[..., 2] * b[..., 1],
                     a[..., 2] * b[..., 0] - a[..., 0] * b[..., 2],
                     a[..., 0] * b[..., 1] - a[..., 1] * b[..., 0]], axis=-1)


def matrix_times(m, v):
    """GLSL's m * v for a 4 x 4 matrix `m` (rows, numpy's layout) and vectors v (..., 4):
    ((c0 x + c1 y) + c2 z) + c3 w, c_k the matrix's columns, in v's dtype."""
    m = np.asarray(m).astype(np.asarray(v).dtype)
    return ((m[:, 0] * v[..., 0:1] + m[:, 1] * v[..., 1:2]) + m[:, 2] * v[..., 2:3]) + m[:, 3] * v[..., 3:4]
