"""Motion blur's data (docs/conventions.md, "Rays", "Motion blur"): which objects move, and how,
in float64 on the CPU, for both twins of the ray tracer (glsl/raytrace/motion.glsl through
renderer/gpu/raytracer.py's uniforms, reference/raytrace/motion.py), which cast it to float32.

An object with a `velocity` v (scene units per unit time) or an `angular_velocity` w (degrees
per unit time about the axis w/|w| through c, the object's world origin: the translation of
its world matrix) has at time t each of its points X at

    X(t) = X + (R(t w) - I)(X - c) + t v,     R(a) - I = sin(a) K + (1 - cos a) K^2

(Rodrigues; K the cross-product matrix of the unit axis). The displacement form makes t = 0
exact: sin(0) K + (1 - cos 0) K^2 and 0 v are zero, and X + 0 is X, bit for bit. Only that
object moves (a child's motion is its own; children do not follow their parent). A camera
sample's time is t = open + u (close - open), u in [0, 1) its TIME number; the shutter
[open, close] is the camera's, [0, 0] by default (the still image).

Here an object's motion is its camera-relative centre c (world c - eye, as the scene's other
positions), v, the unit axis (0 where w = 0) and the rate |w| in radians per unit time.
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np

from renderer.core.scene import Scene


@dataclass(frozen=True)
class SceneMotion:
    """Every object's motion, one row per object (zeros for an object that declares none)."""
    centre: np.ndarray           # (M, 3) c, camera-relative
    velocity: np.ndarray         # (M, 3) v, scene units per unit time
    axis: np.ndarray             # (M, 3) unit axis of w, or 0
    rate: np.ndarray             # (M,) |w|, radians per unit time
    shutter: tuple = (0.0, 0.0)  # the camera's (open, close)

    def rows(self, objects) -> np.ndarray:
        """(len(objects), 3, 4) float64: the uniform rows of those objects' motions, as
        glsl/raytrace/trace.glsl reads them: (c, rate), (v, 0), (axis, 0)."""
        objects = np.asarray(objects, np.int64)
        rows = np.zeros((len(objects), 3, 4))
        rows[:, 0, :3], rows[:, 0, 3] = self.centre[objects], self.rate[objects]
        rows[:, 1, :3], rows[:, 2, :3] = self.velocity[objects], self.axis[objects]
        return rows


def has_motion(obj) -> bool:
    """Whether a scene object declares a velocity or an angular velocity (zero or not)."""
    return obj.velocity is not None or obj.angular_velocity is not None


def declares_motion(scene: Scene) -> bool:
    """Whether some object declares a motion: the twin then runs the motion code, even with the
    shutter closed (so that [0, 0] is a real limit)."""
    return any(has_motion(obj) for obj in scene.objects)


def moves(scene: Scene) -> bool:
    """Whether the image needs the motion code (the GPU's MOTION define): the shutter is not
    [0, 0] (an open one, or an instant [t, t] that shows the scene at time t) and some object
    has a velocity or angular velocity that is not zero."""
    return any(float(x) != 0.0 for x in scene.camera.shutter) and any(
        any(float(x) != 0.0 for x in (obj.velocity or ())) or
        any(float(x) != 0.0 for x in (obj.angular_velocity or ()))
        for obj in scene.objects)


def scene_motion(scene: Scene) -> SceneMotion:
    """Each object's motion (module docstring), camera-relative."""
    eye = np.asarray(scene.camera.eye, np.float64)
    count = len(scene.objects)
    centre, velocity, axis, rate = np.zeros((count, 3)), np.zeros((count, 3)), np.zeros((count, 3)), np.zeros(count)
    for k, (obj, world) in enumerate(zip(scene.objects, scene.world_matrices())):
        centre[k] = np.asarray(world[:3, 3], np.float64) - eye
        if obj.velocity is not None:
            velocity[k] = obj.velocity
        if obj.angular_velocity is not None:
            w = np.asarray(obj.angular_velocity, np.float64)
            length = float(np.linalg.norm(w))
            if length > 0.0:
                axis[k], rate[k] = w / length, math.radians(length)
    return SceneMotion(centre, velocity, axis, rate, tuple(float(x) for x in scene.camera.shutter))

