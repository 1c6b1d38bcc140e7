"""# Twin: glsl/raytrace/trace.glsl

The ray tracer proper (docs/conventions.md, "Rays", "Tracing"), in float32 as the GLSL,
vectorised over rays: a wavefront per bounce (every ray of one depth at once), no Python loop
over pixels or rays.

- closest hit: the analytic spheres, then the planes (intersect.py), then the scene's triangles
  through its BVH (bvh.py) with s_max the nearest hit so far;
- the surface at the hit: P = O + s D; the outward geometric normal Ng (sphere (P - C)/r, the
  plane's N, the triangle's normal) and the shading normal Ns (the same for shapes; for a
  triangle the vertex normals interpolated with (1 - u - v, u, v) and normalised, as the
  rasteriser's Phong shading);
- local colour: lighting.py's `lighting` at P with the viewer at the ray's origin, N = Ns, or
  -Ns where the back is seen (D.Ng > 0) of a two-sided material; a shadow ray per light from
  offset_ray_origin(P, Ng on the light's side): directional, towards L with s_max = inf; point,
  towards the light, unit direction, s_max = the distance. Any hit is a shadow (every surface
  is opaque to shadow rays); in shadow a light adds nothing but its ambient share; a light
  whose terms are 0 at P (behind it; k_d = k_s = 0) casts no shadow ray, as the GLSL;
- secondary rays (depth < max_depth): with Du = normalize(D), N and Ng flipped to the incoming
  side, eta = 1/ior entering (front seen), ior leaving, F = fresnel_schlick(Du, N, eta):
  reflected weight k_r + k_t F along ray_reflect(Du, N) from offset_ray_origin(P, Ng);
  transmitted weight k_t (1 - F) along ray_refract(Du, N, eta) from offset_ray_origin(P, -Ng)
  (none under total internal reflection, where F = 1). A ray's colour is
  local + w_r reflected + w_t transmitted; a ray that misses brings the background colour.
"""

from __future__ import annotations

import numpy as np

from reference.lighting import Lights, MaterialUniforms, lighting, normalize, normalize_or_zero
from reference.raytrace.bvh import any_hit as bvh_any_hit, closest_hit as bvh_closest_hit
from reference.raytrace.intersect import (plane_normal, ray_plane, ray_sphere, sphere_normal,
                                          triangle_normal)
from reference.raytrace.optics import fresnel_schlick, offset_ray_origin, ray_reflect, ray_refract

F32 = np.float32
MISS, SPHERE, PLANE, TRIANGLE = 0, 1, 2, 3


def _dot(a, b):
    return a[..., 0] * b[..., 0] + a[..., 1] * b[..., 1] + a[..., 2] * b[..., 2]


def scene_hit(rs, O, D, s_min, s_max):
    """(kind, index, s, uv) of the nearest hit with s_min < s < s_max of rays O, D (R, 3):
    kind MISS/SPHERE/PLANE/TRIANGLE, index the sphere's, plane's or original triangle's, s the
    hit (s_max on a miss)."""
    R = len(O)
    s = np.broadcast_to(np.asarray(s_max, F32), (R,)).astype(F32)
    kind = np.zeros(R, np.int64)
    index = np.full(R, -1, np.int64)
    uv = np.zeros((R, 2), F32)
    for k in range(len(rs.sphere_radius)):
        hit, s_k = ray_sphere(O, D, rs.sphere_centre[k].astype(F32), F32(rs.sphere_radius[k]), F32(s_min), s)
        s = np.where(hit, s_k, s)
        kind[hit], index[hit] = SPHERE, k
    for k in range(len(rs.plane_offset)):
        hit, s_k = ray_plane(O, D, rs.plane_normal[k].astype(F32), F32(rs.plane_offset[k]), F32(s_min), s)
        s = np.where(hit, s_k, s)
        kind[hit], index[hit] = PLANE, k
    if rs.bvh is not None:
        hit, s_t, uv_t, tri = bvh_closest_hit(rs.bvh, O, D, s_min, s)
        s = np.where(hit, s_t, s)
        kind[hit], index[hit], uv[hit] = TRIANGLE, tri[hit], uv_t[hit]
    return kind, index, s, uv


def occluded(rs, O, D, s_max):
    """Whether anything is hit with 0 < s < s_max (a shadow ray; s_max a number or one per ray):
    any hit, not the nearest, as the GLSL: the spheres, the planes, then the BVH's any-hit walk
    for the rays none of them blocks."""
    zero = F32(0)
    s_max = np.broadcast_to(np.asarray(s_max, F32), (len(O),))
    blocked = np.zeros(len(O), bool)
    for k in range(len(rs.sphere_radius)):
        blocked |= ray_sphere(O, D, rs.sphere_centre[k].astype(F32), F32(rs.sphere_radius[k]), zero, s_max)[0]
    for k in range(len(rs.plane_offset)):
        blocked |= ray_plane(O, D, rs.plane_normal[k].astype(F32), F32(rs.plane_offset[k]), zero, s_max)[0]
    if rs.bvh is not None:
        rest = ~blocked
        blocked[rest] = bvh_any_hit(rs.bvh, O[rest], D[rest], zero, s_max[rest])
    return blocked


def surface(rs, O, D, kind, index, s, uv):
    """(P, Ng, Ns, obj) at hits (no misses): the hit point, the outward geometric and shading
    unit normals, the object index."""
    P = O + s[:, None] * D
    Ng = np.zeros_like(P)
    Ns = np.zeros_like(P)
    obj = np.zeros(len(P), np.int64)
    m = kind == SPHERE
    if m.any():
        k = index[m]
        Ng[m] = sphere_normal(P[m], rs.sphere_centre[k].astype(F32), rs.sphere_radius[k].astype(F32)[:, None])
        Ns[m] = Ng[m]
        obj[m] = rs.sphere_object[k]
    m = kind == PLANE
    if m.any():
        k = index[m]
        Ng[m] = plane_normal(rs.plane_normal[k].astype(F32))
        Ns[m] = Ng[m]
        obj[m] = rs.plane_object[k]
    m = kind == TRIANGLE
    if m.any():
        k = index[m]
        V = rs.triangles[k].astype(F32)
        Ng[m] = triangle_normal(V[:, 0], V[:, 1], V[:, 2])
        n = rs.triangle_normals[k].astype(F32)
        u, v = uv[m, 0:1], uv[m, 1:2]
        Ns[m] = normalize_or_zero((F32(1) - u - v) * n[:, 0] + u * n[:, 1] + v * n[:, 2])
        obj[m] = rs.triangle_object[k]
    return P, Ng, Ns, obj


def materials(rs, obj, specular: bool) -> MaterialUniforms:
    return MaterialUniforms(rs.ka[obj].astype(F32), rs.kd[obj].astype(F32), rs.ks[obj].astype(F32),
                            rs.n[obj].astype(F32)[:, None], specular=specular)


def shadow_visibility(rs, lights: Lights, Ng):
    """The visibility callable of lighting.py for hits with outward geometric normals Ng: one
    shadow ray per point and light (the GLSL's light_visibility_directional / _point)."""
    def visibility(kind, i, P, N, needed):
        blocked = np.zeros(len(P), bool)
        P, n = P[needed], Ng[needed]
        if kind == "directional":
            L = normalize(-lights.u_directional_direction[i])
            n = np.where((_dot(n, L) >= 0)[:, None], n, -n)
            O = offset_ray_origin(P, n)
            blocked[needed] = occluded(rs, O, np.broadcast_to(L, O.shape).astype(F32), F32(np.inf))
        else:
            Q = lights.u_point_position[i]
            n = np.where((_dot(n, Q - P) >= 0)[:, None], n, -n)
            O = offset_ray_origin(P, n)
            to_light = Q - O
            d = np.sqrt(_dot(to_light, to_light))
            with np.errstate(divide="ignore", invalid="ignore"):
                L = to_light / d[:, None]
            blocked[needed] = occluded(rs, O, L, d) & (d > 0)
        return np.where(blocked, F32(0), F32(1))[:, None]
    return visibility


def trace(rs, lights: Lights, O, D, s_min, s_max, background, max_depth: int, shadows: bool = True):
    """Trace rays O, D (R, 3) float32: (colour (R, 3), hit (R,), s (R,)) with hit and s of
    each ray's first hit (primary rays between s_min and s_max; secondary rays from 0 to inf).
    shadows=False lights every point by every light (no shadow rays; the GLSL without SHADOWS)."""
    O = np.asarray(O, F32)
    D = np.asarray(D, F32)
    R = len(O)
    colour = np.zeros((R, 3), F32)
    background = np.asarray(background, F32)
    specular = rs.specular
    owner = np.arange(R)
    weight = np.ones((R, 3), F32)
    first_hit, first_s = None, None
    lo, hi = F32(s_min), F32(s_max)
    for depth in range(max_depth + 1):
        if not len(O):
            break
        kind, index, s, uv = scene_hit(rs, O, D, lo, hi)
        hit = kind != MISS
        if depth == 0:
            first_hit, first_s = hit.copy(), s.copy()
        np.add.at(colour, owner[~hit], weight[~hit] * background)
        O, D, kind, index, s, uv, owner, weight = (a[hit] for a in (O, D, kind, index, s, uv, owner, weight))
        P, Ng, Ns, obj = surface(rs, O, D, kind, index, s, uv)
        Du = normalize(D)
        back = _dot(Du, Ng) > 0
        N = np.where((back & rs.two_sided[obj])[:, None], -Ns, Ns)
        local = lighting(P, N, O, materials(rs, obj, specular), lights,
                         shadow_visibility(rs, lights, Ng) if shadows else None)
        np.add.at(colour, owner, weight * local)
        if depth == max_depth:
            break
        # secondary rays
        N_in = np.where(back[:, None], -Ns, Ns)
        Ng_in = np.where(back[:, None], -Ng, Ng)
        ior = rs.ior[obj].astype(F32)
        eta = np.where(back, ior, F32(1) / ior)
        F = fresnel_schlick(Du, N_in, eta)[:, None]
        kr, kt = rs.kr[obj].astype(F32), rs.kt[obj].astype(F32)
        w_r = weight * (kr + kt * F)
        w_t = weight * (kt * (F32(1) - F))
        refracted, T = ray_refract(Du, N_in, eta)
        go_r = (w_r > 0).any(-1)
        go_t = (w_t > 0).any(-1) & refracted
        O = np.concatenate([offset_ray_origin(P[go_r], Ng_in[go_r]), offset_ray_origin(P[go_t], -Ng_in[go_t])])
        D = np.concatenate([ray_reflect(Du[go_r], N_in[go_r]), T[go_t]]).astype(F32)
        owner = np.concatenate([owner[go_r], owner[go_t]])
        weight = np.concatenate([w_r[go_r], w_t[go_t]])
        lo, hi = F32(0), F32(np.inf)
    return colour, first_hit, first_s
