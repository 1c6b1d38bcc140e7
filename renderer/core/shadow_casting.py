"""Which casters can shadow which receivers for a light: the rule the shadow planning
(renderer/core/shadows.py) leaves passes and casters out by (docs/conventions.md, "Shadows",
"Which lights, which objects").

A pair (caster c, receiver r) is kept unless c provably cannot shadow any point of r that
faces the light (N.L > 0, where the lookup is made at all). Conservative: True when unsure.
c cannot shadow r when

- c is **planar** (its vertices on one plane, `plane_of`): the light grazes the plane (it casts
  no shadow of any area), or r is c itself, or every point of r lies on the light's side of the
  plane (a floor under the lit objects shadows only what lies below it);
- c is a **convex solid** (renderer/core/convexity.py: a closed convex mesh; a sphere's
  tessellation is one) and r is c itself, where the light is inside the solid (every point of
  its boundary sees the light directly), or where the lit side is the outside (one-sided
  material with outward normals: a point whose outward normal faces the light is not behind
  the solid);
- c is a convex solid with a point light inside it and every point of r lies inside it too (a
  room's box around the lamp and the objects in the room);
- the light is directional and, across the light, r's bounding box and c's do not meet, or all
  of r lies nearer the light than all of c (a parallel light's shadow falls within its
  caster's box across the light, behind the caster).

Coordinates: any one world frame for points, models and the light (camera-relative world in a
frame's plan, absolute world for the scene-level question `light_can_shadow`).
"""

from __future__ import annotations

import numpy as np

from renderer.core import transforms
from renderer.core.convexity import ConvexBody, convex_body

# A caster's vertices within PLANAR_TOLERANCE of its extent from one plane make it planar.
PLANAR_TOLERANCE = 1e-9


def plane_of(points: np.ndarray):
    """(unit normal, a point) of the plane the points lie in, or None when they do not."""
    if len(points) < 3:
        return None
    centre = points.mean(axis=0)
    _, singular, rows = np.linalg.svd(points - centre, full_matrices=False)
    if singular[0] == 0.0 or singular[-1] > PLANAR_TOLERANCE * singular[0]:
        return None
    return rows[-1], centre


class Occluders:
    """The pair rule over one scene's objects: `points[i]` object i's vertices (V, 3) and
    `models[i]` its model matrix, in one world frame. Each caster's plane and convex solid are
    found once, for every light asked about."""

    def __init__(self, scene, points: list[np.ndarray], models: list[np.ndarray]):
        self.scene, self.points, self.models = scene, points, models
        self._planes: dict[int, object] = {}
        self._bodies: dict[int, ConvexBody | None] = {}
        self._scale_array: np.ndarray | None = None

    def plane(self, i: int):
        if i not in self._planes:
            self._planes[i] = plane_of(self.points[i])
        return self._planes[i]

    def body(self, i: int) -> ConvexBody | None:
        if i not in self._bodies:
            self._bodies[i] = None if self.plane(i) is not None else convex_body(self.scene.objects[i].mesh)
        return self._bodies[i]

    def _scale(self, i: int) -> float:
        return float(self._scales()[i])

    def _scales(self) -> np.ndarray:
        """(objects,) each object's planar tolerance, PLANAR_TOLERANCE (1 + its largest |coordinate|)."""
        if self._scale_array is None:
            self._scale_array = np.array([PLANAR_TOLERANCE * (1.0 + (float(np.abs(p).max()) if len(p) else 0.0))
                                          for p in self.points])
        return self._scale_array

    def _stacked(self, objects: np.ndarray):
        """(points (V, 3), starts (n,)) of the objects' points in one array, for reductions
        per object (np.logical_or.reduceat)."""
        counts = np.array([len(self.points[i]) for i in objects], np.int64)
        points = np.concatenate([self.points[i] for i in objects]) if len(objects) else np.zeros((0, 3))
        return points, np.concatenate([[0], np.cumsum(counts)[:-1]])

    def pairs(self, casters: list[int], receivers: list[int], light_position=None,
              light_direction=None, first: bool = False) -> dict[int, list[int]]:
        """caster -> the receivers (in `receivers`' order) it can shadow, for a point light at
        `light_position` or a directional one travelling along `light_direction`; casters that
        can shadow none are left out. Each caster's receivers are decided at once (arrays over
        the receivers), so that a scene of thousands of objects stays quick. `first`: stop at
        the first caster that can shadow something (whether any can)."""
        rec = np.asarray(list(receivers), np.int64)
        rec = rec[np.array([len(self.points[r]) > 0 for r in rec], bool)] if len(rec) else rec
        boxes = None if light_direction is None else self._light_boxes(
            sorted({*casters, *rec.tolist()}), light_direction)
        stacked = None
        out = {}
        for c in casters:
            plane = self.plane(c)
            if plane is not None or (self.body(c) is not None and light_position is not None):
                stacked = stacked if stacked is not None else self._stacked(rec)
            ok = self._shadowable(c, rec, light_position, light_direction, boxes, stacked)
            if ok.any():
                out[c] = rec[ok].tolist()
                if first:
                    break
        return out

    def can_shadow(self, c: int, r: int, light_position=None, light_direction=None) -> bool:
        """Whether caster c can shadow receiver r (the module docstring's rule)."""
        return bool(self.pairs([c], [r], light_position, light_direction))

    def _shadowable(self, c: int, rec: np.ndarray, light_position, light_direction, boxes,
                    stacked) -> np.ndarray:
        """(R,) bool: caster c can shadow each of the receivers `rec` (the module's rule)."""
        ok = np.ones(len(rec), bool)
        plane = self.plane(c)
        if plane is not None:
            return (rec != c) & self._below_plane(c, plane, light_position, light_direction, stacked)
        body = self.body(c)
        if body is not None:
            inside = light_position is not None and bool(
                body.contains(np.asarray(light_position)[None], self.models[c])[0])
            outside_lit = body.normals_outward is True and not self.scene.objects[c].material.two_sided
            if inside or outside_lit:
                ok &= rec != c
            if inside:                     # only what reaches outside the solid around the light
                points, starts = stacked
                out = ~body.contains(points, self.models[c]) if len(points) else np.zeros(0, bool)
                ok &= np.logical_or.reduceat(out, starts) if len(points) else False
        if light_direction is not None:
            ok &= (rec == c) | self._across_light_meet(c, rec, boxes)
        return ok

    def _light_boxes(self, objects, light_direction) -> np.ndarray:
        """(objects in the scene, 2, 3): each of `objects`' vertices' least and greatest
        (x, y, depth) in the directional light's frame (light_frame); NaN for the others."""
        rotation = light_rotation(light_direction)
        out = np.full((len(self.points), 2, 3), np.nan)
        for i in objects:
            if len(self.points[i]):
                out[i] = bounds(light_frame(self.points[i], rotation))
        return out

    def _below_plane(self, c, plane, light_position, light_direction, stacked) -> np.ndarray:
        """(R,) bool: some point of each receiver lies beyond planar caster c's plane from the
        light (all False where the light grazes the plane: no shadow of any area)."""
        points, starts = stacked
        normal, origin = plane
        scale = self._scale(c)
        if light_position is not None:
            side = float(normal @ (np.asarray(light_position) - origin))
        else:
            side = -float(normal @ np.asarray(light_direction, dtype=np.float64))
        if abs(side) <= scale or not len(points):
            return np.zeros(len(starts), bool)
        facing = normal if side > 0 else -normal
        return np.logical_or.reduceat((points - origin) @ facing < -scale, starts)

    def _across_light_meet(self, c: int, rec: np.ndarray, boxes: np.ndarray) -> np.ndarray:
        """(R,) bool, directional light (boxes from _light_boxes): each receiver's box across
        the light meets caster c's, and some of the receiver lies deeper than c's nearest."""
        caster, theirs = boxes[c], boxes[rec]
        slack = self._scale(c) + self._scales()[rec]
        apart = (np.any(caster[1, :2] < theirs[:, 0, :2] - slack[:, None], axis=1)
                 | np.any(theirs[:, 1, :2] < caster[0, :2] - slack[:, None], axis=1))
        return ~apart & (theirs[:, 1, 2] > caster[0, 2] - slack)


def light_rotation(light_direction) -> np.ndarray:
    """(4, 4) the view rotation of a directional light travelling along `light_direction`."""
    return transforms.look_at_rotation((0.0, 0.0, 0.0), light_direction, (0.0, 1.0, 0.0))


def light_frame(points: np.ndarray, rotation: np.ndarray) -> np.ndarray:
    """(V, 3) points in a directional light's frame (`rotation`: light_rotation): x, y across
    the light, depth along it (the view's -z)."""
    return (points @ rotation[:3, :3].T) * np.array([1.0, 1.0, -1.0])


def bounds(points: np.ndarray) -> np.ndarray:
    """(2, 3): the points' least and greatest coordinates."""
    return np.stack([points.min(axis=0), points.max(axis=0)])


def world_geometry(scene) -> tuple[list[np.ndarray], list[np.ndarray]]:
    """Each object's vertices (V, 3) and model matrix in absolute world coordinates (float64)."""
    models = [np.asarray(m, dtype=np.float64) for m in scene.world_matrices()]
    points = [np.asarray(o.mesh.positions, dtype=np.float64) @ m[:3, :3].T + m[:3, 3]
              for o, m in zip(scene.objects, models)]
    return points, models


def light_can_shadow(scene, occluders: Occluders, kind: str, index: int) -> bool:
    """Whether light `index` of `kind` can darken any receiver from any camera: some caster
    can shadow some receiver (scene-level: every receiver counts, seen or not)."""
    casters = [i for i, o in enumerate(scene.objects) if o.casts_shadows and o.mesh.triangle_count]
    receivers = [i for i, o in enumerate(scene.objects) if o.receives_shadows and o.mesh.triangle_count]
    if kind == "directional":
        light = scene.directional_lights[index]
        return bool(occluders.pairs(casters, receivers, light_direction=light.direction, first=True))
    light = scene.point_lights[index]
    return bool(occluders.pairs(casters, receivers, light_position=light.position, first=True))
