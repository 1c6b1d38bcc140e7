"""# Twin: glsl/tess_evaluation.glsl

Tessellation evaluation (notes 4.1; issue 34), as the evaluation stage runs on each point the
tessellator makes (reference/tessellation/tessellator.py: gl_TessCoord (u, v, w)): the
patch's barycentric point p = (u c0 + v c1) + w c2 in float32, no fused multiply-add, placed on
the exact surface: on a sphere of centre C and radius r, n = normalize(p - C) (glsl_builtins:
v times the reciprocal of its length) and the point C + r n, the normal n; on a PN triangle
(`evaluate_pn`, from control.py's pn_net) the point
(p + ((E_0 + E_1) + E_2)) + (6 ((t0 t1) t2)) c, E_k = (3 (t_i t_j)) (t_i o_ij + t_j o_ji), and
the normal normalize(((((t0 t0) N0 + (t1 t1) N1) + (t2 t2) N2) + ((t1 t2) m0 + (t2 t0) m1)) + (t0 t1) m2);
elsewhere p itself with the corners' normals interpolated alike and normalised.

Inputs: gl_TessCoord (N, 3) float32, the patch corners (N, 3, 3) and normals (N, 3, 3) object
space for each point, the sphere (centre, radius) or None.
Output: (positions (N, 3), normals (N, 3)) float32, object space.
"""

from __future__ import annotations

import numpy as np

from reference.glsl_builtins import cross, dot, normalize
from reference.sampler import sample
from renderer.core.tessellation import DISPLACEMENT_SAMPLER


def barycentric(tess_coord: np.ndarray, corners: np.ndarray) -> np.ndarray:
    """(u c0 + v c1) + w c2 over (N, 3) tess coords and (N, 3, K) corners, float32."""
    t = np.asarray(tess_coord, np.float32)
    c = np.asarray(corners, np.float32)
    return (t[:, 0:1] * c[:, 0] + t[:, 1:2] * c[:, 1]) + t[:, 2:3] * c[:, 2]


def evaluate_pn(tess_coord: np.ndarray, corners: np.ndarray, normals: np.ndarray,
                offsets: np.ndarray, centre: np.ndarray, mid_normals: np.ndarray):
    """A PN patch's points and normals: tess coords (N, 3), the patch's corners and normals
    (N, 3, 3), its net for each point: offsets (N, 6, 3), centre (N, 3), mid normals (N, 3, 3)."""
    f = np.float32
    t = np.asarray(tess_coord, f)
    p = barycentric(t, corners)
    t0, t1, t2 = t[:, 0:1], t[:, 1:2], t[:, 2:3]
    o = np.asarray(offsets, f)

    def edge(ti, tj, o_ij, o_ji):
        return (f(3) * (ti * tj)) * (ti * o_ij + tj * o_ji)
    edges = (edge(t1, t2, o[:, 0], o[:, 1]) + edge(t2, t0, o[:, 2], o[:, 3])) + edge(t0, t1, o[:, 4], o[:, 5])
    position = (p + edges) + (f(6) * ((t0 * t1) * t2)) * np.asarray(centre, f)
    n, m = np.asarray(normals, f), np.asarray(mid_normals, f)
    normal = normalize(((((t0 * t0) * n[:, 0] + (t1 * t1) * n[:, 1]) + (t2 * t2) * n[:, 2])
                        + ((t1 * t2) * m[:, 0] + (t2 * t0) * m[:, 1])) + (t0 * t1) * m[:, 2])
    return position.astype(f), normal.astype(f)


def evaluate_displaced(tess_coord: np.ndarray, corners: np.ndarray, normals: np.ndarray, uvs: np.ndarray,
                       tangent_s: np.ndarray, tangent_t: np.ndarray, texture, scale: float):
    """A displaced patch's points and normals: tess coords (N, 3), the patch's corners, normals
    (N, 3, 3) and UVs (N, 3, 2), its tangents (N, 3) each (control.py displaced_tangents), the
    height image (a Texture) and S. The height is the red channel of sample() at level 0 with
    the displacement sampler (reference/sampler.py, as textureLod in the evaluation stage)."""
    f = np.float32
    t = np.asarray(tess_coord, f)
    p = barycentric(t, corners)
    st = barycentric(t, uvs)
    along = normalize(barycentric(t, normals))

    def height(s, v):
        return sample(texture, DISPLACEMENT_SAMPLER, s, v, lod=0.0)[:, 0].astype(f)
    S = f(scale)
    position = p + along * (height(st[:, 0], st[:, 1]) * S)[:, None]
    texel = (f(1) / f(texture.width), f(1) / f(texture.height))      # u_height_texel
    dh_ds = (height(st[:, 0] + texel[0], st[:, 1]) - height(st[:, 0] - texel[0], st[:, 1])) * (f(texture.width) * f(0.5))
    dh_dt = (height(st[:, 0], st[:, 1] + texel[1]) - height(st[:, 0], st[:, 1] - texel[1])) * (f(texture.height) * f(0.5))
    across = cross(np.asarray(tangent_s, f) + along * (S * dh_ds)[:, None],
                   np.asarray(tangent_t, f) + along * (S * dh_dt)[:, None])
    facing = dot(across, along) < 0
    return position.astype(f), normalize(np.where(facing[:, None], -across, across)).astype(f)


def evaluate(tess_coord: np.ndarray, corners: np.ndarray, normals: np.ndarray, sphere=None):
    """The points on the surface and their normals (module docstring)."""
    p = barycentric(tess_coord, corners)
    if sphere is None:
        return p, normalize(barycentric(tess_coord, normals))
    centre = np.asarray(sphere[0], np.float32)
    radius = np.float32(sphere[1])
    n = normalize(p - centre)
    return centre + radius * n, n
