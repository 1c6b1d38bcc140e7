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

    def plane(self, i: int):
        if i not in self._planes:
            self._planes[i] = plane_of(self.points[i])
        return self._planes[i]

    def body(self, i: int) -> ConvexBody | None:
        if i not in self._bodies:
            self._bodies[i] = None if self.plane(i) is not None else convex_body(self.scene.objects[i].mesh)
        return self._bodies[i]

    def _scale(self, i: int) -> float:
        return PLANAR_TOLERANCE * (1.0 + float(np.abs(self.points[i]).max()))

    def pairs(self, casters: list[int], receivers: list[int], light_position=None,
              light_direction=None) -> dict[int, list[int]]:
        """caster -> the receivers (in `receivers`' order) it can shadow, for a point light at
        `light_position` or a directional one travelling along `light_direction`; casters that
        can shadow none are left out."""
        boxes = None if light_direction is None else self._light_boxes(
            sorted({*casters, *receivers}), light_direction)
        out = {}
        for c in casters:
            shadowed = [r for r in receivers if self.can_shadow(c, r, light_position, light_direction, boxes)]
            if shadowed:
                out[c] = shadowed
        return out

    def can_shadow(self, c: int, r: int, light_position=None, light_direction=None, boxes=None) -> bool:
        """Whether caster c can shadow receiver r (the module docstring's rule). `boxes`:
        _light_boxes of both, for a directional light (found here when None)."""
        plane = self.plane(c)
        if plane is not None:
            return r != c and self._below_plane(c, plane, r, light_position, light_direction)
        body = self.body(c)
        if body is not None:
            inside = light_position is not None and bool(
                body.contains(np.asarray(light_position)[None], self.models[c])[0])
            if r == c:
                outside_lit = body.normals_outward is True and not self.scene.objects[c].material.two_sided
                return not (inside or outside_lit)
            if inside and body.contains(self.points[r], self.models[c]).all():
                return False
        if light_direction is not None and r != c:
            boxes = boxes if boxes is not None else self._light_boxes([c, r], light_direction)
            return self._across_light_meet(boxes[c], boxes[r], self._scale(c) + self._scale(r))
        return True

    def _light_boxes(self, objects, light_direction) -> dict[int, np.ndarray]:
        """object -> (2, 3): its vertices' least and greatest (x, y, depth) in the directional
        light's frame (x, y across the light, depth along it)."""
        rotation = transforms.look_at_rotation((0.0, 0.0, 0.0), light_direction, (0.0, 1.0, 0.0))[:3, :3]
        flip = np.array([1.0, 1.0, -1.0])                     # the view's -z is the depth
        out = {}
        for i in objects:
            p = (self.points[i] @ rotation.T) * flip
            out[i] = np.stack([p.min(axis=0), p.max(axis=0)])
        return out

    def _below_plane(self, c, plane, r, light_position, light_direction) -> bool:
        normal, origin = plane
        scale = self._scale(c)
        if light_position is not None:
            side = float(normal @ (np.asarray(light_position) - origin))
        else:
            side = -float(normal @ np.asarray(light_direction, dtype=np.float64))
        if abs(side) <= scale:
            return False                     # the light grazes the plane: no shadow of any area
        facing = normal if side > 0 else -normal
        return bool(((self.points[r] - origin) @ facing < -scale).any())

    @staticmethod
    def _across_light_meet(caster: np.ndarray, receiver: np.ndarray, slack: float) -> bool:
        """Directional light, boxes from _light_boxes: the receiver's box across the light
        meets the caster's, and some of the receiver lies deeper than the caster's nearest."""
        if np.any(caster[1, :2] < receiver[0, :2] - slack) or np.any(receiver[1, :2] < caster[0, :2] - slack):
            return False
        return bool(receiver[1, 2] > caster[0, 2] - slack)


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
        return bool(occluders.pairs(casters, receivers, light_direction=light.direction))
    light = scene.point_lights[index]
    return bool(occluders.pairs(casters, receivers, light_position=light.position))
