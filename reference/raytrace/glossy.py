"""# Twin: glsl/raytrace/glossy.glsl

Glossy reflection (docs/conventions.md, "Glossy reflection"), vectorised over reflected rays:
the direction drawn from the Phong lobe of the material's `gloss` exponent about the mirror
direction with the hit's GLOSSY_DIMENSION point (slot 1 + the ray's key), absorbed below the
surface; gloss inf keeps the mirror direction exactly.
"""

from __future__ import annotations

import numpy as np

from reference.glsl_builtins import dot as _dot
from reference.raytrace.warp import orthonormal_basis, square_to_phong_lobe
from renderer.core.ray_sampling import GLOSSY_DIMENSION


def glossy_reflection(R, Ng_in, gloss, u):
    """The GLSL's glossy_direction (docs/conventions.md, "Glossy reflection"): (D, kept) for
    reflected rays with mirror directions R (n, 3), outward geometric normals Ng_in (n, 3) on
    their incoming side, lobe exponents `gloss` (n,) and points u (n, 2) (GLOSSY_DIMENSION at
    the hit): D is square_to_phong_lobe(u, gloss) in the basis (orthonormal_basis(R), R);
    where it lies below the surface (D.Ng_in <= 0) the ray is absorbed (kept False). A mirror
    (gloss inf) takes R exactly and is always kept."""
    t = R.dtype.type
    mirror = np.isinf(gloss)
    lobe = square_to_phong_lobe(np.asarray(u, t), np.asarray(gloss, t))
    b1, b2 = orthonormal_basis(R)
    D = lobe[:, 0:1] * b1 + lobe[:, 1:2] * b2 + lobe[:, 2:3] * R
    return np.where(mirror[:, None], R, D), mirror | (_dot(D, Ng_in) > 0)


def glossy_rays(gloss, samples, D_r, go_r, Ng_in, obj, owner, key):
    """trace.py's reflected rays D_r (those of go_r) through glossy_reflection, each with the
    point of its hit (slot 1 + the ray's key) and its material's exponent (gloss[obj]); the
    absorbed ones dropped from D_r and go_r."""
    if samples is None:
        raise ValueError("a scene that sets gloss needs the camera rays' samples (trace(samples=))")
    with np.errstate(over="ignore"):                 # slots wrap modulo 2^32, as the GLSL's
        slot = np.uint32(1) + key[go_r]
    u = samples.point_2d(owner[go_r], slot, GLOSSY_DIMENSION)
    D_r, kept = glossy_reflection(D_r, Ng_in[go_r], gloss[obj[go_r]], u)
    go_r = go_r.copy()
    go_r[np.flatnonzero(go_r)[~kept]] = False
    return D_r[kept], go_r
