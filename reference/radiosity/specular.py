"""# Twin: glsl/radiosity/specular.glsl

Radiosity's direct specular term (issue 33; docs/radiosity.md, "The specular term"), as the
display's fragment stage adds it: at each fragment of an element whose material has k_s, the
lighting equation's k_s term (reference/lighting.py light_contribution with k_d = 0) of each
source radiosity was lit by, with its attenuation and, for a point of an area light, its
emitter's cosine; weighed by the source's visibility: 1 where the pixel of the source's light
buffer under the fragment (the first of its views whose frustum holds it) saw the fragment's
object's front, else 0. No lookup where the term is 0.

Inputs: fragments' camera-relative positions P (M, 3) and unit normals N (M, 3), their
elements' k_s (M, 3), n (M,) and objects (M,), the frame's SpecularDisplay
(renderer/core/radiosity.py: sources, views, surfaces), in the pipeline's dtype.
Output: (M, 3) the term, linear RGB.
"""

from __future__ import annotations

import numpy as np

from reference import glsl_builtins
from reference.lighting import MaterialUniforms, light_contribution


def normalize_or_zero(v: np.ndarray) -> np.ndarray:
    """GLSL's normalize_or_zero (glsl/lighting.glsl): normalize(v) as llvmpipe computes it, 0 for 0."""
    zero = glsl_builtins.dot(v, v) > 0
    return np.where(zero[:, None], glsl_builtins.normalize(np.where(zero[:, None], v, 1)), 0).astype(v.dtype)


def visibility(P: np.ndarray, obj: np.ndarray, display, first: int, count: int) -> np.ndarray:
    """(M,) 1 where the first of views first..first+count-1 whose frustum holds P saw `obj`'s front."""
    dtype = P.dtype
    n = display.surfaces.shape[-1]
    homogeneous = np.concatenate([P, np.ones((len(P), 1), dtype)], axis=1)
    seen = np.zeros(len(P), dtype)
    left = np.ones(len(P), bool)
    for k in range(first, first + count):
        clip = homogeneous @ display.views[k].astype(dtype).T
        inside = left & (clip[:, 3] > 0) & (np.abs(clip[:, 0]) <= clip[:, 3]) & (np.abs(clip[:, 1]) <= clip[:, 3])
        which = np.flatnonzero(inside)
        window = (clip[which, :2] / clip[which, 3:] * dtype.type(0.5) + dtype.type(0.5)) * dtype.type(n)
        at = np.clip(np.floor(window).astype(np.int64), 0, n - 1)
        surface = display.surfaces[k, n - 1 - at[:, 1], at[:, 0]]          # row 0 at the top
        seen[which] = (surface == obj[which] + 1).astype(dtype)
        left &= ~inside
    return seen


def radiosity_specular(P: np.ndarray, N: np.ndarray, ks: np.ndarray, shininess: np.ndarray, obj: np.ndarray,
                       display) -> np.ndarray:
    """(M, 3): the term at the fragments (module docstring)."""
    dtype = P.dtype
    V = normalize_or_zero(-P)                     # the eye at 0: camera-relative
    material = MaterialUniforms(np.zeros(3, dtype), np.zeros(3, dtype), ks.astype(dtype),
                                shininess.astype(dtype)[:, None])
    total = np.zeros((len(P), 3), dtype)
    first = 0
    for i, count in enumerate(display.counts):
        where = display.where[i].astype(dtype)
        scale = np.ones((len(P), 1), dtype)
        if where[3] > 0:
            to_light = where[:3] - P
            d = glsl_builtins.length(to_light)[:, None]
            L = np.where(d > 0, to_light / np.where(d > 0, d, 1), N)
            c, l, q = display.attenuation[i].astype(dtype)
            scale = 1 / (c + l * d + q * d * d)
            emitter = display.emitter[i].astype(dtype)
            if emitter[3] > 0:
                scale = scale * (emitter[3] * np.maximum(dtype.type(0), -glsl_builtins.dot(L, emitter[:3])))[:, None]
        else:
            L = np.broadcast_to(glsl_builtins.normalize(-where[:3][None]), P.shape)
        term = light_contribution(N, L, V, scale, display.intensity[i].astype(dtype), material)
        lit = np.flatnonzero((term > 0).any(axis=1))
        if len(lit):
            total[lit] += term[lit] * visibility(P[lit], obj[lit], display, first, count)[:, None]
        first += count
    return total
