"""# Twin: glsl/raytrace/area_lights.glsl

Area lights, the ray tracer's soft shadows (docs/conventions.md, "Area lights"), vectorised over
hits: the points of a light's area (`area_light_point`, from the u_point_area rows of
renderer/core/light_areas.py), the light's term averaged over M = light_samples of them
(`area_light_terms`, the area_light hook of reference/lighting.py's `lighting`), and whose
numbers each hit draws (`AreaDraw`: distributed_2d at the hit's slot). trace.py casts the
shadow rays (area_light_shadow).
"""

from __future__ import annotations

import numpy as np

from reference.lighting import Lights, point_term_at
from reference.raytrace.warp import square_to_disc, square_to_sphere
from renderer.core.light_areas import AREA_SHAPE_CODES, NO_AREA
from renderer.core.ray_sampling import LIGHT_DIMENSION


def area_light_point(areas, i: int, centre, u) -> np.ndarray:
    """(R, 3) points of point light i's area at u (R, 2) in [0, 1)^2, in centre's dtype (the
    GLSL's area_light_point): centre + p.x a_0 + p.y a_1 + p.z a_2 with p = (2u - 1, 0) on a
    rectangle, (square_to_disc(u), 0) on a disc, square_to_sphere(u) on a sphere; `areas` the
    (3 Lp, 4) u_point_area rows, `centre` the light's position (3,)."""
    t = centre.dtype.type
    u = np.asarray(u).astype(t)
    shape = areas[3 * i, 3]
    if shape == AREA_SHAPE_CODES["rectangle"]:
        p = np.concatenate([t(2) * u - t(1), np.zeros((len(u), 1), t)], -1)
    elif shape == AREA_SHAPE_CODES["disc"]:
        p = np.concatenate([square_to_disc(u), np.zeros((len(u), 1), t)], -1)
    else:
        p = square_to_sphere(u)
    a = areas[3 * i:3 * i + 3, :3].astype(t)
    offset = p[:, 0:1] * a[0] + p[:, 1:2] * a[1] + p[:, 2:3] * a[2]
    return centre + offset


def area_emission(areas, i: int, u, Q, P) -> np.ndarray:
    """(R,) Lambert's cosine law at points Q (R, 3) of light i's area drawn at u, towards P
    (the GLSL's area_emission): the cosine between the emitting normal (a rectangle's or disc's
    unit normal, row 3i + 2; a sphere's point square_to_sphere(u), times 4) and P - Q, 0
    behind; 1 for an area of size 0 (row 3i + 1's w 0: the isotropic point light)."""
    t = Q.dtype.type
    if areas[3 * i + 1, 3] == 0:
        return np.ones(len(Q), t)
    planar = areas[3 * i, 3] in (AREA_SHAPE_CODES["rectangle"], AREA_SHAPE_CODES["disc"])
    n = np.broadcast_to(areas[3 * i + 2, :3].astype(t), Q.shape) if planar else \
        square_to_sphere(np.asarray(u).astype(t))
    to_P = P - Q
    c = n[:, 0] * to_P[:, 0] + n[:, 1] * to_P[:, 1] + n[:, 2] * to_P[:, 2]
    length = np.sqrt(to_P[:, 0] * to_P[:, 0] + to_P[:, 1] * to_P[:, 1] + to_P[:, 2] * to_P[:, 2])
    with np.errstate(divide="ignore", invalid="ignore"):
        c = np.where(c > 0, c / length, t(0))
    return c if planar else t(4) * c


def area_light_terms(lights: Lights, areas, draw, shadow=None):
    """The area_light callable of lighting.py (the GLSL's has_area and area_light_term): for
    point light i with an area (row 3i's w not NO_AREA), the mean of point_term_at(q_m) times
    area_emission(q_m) over
    its M points q_m = area_light_point(u_m), u_m = draw(i, m), each times the visibility of
    q_m (shadow(i, m, q_m, P, needed, N) -> blocked per hit, asked only where the term is not 0;
    None: no shadow rays), summed in m order; None for a light without an area."""
    M = draw.light_samples

    def area_light(i, P, N, V, material):
        if areas[3 * i, 3] == NO_AREA:
            return None
        t = P.dtype.type
        total = np.zeros(P.shape, t)
        for m in range(M):
            u = draw(i, m)
            Q = area_light_point(areas, i, lights.u_point_position[i], u)
            term = point_term_at(P, N, V, Q, lights.u_point_intensity[i], lights.u_point_attenuation[i],
                                 material) * area_emission(areas, i, u, Q, P)[:, None]
            if shadow is not None:
                blocked = shadow(i, m, Q, P, (term != 0).any(-1), N)
                term = np.where(blocked, t(0), t(1))[:, None] * term
            total += term
        return total / t(M)
    return area_light


class AreaDraw:
    """draw(i, m): the u of point m of light i's area at each hit of the camera rays `owner`,
    rays `key` (distributed_2d at slot 1 + key, dimension LIGHT_DIMENSION + i, m of M)."""

    def __init__(self, samples, owner, key):
        self.samples, self.owner, self.light_samples = samples, owner, samples.sampling.light_samples
        with np.errstate(over="ignore"):                 # slots wrap modulo 2^32, as the GLSL's
            self.slot = np.uint32(1) + key

    def __call__(self, i: int, m: int) -> np.ndarray:
        return self.samples.point_2d(self.owner, self.slot, LIGHT_DIMENSION + i, m, self.light_samples)
