"""# Twin: glsl/raytrace/textures.glsl

Textured hits (docs/conventions.md, "Textures in the ray tracer"; the data:
renderer/core/ray_textures.py), in the dtype of the hits, each formula in the GLSL's order:

- the UV at a hit: a triangle's vertex UVs weighted by its barycentrics (1 - u - v, u, v), as
  the shading normal; a sphere's by the sphere rule (renderer/core/uv_rules.py) on its
  object-space direction R (P - C) (R the world-to-object rotation; no normalisation: both
  angles are ratios), with `texture_atan2` for both angles (asin y = atan2(y, |(x, z)|));
  a plane's by its affine map U (P, 1). With motion blur, a sphere's and plane's hit is moved
  back into the shape's time-0 frame first, so that the texture turns and slides with it;
- the lookup at (u su + ou, v sv + ov) through reference/sampler.py with the slot's ray
  sampler: level 0, the magnification filter (the ray tracer's LOD rule, renderer/core/
  ray_textures.py), the GLSL's textureLod(u_textures[k], uv, 0.0);
- the texel's RGB multiplies the coefficients its material names before lighting.
"""

from __future__ import annotations

import numpy as np

from reference.lighting import MaterialUniforms
from reference.raytrace.intersect import PLANE, SPHERE, TRIANGLE
from reference.raytrace.motion import motion_at, motion_point_back
from reference.sampler import sample

# The constants of texture_atan2 (Cephes' atanf: |error| < 3e-7 rad in float32, an ulp of pi;
# 5e-8 of u, far inside a texel).
TAN_PI_8 = 0.41421356237309503
ATAN_POLYNOMIAL = (8.05374449538e-2, -1.38776856032e-1, 1.99777106478e-1, -3.33329491539e-1)


def texture_atan2(y, x):
    """atan2(y, x) in (-pi, pi] by our own polynomial (GLSL's atan is Mesa's, 1e-5 off; its
    asin worse): |y|, |x| reduced to a = min / max in [0, 1], then to [-tan pi/8, tan pi/8]
    by (a - 1) / (a + 1) + pi/4, Cephes' odd polynomial there, and the octant put back.
    atan2(0, 0) = 0; y = -0 counts as +0 (the seam's u is 1 from either side)."""
    t = np.result_type(y, x).type
    ax, ay = np.abs(x), np.abs(y)
    high, low = np.maximum(ax, ay), np.minimum(ax, ay)
    with np.errstate(divide="ignore", invalid="ignore"):
        a = np.where(high > t(0), low / high, t(0))
        big = a > t(TAN_PI_8)
        z = np.where(big, (a - t(1)) / (a + t(1)), a)
    z2 = z * z
    p = t(ATAN_POLYNOMIAL[0])
    for c in ATAN_POLYNOMIAL[1:]:
        p = p * z2 + t(c)
    r = p * z2 * z + z
    r = np.where(big, r + t(np.pi / 4), r)
    r = np.where(ay > ax, t(np.pi / 2) - r, r)
    r = np.where(x < t(0), t(np.pi) - r, r)
    return np.where(y < t(0), -r, r)


def texture_sphere_uv(d):
    """(R, 2) UVs of object-space directions d (R, 3) from a sphere's centre, any length:
    u = 1/2 + atan2(x, z) / (2 pi), v = 1/2 + atan2(y, |(x, z)|) / pi."""
    t = d.dtype.type
    x, y, z = d[:, 0], d[:, 1], d[:, 2]
    u = t(0.5) + texture_atan2(x, z) * t(0.5 / np.pi)
    v = t(0.5) + texture_atan2(y, np.sqrt(x * x + z * z)) * t(1 / np.pi)
    return np.stack([u, v], -1)


def _rows(M, p):
    """M p (R, 3) for matrices M (R, 3, 3) row by row, each sum ((x + y) + z) as the GLSL."""
    return np.stack([M[:, i, 0] * p[:, 0] + M[:, i, 1] * p[:, 1] + M[:, i, 2] * p[:, 2]
                     for i in range(3)], -1)


def texture_time0(rows, k, P, time):
    """The hits P on shapes k moved back to the shapes' time-0 frame (motion rows per shape)."""
    if rows is None or time is None:
        return P
    out = P.copy()
    for shape in np.unique(k):
        on = k == shape
        out[on] = motion_point_back(motion_at(rows[shape], time[on]), P[on])
    return out


def texture_uv(rs, kind, index, P, bary, time=None):
    """(R, 2) the UV of each hit (trace.py's kind and index; P the hit points; bary the
    triangles' (u, v)); `time` each hit's time where motion blur runs."""
    tx, t = rs.textures, P.dtype.type
    uv = np.zeros((len(P), 2), t)
    moving = rs.motion is not None and time is not None
    m = kind == SPHERE
    if m.any():
        k = index[m]
        rows = rs.motion.rows(rs.sphere_object) if moving else None
        centres = rs.sphere_centre[k].astype(t)        # time 0, where P is moved back to
        d = texture_time0(rows, k, P[m], None if time is None else time[m]) - centres
        uv[m] = texture_sphere_uv(_rows(tx.sphere_rotation[k].astype(t), d))
    m = kind == PLANE
    if m.any():
        k = index[m]
        rows = rs.motion.rows(rs.plane_object) if moving else None
        p = texture_time0(rows, k, P[m], None if time is None else time[m])
        U = tx.plane_map[k].astype(t)
        uv[m] = np.stack([U[:, i, 0] * p[:, 0] + U[:, i, 1] * p[:, 1] + U[:, i, 2] * p[:, 2]
                          + U[:, i, 3] for i in range(2)], -1)
    m = kind == TRIANGLE
    if m.any():
        w = tx.triangle_uvs[index[m]].astype(t)
        u, v = bary[m, 0:1], bary[m, 1:2]
        uv[m] = (t(1) - u - v) * w[:, 0] + u * w[:, 1] + v * w[:, 2]
    return uv


def texture_texel(rs, obj, uv):
    """(R, 3) the RGB each hit's texture gives at its UV (1 where the object is untextured):
    the lookup at uv * scale + offset, per slot through its ray sampler at level 0; in
    float32 (the sampler's) whatever the hits' dtype."""
    tx, t = rs.textures, uv.dtype.type
    out = np.ones((len(uv), 3), t)
    slot = tx.slot[obj]
    transform = tx.uv_transform[obj].astype(np.float32)
    at = uv.astype(np.float32) * transform[:, :2] + transform[:, 2:]
    for k, material_texture in enumerate(tx.textures):
        m = slot == k
        if m.any():
            out[m] = sample(material_texture.texture, material_texture.sampler,
                            at[m, 0], at[m, 1])[:, :3]
    return out


def texture_modulate(rs, mats: MaterialUniforms, obj, kind, index, P, bary,
                     time=None) -> MaterialUniforms:
    """The hits' materials (trace.py's `materials`) with each coefficient their texture
    modulates multiplied by the texel; an untextured object's left as they are."""
    texel = texture_texel(rs, obj, texture_uv(rs, kind, index, P, bary, time)).astype(mats.u_kd.dtype)
    flags = rs.textures.modulate[obj]

    def by(i, k):
        return np.where(flags[:, i:i + 1], k * texel, k)
    return MaterialUniforms(by(0, mats.u_ka), by(1, mats.u_kd), by(2, mats.u_ks), mats.u_n,
                            specular=mats.specular)
