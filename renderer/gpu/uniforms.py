"""Uniform values as GL takes them: the layout of renderer/core/uniforms.py (the one source,
shared with the reference) cast to bytes. Floats and vectors become float32, matrices
column-major float32 (transforms.to_glsl, so that GLSL `M * v` is `M @ v`), flags and counts
int32. A light array of a kind the scene lacks is left out (neither does the shader declare
it), except in the all-features build, whose arrays have `light_slots` rows, zeros past the
scene's lights, with the counts as uniforms. The shadow-map lookup's uniforms are the frame's
ShadowPlan.uniforms (renderer/core/shadows.py), the directional maps' array texture on unit
SHADOW_MAPS_UNITS["directional"], the point lights' on SHADOW_MAPS_UNITS["point"]; a textured
material's texture is on MATERIAL_TEXTURE_UNIT.
"""

from __future__ import annotations

import ctypes

import numpy as np

from renderer.core.scene import FrameMatrices, Scene, SceneObject
from renderer.core.transforms import to_glsl
from renderer.core.uniforms import (ROWS_PER_LIGHT, UNIFORM_TYPES, frame_uniforms, object_uniforms,
                                    tessellation_uniforms)
from renderer.gpu.context import gl_function

MATERIAL_TEXTURE_UNIT = 1                # the unit a textured material's texture is bound to
FACE_NORMALS_UNIT = 3                    # a shadowed Phong or Gouraud object's facet normals
DISPLACEMENT_TEXTURE_UNIT = 4            # a displaced object's height image (its evaluation stage)
# The texture units each kind of light's shadow-map stack (array texture) is bound to.
SHADOW_MAPS_UNITS = {"directional": 0, "point": 2}


def set_shadow_sampler_units(ctx, program) -> None:
    """Point the program's u_directional_shadow_maps and u_point_shadow_maps (where it has
    them) at SHADOW_MAPS_UNITS, once, when it is linked. Through glProgramUniform1i: moderngl
    (5.x) has no setter for GL_SAMPLER_2D_ARRAY_SHADOW uniforms and ignores writes to them,
    so they would stay at unit 0 (where, with one stack, the other stack would be read)."""
    names = [(f"u_{kind}_shadow_maps", unit) for kind, unit in SHADOW_MAPS_UNITS.items()]
    present = [(program[name].location, unit) for name, unit in names if program.get(name, None) is not None]
    if not present:
        return
    set_int = gl_function(ctx, "glProgramUniform1i", None, ctypes.c_uint, ctypes.c_int, ctypes.c_int)
    for location, unit in present:
        set_int(program.glo, location, unit)


def as_bytes(name: str, value) -> bytes:
    """The bytes GL takes for uniform `name` (its type from the layout)."""
    kind = UNIFORM_TYPES[name]
    if kind in ("mat3", "mat4", "mat4[]"):
        return to_glsl(value)
    if kind in ("int", "bool", "sampler2DArrayShadow", "sampler2D"):
        return np.asarray(value, dtype=np.int32).tobytes()
    return np.asarray(value, dtype=np.float32).tobytes()


def frame_uniform_values(scene: Scene, matrices: FrameMatrices, light_slots: int | None = None,
                         shadows: dict | None = None) -> dict[str, bytes]:
    """Uniforms shared by every object of a frame: camera, eye, ambient and lights, and the
    shadow lookup's when `shadows` (ShadowPlan.uniforms) is given. `light_slots` is for the
    all-features build: arrays of that size and the counts."""
    values = frame_uniforms(scene, matrices)
    if light_slots is not None:
        directional, point = len(scene.directional_lights), len(scene.point_lights)
        if max(directional, point) > light_slots:
            raise ValueError(f"the all-features build has room for {light_slots} lights of each "
                             f"kind; the scene has {directional} directional and {point} point lights")
        values["u_num_directional_lights"] = np.asarray(directional)
        values["u_num_point_lights"] = np.asarray(point)
    if shadows is not None:
        values |= shadows                 # the samplers' units: set_shadow_sampler_units
    out = {}
    for name, value in values.items():
        if UNIFORM_TYPES[name].endswith("[]"):
            rows = light_slots * ROWS_PER_LIGHT.get(name, 1) if light_slots else len(value)
            if rows == 0:
                continue
            value = np.concatenate([value, np.zeros((rows - len(value),) + value.shape[1:])])
        out[name] = as_bytes(name, value)
    return out


def object_uniform_values(obj: SceneObject, matrices, shadow_masks: dict | None = None,
                          height: int = 0) -> dict[str, bytes]:
    """One object's uniforms: its model and normal matrices and its material (a textured
    one's UV transform and texture unit too); with `shadow_masks` (the frame's
    ShadowPlan.self_masks of the object, when the scene has maps) the shadow lookup's per-object
    masks and its facet normals' unit; a tessellated sphere's in a frame `height` pixels tall."""
    values = object_uniforms(obj, matrices) | tessellation_uniforms(obj, matrices, height)
    if obj.material.texture is not None:
        values["u_texture"] = np.asarray(MATERIAL_TEXTURE_UNIT)
    if obj.tessellation is not None and obj.tessellation.displacement is not None:
        values["u_height"] = np.asarray(DISPLACEMENT_TEXTURE_UNIT)
    if shadow_masks is not None:
        values |= {name: np.asarray(mask) for name, mask in shadow_masks.items()}
        values["u_shadow_facets"] = np.asarray(int(obj.shape is None))
        values["u_face_normals"] = np.asarray(FACE_NORMALS_UNIT)
    return {name: as_bytes(name, value) for name, value in values.items()}


def uniform_values(scene: Scene, obj: SceneObject, matrices: FrameMatrices,
                   index: int) -> dict[str, bytes]:
    """Every uniform (name -> bytes) for drawing `obj`, object number `index` of `scene`.
    A program may lack some (the compiler drops unused ones): skip names it does not have."""
    return frame_uniform_values(scene, matrices) | object_uniform_values(obj, matrices.objects[index])
