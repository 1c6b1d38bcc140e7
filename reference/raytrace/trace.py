"""# Twin: glsl/raytrace/trace.glsl

The ray tracer proper (docs/conventions.md, "Rays", "Tracing"), in float32 as the GLSL (or in
float64, the ground truth: the dtype of the rays given), vectorised over rays: a wavefront per
bounce (every ray of one depth at once), no Python loop over pixels or rays.

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
  whose terms are 0 at P (behind it; k_d = k_s = 0) casts no shadow ray, as the GLSL; an area
  light (a point light with an area) is M = light_samples point lights at points of its area,
  each with its shadow ray, averaged (area_lights.py, with area_light_shadow's rays);
- secondary rays (depth < max_depth): with Du = normalize(D), N and Ng flipped to the incoming
  side, eta = 1/ior entering (front seen), ior leaving, F = fresnel_schlick(Du, N, eta):
  reflected weight k_r + k_t F along ray_reflect(Du, N) from offset_ray_origin(P, Ng);
  transmitted weight k_t (1 - F) along ray_refract(Du, N, eta) from offset_ray_origin(P, -Ng)
  (none under total internal reflection, where F = 1). A ray's colour is
  local + w_r reflected + w_t transmitted; a ray that misses brings the background colour;
- textures (docs/conventions.md, "Textures in the ray tracer"; textures.py): where some
  material is textured, the coefficients its texture modulates are multiplied by the texel at
  the hit's UV before lighting (texture_modulate);
- glossy reflection (docs/conventions.md, "Glossy reflection"; glossy.py): where some material
  sets `gloss`, each reflected ray is drawn from the Phong lobe of its material's exponent
  about the mirror direction with the hit's GLOSSY_DIMENSION point, absorbed below the
  surface; gloss inf keeps the mirror direction.
"""

from __future__ import annotations

import numpy as np

from reference.glsl_builtins import dot as _dot
from reference.lighting import Lights, MaterialUniforms, lighting, normalize, normalize_or_zero
from reference.raytrace.bvh import any_hit as bvh_any_hit, closest_hit as bvh_closest_hit
from reference.raytrace.intersect import (MISS, PLANE, SPHERE, TRIANGLE, plane_normal, ray_plane,
                                          ray_sphere_from, sphere_normal, triangle_normal)
from reference.raytrace.motion import (motion_at, motion_direction, motion_direction_back,
                                       motion_plane, motion_point, motion_point_back, motion_time)
from renderer.core.ray_sampling import TIME_DIMENSION
from reference.raytrace.optics import fresnel_exact, fresnel_schlick, offset_ray_origin, ray_reflect, ray_refract
from reference.raytrace.area_lights import AreaDraw, area_light_terms
from reference.raytrace.glossy import glossy_rays
from reference.raytrace.textures import texture_modulate
from renderer.core.ray_depth import RAY_WEIGHT_CUTOFF

F32 = np.float32
# Hits closer than this, relative, are a tie, kept by the surface found first (scene_hit; the
# GLSL's TRACE_HIT_TIE): 64 eps32, above the few ulps by which the rounding of a triangle's
# vertices and of the two intersection formulas moves a triangle lying in a plane off it.
HIT_TIE = 2.0 ** -18


def leaving_s_min(O):
    """s_min of a secondary or shadow ray (unit direction) from O: HIT_TIE |O|. A surface met
    closer than that to the point the ray leaves ties with the surface it leaves (positions
    are camera-relative, so |O| is the scale of their rounding), which keeps it."""
    return O.dtype.type(HIT_TIE) * np.sqrt(_dot(O, O))


def scene_hit(rs, O, D, s_min, s_max, from_shape=None, time=None):
    """(kind, index, s, uv) of the nearest hit with s_min < s < s_max of rays O, D (R, 3):
    kind MISS/SPHERE/PLANE/TRIANGLE, index the sphere's, plane's or original triangle's, s the
    hit (s_max on a miss). In the dtype of O: float32, or float64 with the scene's float64
    surfaces. `from_shape` (R,): the analytic shape each ray starts on (shape_id; -1 for none),
    met again only at a sphere's far side (ray_sphere_from, on_surface). Ties (HIT_TIE): a surface
    replaces the nearest found so far only when nearer by more than HIT_TIE relative. `time`
    (R,): each ray's time, where the motion code runs (shapes_at, mesh_trees)."""
    R, t = len(O), O.dtype.type
    s = np.broadcast_to(np.asarray(s_max, t), (R,)).astype(t)
    s_min = np.broadcast_to(np.asarray(s_min, t), (R,))
    limit = s.copy()
    keep = t(1) - t(HIT_TIE)
    from_shape = np.full(R, -1) if from_shape is None else from_shape
    kind = np.zeros(R, np.int64)
    index = np.full(R, -1, np.int64)
    uv = np.zeros((R, 2), t)

    def found(hit, s_k, what, k):
        nonlocal s, limit
        s = np.where(hit, s_k, s)
        limit = np.where(hit, s_k * keep, limit)
        kind[hit], index[hit] = what, k

    centres, planes = shapes_at(rs, time, t)
    for k in range(len(rs.sphere_radius)):
        C, r = centres[k], t(rs.sphere_radius[k])
        hit, s_k = ray_sphere_from(O, D, C, r, from_shape == k, s_min, limit)
        found(hit, s_k, SPHERE, k)
    for k in range(len(rs.plane_offset)):
        hit, s_k = ray_plane(O, D, *planes[k], s_min, limit)
        found(hit & (from_shape != len(rs.sphere_radius) + k), s_k, PLANE, k)
    for root, O_k, D_k in mesh_trees(rs, O, D, time):
        hit, s_t, uv_t, tri = bvh_closest_hit(rs.bvh, O_k, D_k, s_min, limit,
                                              vertices=None if t is F32 else rs.triangles, root=root)
        s = np.where(hit, s_t, s)
        limit = np.where(hit, s_t, limit)
        kind[hit], index[hit], uv[hit] = TRIANGLE, tri[hit], uv_t[hit]
    return kind, index, s, uv


# -- motion blur --------------------------------------------------------------------------------
# Where the scene has motion (rs.motion; renderer/core/raytrace_scene.py) each ray carries its
# camera sample's time: the spheres and planes move (motion_point, motion_plane) and the rays
# move into each moving mesh's time-0 frame (motion_point_back), the GLSL's trace_motion_at.
# Without a time (a caller tracing the still scene) everything stays at time 0.

def sample_times(rs, samples, R: int, t):
    """The times (R,) of camera rays 0 .. R-1 of `samples` (a sampling.RaySamples), in dtype
    t: open + u (close - open) with u their TIME_DIMENSION number at slot 0 (the GLSL's
    trace_sample_time); None where the scene has no motion or no samples are given."""
    if rs.motion is None or samples is None:
        return None
    u = samples.point_1d(np.arange(R), 0, TIME_DIMENSION)
    return motion_time(rs.motion.shutter, u.astype(t))


def shapes_at(rs, time, t):
    """(centres, planes): each sphere's centre and each plane's (N, d) in dtype t, (3,) and ()
    or, where the motion code runs, one per ray (R, 3) and (R,) at the rays' times."""
    centres = [rs.sphere_centre[k].astype(t) for k in range(len(rs.sphere_radius))]
    planes = [(rs.plane_normal[k].astype(t), t(rs.plane_offset[k])) for k in range(len(rs.plane_offset))]
    if rs.motion is None or time is None:
        return centres, planes
    spheres, flat = rs.motion.rows(rs.sphere_object), rs.motion.rows(rs.plane_object)
    return ([motion_point(motion_at(spheres[k], time), C) for k, C in enumerate(centres)],
            [motion_plane(motion_at(flat[k], time), N, d) for k, (N, d) in enumerate(planes)])


def mesh_trees(rs, O, D, time):
    """(root, O, D) for each tree of the scene's BVH: the static triangles' with the rays as
    they are, each moving mesh object's with the rays moved into its time-0 frame."""
    if rs.bvh is None:
        return []
    trees = []
    for root, obj in zip(rs.mesh_roots, rs.mesh_object):
        if obj < 0 or time is None:
            trees.append((root, O, D))
        else:
            m = motion_at(rs.motion.rows([obj])[0], time)
            trees.append((root, motion_point_back(m, O), motion_direction_back(m, D)))
    return trees


def _at(time, rays):
    """The times of `rays` (an index or mask), or None where no time is given."""
    return None if time is None else time[rays]


def _per_hit(values, k, rays):
    """values[k] at each hit (shape k, ray `rays`): one vector per shape (S of (3,)) or one per
    shape and ray (S of (R, 3))."""
    stacked = np.stack(values)
    return stacked[k, rays] if stacked.ndim == 3 else stacked[k]


def transmitted_share(rs, F, eta):
    """(R, 1) the share of the light a refracted ray brings back (the GLSL's transmitted_share):
    1 - F, times eta^2 where the scene scales radiance across refraction (the physical model:
    rs.radiance_scaling; eta = n_i / n_t)."""
    t = F.dtype.type
    share = t(1) - F
    return share * (eta * eta)[:, None] if rs.radiance_scaling else share


def shape_id(rs, kind, index):
    """The analytic shape of hits (kind, index), as from_shape: sphere k is k, plane k is
    (number of spheres) + k; -1 for a triangle or a miss (the GLSL's g_shape)."""
    return np.where(kind == SPHERE, index, np.where(kind == PLANE, len(rs.sphere_radius) + index, -1))


def ray_origin(P, n, shape):
    """Where a secondary or shadow ray leaving P on the side of n starts: P itself on an
    analytic shape (scene_hit never meets it there again), else Waechter and Binder's offset."""
    return np.where((shape >= 0)[:, None], P, offset_ray_origin(P, n))


def occluded(rs, O, D, s_max, from_shape=None, time=None):
    """Whether anything is hit with leaving_s_min(O) < s < s_max (a shadow ray from a point of
    from_shape; s_max a number or one per ray): any hit, not the nearest, as the GLSL: the
    spheres, the planes, then the BVH's any-hit walks for the rays none of them blocks. The
    answer is scene_hit's (kind != MISS) at the same `time`, found with less work."""
    R, t = len(O), O.dtype.type
    s_min = leaving_s_min(O)
    s_max = np.broadcast_to(np.asarray(s_max, t), (R,))
    from_shape = np.full(R, -1) if from_shape is None else from_shape
    blocked = np.zeros(R, bool)
    centres, planes = shapes_at(rs, time, t)
    for k in range(len(rs.sphere_radius)):
        C, r = centres[k], t(rs.sphere_radius[k])
        blocked |= ray_sphere_from(O, D, C, r, from_shape == k, s_min, s_max)[0]
    for k in range(len(rs.plane_offset)):
        hit = ray_plane(O, D, *planes[k], s_min, s_max)[0]
        blocked |= hit & (from_shape != len(rs.sphere_radius) + k)
    for root, O_k, D_k in mesh_trees(rs, O, D, time):
        rest = ~blocked
        blocked[rest] = bvh_any_hit(rs.bvh, O_k[rest], D_k[rest], s_min[rest], s_max[rest],
                                    vertices=None if t is F32 else rs.triangles, root=root)
    return blocked


def surface(rs, O, D, kind, index, s, uv, time=None):
    """(P, Ng, Ns, obj) at hits (no misses): the hit point, the outward geometric and shading
    unit normals, the object index; the surfaces at each hit's `time` (scene_hit's)."""
    P = O + s[:, None] * D
    t = P.dtype.type
    Ng = np.zeros_like(P)
    Ns = np.zeros_like(P)
    obj = np.zeros(len(P), np.int64)
    centres, planes = shapes_at(rs, time, t)
    m = kind == SPHERE
    if m.any():
        k = index[m]
        Ng[m] = sphere_normal(P[m], _per_hit(centres, k, m),
                              rs.sphere_radius[k].astype(t)[:, None])
        Ns[m] = Ng[m]
        obj[m] = rs.sphere_object[k]
    m = kind == PLANE
    if m.any():
        k = index[m]
        Ng[m] = plane_normal(_per_hit([N for N, _ in planes], k, m))
        Ns[m] = Ng[m]
        obj[m] = rs.plane_object[k]
    m = kind == TRIANGLE
    if m.any():
        k = index[m]
        V = rs.triangles[k].astype(t)
        Ng[m] = triangle_normal(V[:, 0], V[:, 1], V[:, 2])
        n = rs.triangle_normals[k].astype(t)
        u, v = uv[m, 0:1], uv[m, 1:2]
        Ns[m] = normalize_or_zero((t(1) - u - v) * n[:, 0] + u * n[:, 1] + v * n[:, 2])
        obj[m] = rs.triangle_object[k]
        _turn_normals(rs, m, obj, time, Ng, Ns)
    return P, Ng, Ns, obj


def _turn_normals(rs, hits, obj, time, Ng, Ns):
    """Turn the time-0 normals of the hits on moving meshes (in place) to their hits' times."""
    if time is None or rs.bvh is None:
        return
    for o in rs.mesh_object[rs.mesh_object >= 0]:
        on = hits & (obj == o)
        if on.any():
            m = motion_at(rs.motion.rows([o])[0], time[on])
            Ng[on], Ns[on] = motion_direction(m, Ng[on]), motion_direction(m, Ns[on])


def materials(rs, obj, specular: bool, dtype=F32) -> MaterialUniforms:
    return MaterialUniforms(rs.ka[obj].astype(dtype), rs.kd[obj].astype(dtype), rs.ks[obj].astype(dtype),
                            rs.n[obj].astype(dtype)[:, None], specular=specular)


def blocked_towards(rs, Q, P, Ng, shape, time=None):
    """Whether the shadow ray from each hit P (outward geometric normal Ng, on analytic shape
    `shape`) to the point Q (a point light, or a point of an area light; (3,) or one per hit)
    is blocked: from ray_origin(P, Ng on Q's side), towards Q (unit direction), s_max the
    distance less the hit tie, d (1 - HIT_TIE) (a surface through Q ties with the light, which
    keeps it); a light at the origin (d = 0) is not blocked (the GLSL's light_visibility_at).
    The scene at the hits' `time` (motion blur)."""
    n = np.where((_dot(Ng, Q - P) >= 0)[:, None], Ng, -Ng)
    O = ray_origin(P, n, shape)
    to_light = Q - O
    d = np.sqrt(_dot(to_light, to_light))
    with np.errstate(divide="ignore", invalid="ignore"):
        L = to_light / d[:, None]
    return occluded(rs, O, L, d * (d.dtype.type(1) - d.dtype.type(HIT_TIE)), shape, time) & (d > 0)


def shadow_visibility(rs, lights: Lights, Ng, shape, record=None, time=None):
    """The visibility callable of lighting.py for hits with outward geometric normals Ng on
    analytic shapes `shape` (shape_id): one shadow ray per point and light (the GLSL's
    light_visibility_directional / _point), at the hits' `time`; 0 without one where the facet,
    on the side of the lit normal N, is turned from the light (the facet rule, the GLSL's
    facet_turned_from; a blocked ray for the hash). `record(needed, event)`, if given, hears
    each shadow ray's outcome (ray_tree_event)."""
    t = Ng.dtype.type

    def visibility(kind, i, P, N, needed):
        blocked = np.zeros(len(P), bool)
        P, n, on = P[needed], Ng[needed], shape[needed]
        facet = np.where((_dot(n, N[needed]) >= 0)[:, None], n, -n)   # on the lit side
        if kind == "directional":
            L = normalize(-lights.u_directional_direction[i])
            turned = _dot(facet, np.broadcast_to(L, facet.shape)) < 0
            n = np.where((_dot(n, L) >= 0)[:, None], n, -n)
            O = ray_origin(P, n, on)
            blocked[needed] = turned | occluded(rs, O, np.broadcast_to(L, O.shape).astype(t), t(np.inf),
                                                on, _at(time, needed))
        else:
            turned = _dot(facet, lights.u_point_position[i] - P) < 0
            blocked[needed] = turned | blocked_towards(rs, lights.u_point_position[i], P, n, on,
                                                       _at(time, needed))
        if record is not None:
            light = i if kind == "directional" else len(lights.u_directional_direction) + i
            record(blocked, ray_tree_event(SHADOW, light))
        return np.where(blocked, t(0), t(1))[:, None]
    return visibility


def area_light_shadow(rs, lights: Lights, Ng, shape, record=None, time=None):
    """The `shadow` of area_lights.area_light_terms for hits with outward geometric normals
    Ng on analytic shapes `shape`, at the hits' `time`: shadow(i, m, Q, P, needed, N) ->
    whether the shadow ray from each hit (where `needed`) to point Q of light i's area is
    blocked (blocked_towards), or the facet on the lit normal N's side turned from Q (the facet
    rule); `record` hears each (the event of light l's m-th point: SHADOW,
    l + m * (number of lights))."""
    n_lights = len(lights.u_directional_direction) + len(lights.u_point_position)

    def shadow(i, m, Q, P, needed, N):
        blocked = np.zeros(len(P), bool)
        n = Ng[needed]
        facet = np.where((_dot(n, N[needed]) >= 0)[:, None], n, -n)      # the facet rule
        blocked[needed] = (_dot(facet, Q[needed] - P[needed]) < 0) | blocked_towards(
            rs, Q[needed], P[needed], n, shape[needed], _at(time, needed))
        if record is not None:
            light = len(lights.u_directional_direction) + i
            record(blocked, ray_tree_event(SHADOW, light + m * n_lights))
        return blocked
    return shadow


# -- the ray tree's hash ------------------------------------------------------------------------
# Which surface each ray of a camera ray's tree hit (or none), and which shadow rays were
# blocked, hashed into one uint64 per camera ray: two precisions that disagree on a grazing ray
# (a hit in one and a miss or another surface in the other; a shadow ray blocked in one only;
# one child spawned in one only) give different hashes (docs/conventions.md, "Grazing rays").
# A shadow ray not cast (its light adds nothing at the point) counts as not blocked: whether a
# term of 1e-50 underflows to 0 (float32) or not (float64) changes nothing one can see.
# Every ray has a path id (the root's ROOT_PATH; a child's the mix of its parent's and of
# which child it is); each event adds mix(path + event) to the sum, modulo 2^64, so that the
# order in which the rays are traced (the GLSL's depth first, the twin's wavefronts) does not
# matter. mix is splitmix64's finaliser (Steele, Lea and Flood 2014).
SHADOW = 4                    # event kinds: MISS, SPHERE, PLANE, TRIANGLE; SHADOW + blocked
ROOT_PATH = np.uint64(0x9E3779B97F4A7C15)


def mix64(z):
    z = np.asarray(z, np.uint64)
    with np.errstate(over="ignore"):                 # products modulo 2^64, as meant
        z = (z ^ (z >> np.uint64(30))) * np.uint64(0xBF58476D1CE4E5B9)
        z = (z ^ (z >> np.uint64(27))) * np.uint64(0x94D049BB133111EB)
    return z ^ (z >> np.uint64(31))


def ray_tree_event(kind, index):
    """The uint64 event of a ray that hit surface (kind, index), or of a shadow ray."""
    kind = np.asarray(kind, np.uint64)
    return (kind << np.uint64(32)) | (np.asarray(index, np.int64) & 0xFFFFFFFF).astype(np.uint64)


def trace(rs, lights: Lights, O, D, s_min, s_max, background, max_depth: int, shadows: bool = True,
          ray_trees=None, samples=None, areas=None, time=None):
    """Trace rays O, D (R, 3): (colour (R, 3), hit (R,), s (R,)) with hit and s of each ray's
    first hit (primary rays between s_min and s_max; secondary rays from 0 to inf). float32 as
    the GLSL, or float64 for float64 rays (and then `lights` in float64). shadows=False lights
    every point by every light (no shadow rays; the GLSL without SHADOWS). `ray_trees`, an
    (R,) uint64 array, has each ray tree's hash added to it (the comment above). `samples`, a
    sampling.RaySamples of the R camera rays, says whose numbers each hit draws (the
    distributed effects); each ray of a tree carries its key (the GLSL's g_ray_key: the camera
    ray 0, the reflected child of r 2r + 1, the transmitted 2r + 2, as uint32). `areas`, the
    u_point_area rows of renderer/core/light_areas.py (None: no light declares an area), makes
    the point lights with an area area lights (area_light_terms; `samples` then required).
    Motion blur: each camera ray's time (`time` (R,), else drawn from `samples`: sample_times),
    which its secondary and shadow rays share.
    A secondary ray is spawned only when some channel of its weight is at least
    RAY_WEIGHT_CUTOFF (renderer/core/ray_depth.py)."""
    t = np.asarray(O).dtype.type if np.asarray(O).dtype == np.float64 else F32
    O = np.asarray(O, t)
    D = np.asarray(D, t)
    R = len(O)
    time = sample_times(rs, samples, R, t) if time is None else np.asarray(time, t)
    colour = np.zeros((R, 3), t)
    background = np.asarray(background, t)
    specular = rs.specular
    owner = np.arange(R)
    from_shape = np.full(R, -1)
    path = np.full(R, ROOT_PATH, np.uint64)
    key = np.zeros(R, np.uint32)
    weight = np.ones((R, 3), t)
    first_hit, first_s = None, None
    lo, hi = t(s_min), t(s_max)
    trees = np.zeros(R, np.uint64) if ray_trees is None else ray_trees

    def record(rays, event):
        np.add.at(trees, owner[rays], mix64(path[rays] + mix64(event)))

    for depth in range(max_depth + 1):
        if not len(O):
            break
        kind, index, s, uv = scene_hit(rs, O, D, lo, hi, from_shape, _at(time, owner))
        record(slice(None), ray_tree_event(kind, index))
        hit = kind != MISS
        if depth == 0:
            first_hit, first_s = hit.copy(), s.copy()
        np.add.at(colour, owner[~hit], weight[~hit] * background)
        O, D, kind, index, s, uv, owner, path, key, weight = (
            a[hit] for a in (O, D, kind, index, s, uv, owner, path, key, weight))
        P, Ng, Ns, obj = surface(rs, O, D, kind, index, s, uv, _at(time, owner))
        shape = shape_id(rs, kind, index)
        Du = normalize(D)
        back = _dot(Du, Ng) > 0
        N = np.where((back & rs.two_sided[obj])[:, None], -Ns, Ns)
        area_light = None if areas is None else area_light_terms(
            lights, areas, AreaDraw(samples, owner, key),
            area_light_shadow(rs, lights, Ng, shape, record, _at(time, owner)) if shadows else None)
        mats = materials(rs, obj, specular, t)
        if rs.textures is not None:     # the texel multiplies the coefficients it modulates
            mats = texture_modulate(rs, mats, obj, kind, index, P, uv, _at(time, owner))
        local = lighting(P, N, O, mats, lights,
                         shadow_visibility(rs, lights, Ng, shape, record, _at(time, owner))
                         if shadows else None,
                         area_light)
        np.add.at(colour, owner, weight * local)
        if depth == max_depth:
            break
        # secondary rays, down to the weight cut-off
        N_in = np.where(back[:, None], -Ns, Ns)
        Ng_in = np.where(back[:, None], -Ng, Ng)
        ior = rs.ior[obj].astype(t)
        eta = np.where(back, ior, t(1) / ior)
        F = np.where(rs.fresnel_exact[obj], fresnel_exact(Du, N_in, eta),
                     fresnel_schlick(Du, N_in, eta))[:, None]
        kr, kt = rs.kr[obj].astype(t), rs.kt[obj].astype(t)
        w_r = weight * (kr + kt * F)
        w_t = weight * (kt * transmitted_share(rs, F, eta))
        refracted, T = ray_refract(Du, N_in, eta)
        go_r = w_r.max(-1) >= RAY_WEIGHT_CUTOFF
        go_t = (w_t.max(-1) >= RAY_WEIGHT_CUTOFF) & refracted
        D_r = ray_reflect(Du[go_r], N_in[go_r])
        if rs.gloss_set:        # the lobe's code wherever a material sets gloss, inf included
            D_r, go_r = glossy_rays(rs.gloss, samples, D_r, go_r, Ng_in, obj, owner, key)
        O = np.concatenate([ray_origin(P[go_r], Ng_in[go_r], shape[go_r]),
                            ray_origin(P[go_t], -Ng_in[go_t], shape[go_t])])
        D = np.concatenate([D_r, T[go_t]]).astype(t)
        owner = np.concatenate([owner[go_r], owner[go_t]])
        from_shape = np.concatenate([shape[go_r], shape[go_t]])
        path = np.concatenate([mix64(path[go_r] ^ np.uint64(1)), mix64(path[go_t] ^ np.uint64(2))])
        with np.errstate(over="ignore"):                 # keys wrap modulo 2^32, as the GLSL's
            key = np.concatenate([np.uint32(2) * key[go_r] + np.uint32(1),
                                  np.uint32(2) * key[go_t] + np.uint32(2)])
        weight = np.concatenate([w_r[go_r], w_t[go_t]])
        lo, hi = leaving_s_min(O), t(np.inf)
    return colour, first_hit, first_s
