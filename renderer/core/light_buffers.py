"""Radiosity's light from the scene's point and directional lights (issue 33): the light buffer
(Haines and Greenberg, "The Light Buffer: A Shadow-Testing Accelerator", IEEE CG&A 1986), an
item buffer drawn from the light, read the way Cohen et al. 1988 shoot a patch's light through
its hemicube. One definition for the GPU path and its twin: both draw these views with their
item buffers (renderer/gpu/item_buffers.py ItemBuffers.views, reference/radiosity/item_buffer.py
draw_views), this module weighs the pixels alike, so identical item buffers give identical light.

The equation radiosity solves is then (renderer/core/radiosity.py)

    B_i = E_i + rho_i (H_i + sum_j F_ij B_j)

with H_i the element's mean direct irradiance in the Phong model's units: the mean over the
element of what the lighting equation multiplies k_d by, I cos(theta) att(d), with the light's
visibility (its shadows).

A point light (or each point q of its area's grid, `area_points`) sees the elements through the
six faces of a cube around it (CUBE_FACES), each `resolution` pixels square. The pixel whose
centre lies in direction w on the unit cube, of solid angle dw = (2 / N)^2 / |p|^3 (p the centre
on the face), lands on the element seen there at distance d along w (from the element's plane);
the element's area it covers is d^2 dw / cos(theta), so it brings the element

    I e(w) att(d) d^2 dw                   (the light's power through the pixel, Phong units)

with e(w) the area's emission (1 for a point; a planar area's one-sided Lambert cosine; a
sphere's 4 cos, light_areas.py), and H_j is their sum over element j's front pixels over A_j.
Under inverse-square fall-off att(d) d^2 = 1: a surface's total is I times the solid angle it
subtends, its closed form (tests/test_radiosity_lights.py). A directional light sees the
elements through one parallel view along its direction, a square 2R across (R half the elements'
bounding diagonal): each pixel of area a = (2R / N)^2 brings I a (irradiance I cos over the area
a / cos).

Pixels are point samples: an element smaller than a few pixels of the view gets its light by
chance (the hemicube's aliasing, docs/radiosity.md); `resolution` (--light-buffer) is the knob.
"""

from __future__ import annotations

from dataclasses import dataclass
from functools import lru_cache
from typing import Callable

import numpy as np

from renderer.core.hemicube import (FACES, ITEM_BACK_BIT, ITEM_INDEX_MASK, Face, depth_range,
                                    face_views, pixel_centres, projection)
from renderer.core.light_areas import area_axes
from renderer.core.transforms import fallback_up, look_at, orthographic

# The six faces of a point light's cube: the hemicube's five around +z, and -z.
CUBE_FACES = FACES + (Face("bottom", (0, 0, -1), (0, 1, 0)),)
# A directional light's view stands this many bounding radii from the elements' centre.
PARALLEL_DISTANCE = 2.0


@dataclass(frozen=True)
class LightSource:
    """One source the light buffer is drawn from: a point light's point (its position, or a
    point of its area's grid, with its share 1 / k^2 of the intensity) or a directional light."""
    kind: str                              # "point" or "directional"
    where: tuple                           # a point's position; a directional light's unit direction
    intensity: tuple                       # RGB, the point's share
    attenuation: tuple = (1.0, 0.0, 0.0)   # 1 / (c + l d + q d^2)
    emitter: tuple | None = None           # an area point's emitting normal (None: isotropic)
    emitter_scale: float = 1.0             # 1 on a planar area, 4 on a sphere's (light_areas.py)


def area_points(area, samples: int) -> tuple[np.ndarray, np.ndarray | None, float]:
    """(points (k^2, 3) offsets from the light's centre, normals (k^2, 3) or None, scale) of a
    light's area at `samples` = k points a side, the midpoints of a k x k grid of the unit square
    mapped so that each point stands for an equal area: a rectangle's (2u - 1) along its axes; a
    disc's polar grid r = sqrt(u0), phi = 2 pi u1; a sphere's z = 1 - 2 u0, phi = 2 pi u1
    (Archimedes: equal areas). An area of no size is its centre alone, isotropic."""
    if area is None or not area.has_size:
        return np.zeros((1, 3)), None, 1.0
    k = int(samples)
    u0, u1 = np.meshgrid((np.arange(k) + 0.5) / k, (np.arange(k) + 0.5) / k, indexing="ij")
    u0, u1 = u0.ravel(), u1.ravel()
    axes = area_axes(area)
    if area.shape == "sphere":
        z = 1.0 - 2.0 * u0
        s = np.sqrt(np.maximum(0.0, 1.0 - z * z))
        unit = np.stack([s * np.cos(2 * np.pi * u1), s * np.sin(2 * np.pi * u1), z], axis=1)
        return unit @ axes, unit, 4.0
    if area.shape == "disc":
        r = np.sqrt(u0)
        p = np.stack([r * np.cos(2 * np.pi * u1), r * np.sin(2 * np.pi * u1)], axis=1)
    else:
        p = np.stack([2 * u0 - 1, 2 * u1 - 1], axis=1)
    normal = np.asarray(area.normal, np.float64)
    normal = normal / np.linalg.norm(normal)
    return p @ axes[:2], np.broadcast_to(normal, (k * k, 3)), 1.0


def light_sources(scene, area_samples: int) -> tuple[LightSource, ...]:
    """The scene's lights as light-buffer sources (a light of zero intensity left out)."""
    sources = []
    for light in scene.point_lights:
        if not any(float(c) for c in light.intensity):
            continue
        offsets, normals, scale = area_points(light.area, area_samples)
        share = tuple(float(c) / len(offsets) for c in light.intensity)
        for m, offset in enumerate(offsets):
            sources.append(LightSource(
                "point", tuple(float(c) for c in np.asarray(light.position, np.float64) + offset), share,
                tuple(float(c) for c in light.attenuation),
                None if normals is None else tuple(float(c) for c in normals[m]), scale))
    for light in scene.directional_lights:
        direction = np.asarray(light.direction, np.float64)
        if not any(float(c) for c in light.intensity) or not np.linalg.norm(direction) > 0:
            continue
        sources.append(LightSource("directional", tuple(float(c) for c in direction / np.linalg.norm(direction)),
                                   tuple(float(c) for c in light.intensity)))
    return tuple(sources)


def views(source: LightSource, elements) -> np.ndarray:
    """(F, 4, 4) float64: the clip_from_world of each view the source sees the elements through
    (six cube faces at a point, one parallel view for a directional light), of positions
    relative to the elements' centre (as the item buffers hold them); reversed-Z as the
    hemicube's (hemicube.DEPTH_MAPPING)."""
    origin, diameter = elements.extent()
    radius = max(diameter / 2, np.finfo(float).tiny)
    edge = elements.shortest_edge()
    if source.kind == "point":
        q = np.asarray(source.where, np.float64)
        near, _ = depth_range(edge, diameter)
        far = 2.0 * (np.linalg.norm(q - origin) + radius) + edge
        return projection(near, far) @ face_views(np.eye(3)[None], q[None], origin, CUBE_FACES)[0]
    forward = np.asarray(source.where, np.float64)
    distance = PARALLEL_DISTANCE * radius
    view = look_at(-forward * distance, np.zeros(3), fallback_up(forward))     # eye at -forward 2R
    parallel = orthographic(2 * radius, 1.0, distance - 1.5 * radius, distance + 1.5 * radius, reversed_z=True)
    return (parallel @ view)[None]


@lru_cache(maxsize=4)
def _point_weights(resolution: int) -> tuple[np.ndarray, np.ndarray]:
    """(6 N N, 3) unit directions of the cube's pixel centres, world axes, and (6 N N,) their
    solid angles (2 / N)^2 / |p|^3, in CUBE_FACES' order, row 0 at the top (read-only: cached)."""
    centres = np.stack([pixel_centres(face, resolution, rows=resolution) for face in CUBE_FACES]).reshape(-1, 3)
    length = np.linalg.norm(centres, axis=-1)
    directions, solid_angles = centres / length[:, None], (2.0 / resolution) ** 2 / length ** 3
    directions.flags.writeable = solid_angles.flags.writeable = False
    return directions, solid_angles


def power(source: LightSource, elements, items: np.ndarray) -> np.ndarray:
    """(E, 3): the power the source brings each element's front, from its views' item buffers
    `items` (F, N, N), row 0 at the top (module docstring)."""
    count, resolution = len(elements), items.shape[-1]
    flat = items.reshape(len(items), -1)
    index = (flat & ITEM_INDEX_MASK).astype(np.int64) - 1
    front = (index >= 0) & ((flat & ITEM_BACK_BIT) == 0)
    intensity = np.asarray(source.intensity, np.float64)
    if source.kind == "directional":
        _, diameter = elements.extent()
        pixel_area = (max(diameter, np.finfo(float).tiny) / resolution) ** 2       # (2R / N)^2
        seen = np.bincount(index[front], minlength=count).astype(np.float64)
        return seen[:, None] * pixel_area * intensity
    directions, solid_angles = _point_weights(resolution)
    front = front.ravel()
    directions, solid_angles = directions[front], solid_angles[front]
    j = index.ravel()[front]
    q = np.asarray(source.where, np.float64)
    normal = elements.normals[j]
    # distance along w to the element's plane, at most to its farthest corner (grazing pixels)
    d = ((elements.centres[j] - q) * normal).sum(axis=1) / np.minimum((directions * normal).sum(axis=1), -1e-300)
    farthest = np.linalg.norm(elements.corners - q, axis=2).max(axis=1)
    d = np.clip(d, 0.0, farthest[j])
    c, l, s = source.attenuation
    weight = solid_angles * d * d / (c + l * d + s * d * d)
    if source.emitter is not None:
        weight = weight * source.emitter_scale * np.maximum(0.0, directions @ np.asarray(source.emitter, np.float64))
    return np.bincount(j, weights=weight, minlength=count)[:, None] * intensity


def irradiance(elements, sources, draw_views: Callable[[np.ndarray], np.ndarray],
               keep: list | None = None) -> np.ndarray:
    """(E, 3) float64: each element's mean direct irradiance H (module docstring) from `sources`,
    each source's views drawn by `draw_views(matrices)` (the item buffers (F, N, N), row 0 at
    the top: the GPU's ItemBuffers.views or the twin's). `keep`, a list: the LightSurfaces of
    the same draws appended to it (the specular term's shadows), no view drawn twice."""
    total = np.zeros((len(elements), 3))
    drawn = []
    for source in sources:
        these = views(source, elements)
        items = draw_views(these)
        total += power(source, elements, items)
        if keep is not None:
            drawn.append((these, surfaces_seen(items, elements.obj)))
    if keep is not None:
        keep.append(_kept(elements, drawn))
    return total / elements.areas[:, None]


@dataclass(frozen=True)
class LightSurfaces:
    """What each source's light buffer saw, kept for radiosity's direct specular term (its
    shadows: glsl/radiosity/specular.glsl, reference/radiosity/specular.py): per view, which
    object's front each pixel saw. A fragment of object o is lit by a source where the pixel of
    the source's view under it saw o's front: objects, not elements, are compared, so that an
    element's neighbour on the same surface does not shadow it (a surface cannot shadow itself
    where its normal faces the light, save a concave mesh's folds, which this leaves lit).

    `matrices` (V, 4, 4) float64 are clip_from_world of positions relative to `origin` (the
    elements' centre, as views() makes them); `surfaces` (V, N, N) uint32, row 0 at the top,
    hold object + 1 where the pixel saw that object's front, else 0; `counts` (S,) the views of
    each source in `sources`' order (six at a point, one for a directional light)."""
    origin: np.ndarray
    matrices: np.ndarray
    surfaces: np.ndarray
    counts: tuple

    @property
    def nbytes(self) -> int:
        return int(self.surfaces.nbytes)


def surfaces_seen(items: np.ndarray, obj: np.ndarray) -> np.ndarray:
    """(F, N, N) uint32: object + 1 where a pixel of item buffers `items` saw an element's front
    (`obj` (E,) each element's object), 0 where it saw nothing or a back."""
    index = (items & ITEM_INDEX_MASK).astype(np.int64) - 1
    front = (index >= 0) & ((items & ITEM_BACK_BIT) == 0)
    owner = np.concatenate([np.asarray(obj, np.int64) + 1, [0]]).astype(np.uint32)
    return np.where(front, owner[np.where(front, index, -1)], np.uint32(0)).astype(np.uint32)


def light_surfaces(elements, sources, draw_views: Callable[[np.ndarray], np.ndarray]) -> LightSurfaces:
    """The LightSurfaces of `sources` seeing `elements`, each source's views drawn by
    `draw_views(matrices)` (as irradiance's)."""
    drawn = []
    for source in sources:
        these = views(source, elements)
        drawn.append((these, surfaces_seen(draw_views(these), elements.obj)))
    return _kept(elements, drawn)


def _kept(elements, drawn: list) -> LightSurfaces:
    """The LightSurfaces of [(matrices (F, 4, 4), surfaces (F, N, N))], a pair per source."""
    return LightSurfaces(elements.extent()[0], np.concatenate([m for m, _ in drawn]),
                         np.concatenate([s for _, s in drawn]), tuple(len(m) for m, _ in drawn))
