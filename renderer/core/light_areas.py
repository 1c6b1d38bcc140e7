"""Area lights for the ray tracer (docs/conventions.md, "Area lights"): what both twins read
about each point light's area (renderer/core/scene.py, LightArea); the points per hit,
`light_samples`, are the sampling rule's (renderer/core/ray_sampling.py). The rasteriser reads
none of it: it lights from each light's centre.

A point of light i's area is q = Q_i + p.x a_0 + p.y a_1 + p.z a_2, with Q_i the light's
position (u_point_position) and p the point of the unit shape at the sample's u in [0, 1)^2:

    rectangle   p = (2 u0 - 1, 2 u1 - 1, 0)      a_0 = w/2 b1, a_1 = h/2 b2, a_2 = 0
    disc        p = (square_to_disc(u), 0)       a_0 = r b1,   a_1 = r b2,   a_2 = 0
    sphere      p = square_to_sphere(u)          a_j = r e_j (the world axes)

b1, b2 the orthonormal basis of the unit normal (`orthonormal_basis`: Duff et al., JCGT 6(1)
2017, the formula of glsl/raytrace/warp.glsl's, here in float64 once per light). The axes are
the uniform `u_point_area` (AREA_UNIFORM): rows 3i .. 3i + 2 are (a_j, 0), and row 3i's w is
the light's shape code (AREA_SHAPE_CODES; 0 for a light without an area, which keeps the
point light's code). An area of size 0 has a = 0, so q = Q_i exactly: p is finite and
0 p = 0.

Emission (docs/conventions.md, "Area lights"): an area with a size is a one-sided Lambertian
emitter. Row 3i + 1's w is 1 for it (LAMBERTIAN; 0 for an area of size 0, the isotropic point
light); a rectangle's or disc's row 3i + 2 holds its unit normal n instead of a_2 = 0 (its
points have p.z = 0, so the offset is the same), and its point q shines I cos(n, P - q) on the
side n faces, none behind; a sphere's point p shines 4 I cos(p, P - q) outward (4: the mean of
the positive cosine over the sphere is 1/4, so that far away it is the point light).
"""

from __future__ import annotations

import numpy as np

from renderer.core.scene import AREA_SHAPES, LightArea, Scene

# The shapes' codes in the uniform (and the GLSL's AREA_RECTANGLE, AREA_DISC, AREA_SPHERE).
AREA_SHAPE_CODES = {shape: code for code, shape in enumerate(AREA_SHAPES, start=1)}
NO_AREA = 0
AREA_UNIFORM = "u_point_area"          # vec4[3 * NUM_POINT_LIGHTS]
LAMBERTIAN = 1.0                       # row 3i + 1's w: the area is a Lambertian emitter
def orthonormal_basis(n) -> tuple[np.ndarray, np.ndarray]:
    """(b1, b2) completing the unit vector n to a right-handed orthonormal basis (b1, b2, n):
    Duff, Burgess, Christensen, Hery, Kensler, Liani and Villemin, "Building an Orthonormal
    Basis, Revisited", JCGT 6(1) 2017, listing 3, in float64, with n.z = 0 counting as
    positive as in warp.glsl's. n = (0, -1, 0), the default normal, gives b1 = (1, 0, 0),
    b2 = (0, 0, 1)."""
    x, y, z = (float(c) for c in n)
    sign = 1.0 if z >= 0.0 else -1.0
    a = -1.0 / (sign + z)
    b = x * y * a
    return (np.array([1.0 + sign * x * x * a, sign * b, -sign * x]),
            np.array([b, sign + y * y * a, -y]))


def area_axes(area: LightArea | None) -> np.ndarray:
    """(3, 3) float64: the axes a_0, a_1, a_2 (rows) of the module docstring; zero for None."""
    axes = np.zeros((3, 3))
    if area is None:
        return axes
    if area.shape == "sphere":
        return float(area.radius) * np.eye(3)
    normal = np.asarray(area.normal, dtype=np.float64)
    b1, b2 = orthonormal_basis(normal / np.linalg.norm(normal))
    half = (0.5 * float(area.size[0]), 0.5 * float(area.size[1])) if area.shape == "rectangle" \
        else (float(area.radius),) * 2
    axes[0], axes[1] = half[0] * b1, half[1] * b2
    return axes


def area_light_uniforms(scene: Scene) -> dict[str, np.ndarray]:
    """{AREA_UNIFORM: (3 Lp, 4) float64}: each point light's axes, shape code, normal and
    emission (module docstring); no rows when the scene has no point light."""
    rows = np.zeros((3 * len(scene.point_lights), 4))
    for i, light in enumerate(scene.point_lights):
        rows[3 * i:3 * i + 3, :3] = area_axes(light.area)
        rows[3 * i, 3] = NO_AREA if light.area is None else AREA_SHAPE_CODES[light.area.shape]
        if light.area is not None and light.area.shape != "sphere":
            normal = np.asarray(light.area.normal, np.float64)
            rows[3 * i + 2, :3] = normal / np.linalg.norm(normal)
        if light.area is not None and light.area.has_size:
            rows[3 * i + 1, 3] = LAMBERTIAN
    return {AREA_UNIFORM: rows}


def declares_area_lights(scene: Scene) -> bool:
    """Whether some point light has an area, of any size (the twin then samples it)."""
    return any(light.area is not None for light in scene.point_lights)


def uses_area_lights(scene: Scene) -> bool:
    """Whether some point light has an area of size > 0 (the GLSL then compiles AREA_LIGHTS in)."""
    return any(light.area is not None and light.area.has_size for light in scene.point_lights)
