"""Curved primitives rebuilt at other tessellation levels, for the report's tessellation knob.

A level is a factor on the authored segment counts: uv_sphere (segments, rings), cylinder
(segments) and torus (major and minor segments) are multiplied by it; an icosphere, whose
triangles quadruple with each subdivision, gets log2(level) subdivisions more or fewer, so
that at every level a primitive has about level^2 times its authored triangles. Counts are
clamped to the scene format's limits (renderer/core/scene_file.py PRIMITIVE_LIMITS). Meshes
without a recipe (mesh files) and flat primitives (plane, cube) stay as they are.

    scene_at_level(scene, 4.0)      a copy of the scene with every curved primitive 4x finer
"""

from __future__ import annotations

import math
from dataclasses import replace

from renderer.core.primitives import PRIMITIVES
from renderer.core.scene import Mesh, Scene
from renderer.core.scene_file import PRIMITIVE_LIMITS

LEVELS = (0.25, 0.5, 1.0, 2.0, 4.0)   # the report's sweep; the last (finest) serves the ground truth
FINEST = LEVELS[-1]
SEGMENT_ARGUMENTS = {
    "uv_sphere": {"segments": 32, "rings": 16},
    "cylinder": {"segments": 32},
    "torus": {"major_segments": 48, "minor_segments": 24},
}                                     # the counts each primitive scales, with its defaults


def _clamped(name: str, argument: str, value: int) -> int:
    _, low, high = PRIMITIVE_LIMITS[name][argument]
    return max(low, min(high, value))


def retessellate(mesh: Mesh, level: float) -> Mesh:
    """`mesh` rebuilt at `level` times its authored tessellation (itself if it cannot be)."""
    if mesh.recipe is None or level == 1.0:
        return mesh
    name, arguments = mesh.recipe
    arguments = dict(arguments)
    if name == "icosphere":
        authored = arguments.get("subdivisions", 2)
        arguments["subdivisions"] = _clamped(name, "subdivisions", authored + round(math.log2(level)))
    elif name in SEGMENT_ARGUMENTS:
        for argument, default in SEGMENT_ARGUMENTS[name].items():
            authored = arguments.get(argument, default)
            arguments[argument] = _clamped(name, argument, round(authored * level))
    else:
        return mesh
    rebuilt = PRIMITIVES[name](**arguments)
    rebuilt.recipe = (name, arguments)
    return rebuilt


def scene_at_level(scene: Scene, level: float) -> Scene:
    """A copy of `scene` whose curved primitives are rebuilt at `level`; a mesh shared by
    several objects stays shared."""
    rebuilt: dict[int, Mesh] = {}
    objects = []
    for obj in scene.objects:
        if id(obj.mesh) not in rebuilt:
            rebuilt[id(obj.mesh)] = retessellate(obj.mesh, level)
        mesh = rebuilt[id(obj.mesh)]
        objects.append(replace(obj, mesh=mesh))
    return replace(scene, objects=objects)
