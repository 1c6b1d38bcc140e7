"""# Twin: glsl/raytrace/pathtrace.glsl

Path tracing (docs/pathtrace.md; Kajiya 1986), vectorised over paths: one path per camera ray,
every path of one bounce at once (a wavefront), in float32 as the GLSL (or float64, the ground
truth). Each bounce, as the GLSL:

- the nearest hit (trace.py's scene_hit) and its surface; a miss brings the background;
- on the lit side (the front, or either side of a two-sided material): the emission; the
  lights' terms (reference/lighting.py with k_a = 0, area lights and shadow rays as trace.py's);
  next-event estimation of one emitting triangle (emitter_light) times k_d. An emitter's light
  found by next-event estimation and found by a diffuse bounce are each weighted by the power
  heuristic of the two densities (emitter_light's weight, emission_weight;
  renderer/core/path_emitters.py's density);
- one lobe by the largest channel of its weight (diffuse k_d, reflected k_r + k_t F,
  transmitted k_t (1 - F)), the weight divided by its probability; a diffuse direction
  cosine-weighted about the lit normal (warp.py's square_to_cosine_hemisphere), absorbed
  below the surface; Russian roulette from ROULETTE_DEPTH (renderer/core/path_options.py).

The numbers of bounce b are those of slot 1 + b (the GLSL's g_ray_key = b). The ray tree's
hash (trace.py) hears each hit, each shadow ray and each lobe chosen.
"""

from __future__ import annotations

from dataclasses import replace

import numpy as np

from reference.lighting import Lights, lighting, normalize
from reference.raytrace.area_lights import AreaDraw, area_light_terms
from reference.raytrace.glossy import glossy_reflection
from reference.raytrace.intersect import MISS, triangle_normal
from reference.raytrace.optics import fresnel_exact, fresnel_schlick, ray_reflect, ray_refract
from reference.raytrace.trace import (ROOT_PATH, SHADOW, _at, _dot, area_light_shadow, blocked_towards,
                                      leaving_s_min, materials, mix64, ray_origin, ray_tree_event,
                                      sample_times, scene_hit, shadow_visibility, shape_id, surface,
                                      transmitted_share)
from reference.raytrace.warp import orthonormal_basis, square_to_cosine_hemisphere
from renderer.core.path_options import (BOUNCE_DIMENSION, EMITTER_CHOICE_DIMENSION,
                                        EMITTER_POINT_DIMENSION, LOBE_DIMENSION, ROULETTE_DEPTH,
                                        ROULETTE_DIMENSION)
from renderer.core.ray_sampling import GLOSSY_DIMENSION

F32 = np.float32
LOBE = 6                     # the ray tree's event of a lobe chosen (after trace.py's SHADOW + 1)
EMITTER_SHADOW = 1 << 20     # the light index of a next-event shadow ray in its SHADOW event


def _largest(v):
    return np.maximum(v[:, 0], np.maximum(v[:, 1], v[:, 2]))


def power_heuristic(mine, other):
    """Veach's power heuristic: the weight of a sample of density `mine` against `other`'s."""
    return mine * mine / (mine * mine + other * other)


def emission_weight(bounce_density, density, s, D, Du, Ng):
    """The GLSL's emission_weight: 1 where the last bounce was not diffuse (density 0) or the
    emitter is not sampled, else the power heuristic of the bounce's density against next-event
    estimation's, density s^2 |D|^2 / cos."""
    t = Du.dtype.type
    weighed = (bounce_density > 0) & (density > 0)
    with np.errstate(divide="ignore", invalid="ignore", over="ignore"):
        other = density * (s * s * _dot(D, D)) / -_dot(Du, Ng)
        weight = power_heuristic(bounce_density, other)
    return np.where(weighed, weight, t(1))


def emitter_light(rs, emitters, P, N, Ng, shape, samples, owner, slot, share, time=None, record=None):
    """The GLSL's emitter_light at points P (n, 3) with lit normals N and outward geometric
    normals Ng, on analytic shapes `shape`, of the camera rays `owner` at `slot`, with
    g_diffuse_share `share` (n,): (n, 3)."""
    t = P.dtype.type
    u = samples.point_1d(owner, slot, EMITTER_CHOICE_DIMENSION)
    k = np.minimum(np.searchsorted(emitters.cdf, u, side="right"), emitters.count - 1)
    A, B, C = (emitters.triangles[k, j].astype(t) for j in range(3))
    v = samples.point_2d(owner, slot, EMITTER_POINT_DIMENSION).astype(t)
    r = np.sqrt(v[:, 0])
    Q = A + (r * (t(1) - v[:, 1]))[:, None] * (B - A) + (r * v[:, 1])[:, None] * (C - A)
    to_light = Q - P
    d2 = _dot(to_light, to_light)
    d = np.sqrt(d2)
    with np.errstate(divide="ignore", invalid="ignore"):
        L = to_light / d[:, None]
        cos_here = _dot(N, L)
        cos_there = -_dot(triangle_normal(A, B, C), L)
    facet = np.where((_dot(Ng, N) >= 0)[:, None], Ng, -Ng)        # trace.glsl's facet rule
    lit = (d2 > 0) & (cos_here > 0) & (cos_there > 0) & ~(_dot(facet, to_light) < 0)
    blocked = np.zeros(len(P), bool)
    blocked[lit] = blocked_towards(rs, Q[lit], P[lit], Ng[lit], shape[lit], _at(time, lit))
    if record is not None:
        record(blocked, ray_tree_event(SHADOW, EMITTER_SHADOW))
    visible = np.where(blocked, t(0), t(1))
    e = emitters.emission[emitters.owner[k]].astype(t)
    density = e[:, 3]
    with np.errstate(divide="ignore", invalid="ignore", over="ignore"):
        weight = power_heuristic(density * d2 / cos_there, share * cos_here / t(np.pi))
        scale = visible * cos_here * cos_there / (t(np.pi) * d2 * density) * weight
        light = e[:, :3] * scale[:, None]
    return np.where(lit[:, None], light, t(0))


def path_trace(rs, lights: Lights, O, D, s_min, s_max, background, max_depth: int, shadows: bool = True,
               ray_trees=None, samples=None, areas=None, time=None, *, emitters):
    """Trace paths from camera rays O, D (R, 3): (colour (R, 3), hit (R,), s (R,)), the camera
    rays' hits between s_min and s_max; the arguments as trace.py's trace, `emitters` a
    PathEmitters (renderer/core/path_emitters.py) and `samples` required (every bounce draws)."""
    t = np.asarray(O).dtype.type if np.asarray(O).dtype == np.float64 else F32
    O, D = np.asarray(O, t), np.asarray(D, t)
    R = len(O)
    time = sample_times(rs, samples, R, t) if time is None else np.asarray(time, t)
    colour = np.zeros((R, 3), t)
    background = np.asarray(background, t)
    emission = emitters.emission.astype(t)
    owner = np.arange(R)
    from_shape = np.full(R, -1)
    weight = np.ones((R, 3), t)
    bounce_density = np.zeros(R, t)            # the last diffuse bounce's, per steradian; 0: none
    path = np.full(R, ROOT_PATH, np.uint64)
    trees = np.zeros(R, np.uint64) if ray_trees is None else ray_trees
    first_hit, first_s = np.zeros(R, bool), np.full(R, t(s_max))

    def record(rays, event):
        np.add.at(trees, owner[rays], mix64(path[rays] + mix64(event)))

    for depth in range(max_depth + 1):
        if not len(O):
            break
        lo, hi = (t(s_min), t(s_max)) if depth == 0 else (leaving_s_min(O), t(np.inf))
        kind, index, s, uv = scene_hit(rs, O, D, lo, hi, from_shape, _at(time, owner))
        record(slice(None), ray_tree_event(kind, index))
        hit = kind != MISS
        if depth == 0:
            first_hit, first_s = hit.copy(), s.copy()
        colour[owner[~hit]] += weight[~hit] * background
        O, D, kind, index, s, uv, owner, from_shape, weight, bounce_density, path = (
            a[hit] for a in (O, D, kind, index, s, uv, owner, from_shape, weight, bounce_density, path))
        when = _at(time, owner)
        P, Ng, Ns, obj = surface(rs, O, D, kind, index, s, uv, when)
        shape = shape_id(rs, kind, index)
        Du = normalize(D)
        back = _dot(Du, Ng) > 0
        mats = materials(rs, obj, rs.specular, t)
        if rs.textures is not None:
            from reference.raytrace.textures import texture_modulate
            mats = texture_modulate(rs, mats, obj, kind, index, P, uv, when)
        mats = replace(mats, u_ka=np.zeros_like(mats.u_ka))      # the bounces are the ambient light
        key = np.full(len(O), depth, np.uint32)
        slot = np.uint32(1) + key
        lit = ~back | rs.two_sided[obj]
        N_in = np.where(back[:, None], -Ns, Ns)
        Ng_in = np.where(back[:, None], -Ng, Ng)
        kd = np.where(lit[:, None], mats.u_kd, t(0))
        # the next bounce's lobes first: next-event estimation weighs against the diffuse one
        kr, kt = rs.kr[obj].astype(t), rs.kt[obj].astype(t)
        ior = rs.ior[obj].astype(t)
        eta = np.where(back, ior, t(1) / ior)
        F = np.where(rs.fresnel_exact[obj], fresnel_exact(Du, N_in, eta), fresnel_schlick(Du, N_in, eta))
        refracted, T = ray_refract(Du, N_in, eta)
        w_r = kr + kt * F[:, None]
        w_t = np.where(refracted[:, None], kt * transmitted_share(rs, F[:, None], eta), t(0))
        p_d, p_r, p_t = _largest(kd), _largest(w_r), _largest(w_t)
        total = p_d + p_r + p_t
        with np.errstate(divide="ignore", invalid="ignore"):
            share = np.where((depth < max_depth) & (total > 0), p_d / total, t(0))
        e = emission[obj]
        shows = lit & ~back
        colour[owner] += np.where(shows[:, None], weight * (e[:, :3] * emission_weight(
            bounce_density, e[:, 3], s, D, Du, Ng)[:, None]), t(0))
        L = np.flatnonzero(lit)
        if len(L):
            def record_lit(rays, event, L=L):
                record(L[rays], event)
            lit_mats = replace(mats, **{name: getattr(mats, name)[L] for name in ("u_ka", "u_kd", "u_ks", "u_n")})
            at_lit = _at(when, L)
            area_light = None if areas is None else area_light_terms(
                lights, areas, AreaDraw(samples, owner[L], key[L]),
                area_light_shadow(rs, lights, Ng[L], shape[L], record_lit, at_lit) if shadows else None)
            local = lighting(P[L], N_in[L], O[L], lit_mats, lights,
                             shadow_visibility(rs, lights, Ng[L], shape[L], record_lit, at_lit)
                             if shadows else None, area_light)
            colour[owner[L]] += weight[L] * local
            if emitters.count:
                light = emitter_light(rs, emitters, P[L], N_in[L], Ng[L], shape[L], samples, owner[L],
                                      slot[L], share[L], at_lit, record_lit)
                colour[owner[L]] += weight[L] * (kd[L] * light)
        if depth == max_depth:
            break
        # the next bounce: one lobe, by the largest channel of its weight
        u = samples.point_1d(owner, slot, LOBE_DIMENSION).astype(t) * total
        lobe = np.where(u < p_d, 0, np.where(u < p_d + p_r, 1, 2))
        p = np.choose(lobe, [p_d, p_r, p_t])
        go = (total > 0) & (p > 0)
        with np.errstate(divide="ignore", invalid="ignore"):
            factor = np.choose(lobe[:, None], [kd, w_r, w_t]) * (total / p)[:, None]
        O_next, D_next, density_next = np.zeros_like(P), np.zeros_like(P), np.zeros(len(P), t)
        diffuse = np.flatnonzero(go & (lobe == 0))
        if len(diffuse):
            v = square_to_cosine_hemisphere(samples.point_2d(owner[diffuse], slot[diffuse],
                                                             BOUNCE_DIMENSION).astype(t))
            n = N_in[diffuse]
            b1, b2 = orthonormal_basis(n)
            D_next[diffuse] = v[:, 0:1] * b1 + v[:, 1:2] * b2 + v[:, 2:3] * n
            go[diffuse] &= _dot(D_next[diffuse], Ng_in[diffuse]) > 0
            O_next[diffuse] = ray_origin(P[diffuse], Ng_in[diffuse], shape[diffuse])
            density_next[diffuse] = share[diffuse] * v[:, 2] / t(np.pi)
        mirror = np.flatnonzero(go & (lobe == 1))
        if len(mirror):
            R_m = ray_reflect(Du[mirror], N_in[mirror])
            if rs.gloss_set:     # the lobe's code wherever a material sets gloss, inf included
                u_g = samples.point_2d(owner[mirror], slot[mirror], GLOSSY_DIMENSION)
                R_m, kept = glossy_reflection(R_m, Ng_in[mirror], rs.gloss[obj[mirror]], u_g)
                go[mirror] &= kept
            D_next[mirror] = R_m
            O_next[mirror] = ray_origin(P[mirror], Ng_in[mirror], shape[mirror])
        glass = np.flatnonzero(go & (lobe == 2))
        if len(glass):
            D_next[glass] = T[glass]
            O_next[glass] = ray_origin(P[glass], -Ng_in[glass], shape[glass])
        record(go, ray_tree_event(LOBE, lobe[go]))
        weight = weight * factor
        if depth + 1 >= ROULETTE_DEPTH:
            q = np.minimum(t(1), _largest(weight))
            go &= ~(samples.point_1d(owner, slot, ROULETTE_DIMENSION) >= q)
            with np.errstate(divide="ignore", invalid="ignore"):
                weight = weight / q[:, None]
        path = mix64(path ^ (lobe.astype(np.uint64) + np.uint64(1)))
        O, D, owner, weight, path = O_next[go], D_next[go], owner[go], weight[go], path[go]
        from_shape, bounce_density = shape[go], density_next[go]
    return colour, first_hit, first_s
