"""The uniform layout, written once: every uniform the GLSL programs read, its GLSL type, and its
value for a frame or an object as float64 arrays (int for flags and counts).

Both pipelines take their uniforms from here: the GPU path casts these arrays to bytes
(renderer/gpu/uniforms.py: float32, matrices column-major), and the reference reads the same
arrays in its own dtype (reference/lighting.py: Lights, MaterialUniforms). The names are the
GLSL names (glsl/lighting.glsl, glsl/vertex.glsl). Positions are camera-relative
(FrameMatrices.relative, docs/conventions.md); a light array of a kind the scene lacks has
no rows (the GPU path then leaves it out: GLSL has no empty arrays).
"""

from __future__ import annotations

import numpy as np

from renderer.core.scene import FrameMatrices, Material, ObjectMatrices, Scene, SceneObject
from renderer.core.tessellation import EDGE_ERROR_SHARE, MAX_LEVEL
from renderer.core.textures import MaterialTexture

# name -> GLSL type; "vec3[]" is an array with one row per light of that kind.
LIGHT_UNIFORMS = {
    "u_ambient": "vec3",                    # I_a
    "u_directional_direction": "vec3[]",    # D, the way the light travels
    "u_directional_intensity": "vec3[]",    # I_l
    "u_point_position": "vec3[]",           # Q
    "u_point_intensity": "vec3[]",          # I_l
    "u_point_attenuation": "vec3[]",        # (c, l, q)
}
FRAME_UNIFORMS = {
    "u_view": "mat4",                       # V, a rotation (camera-relative coordinates)
    "u_projection": "mat4",                 # P
    "u_eye": "vec3",                        # E, the eye
    **LIGHT_UNIFORMS,
}
MATERIAL_UNIFORMS = {
    "u_ka": "vec3",                         # k_a, k_d, k_s: linear RGB reflection coefficients
    "u_kd": "vec3",
    "u_ks": "vec3",
    "u_n": "float",                         # the Phong exponent
}
OBJECT_UNIFORMS = {
    "u_model": "mat4",                      # T(-origin) M_world
    "u_normal_matrix": "mat3",              # transforms.normal_matrix(M_world)
    **MATERIAL_UNIFORMS,
    "u_two_sided": "bool",                  # read by the all-features build only
}
# A textured material's lookup (glsl/texture.glsl), in its programs only: the lookup is at
# uv * u_uv_scale + u_uv_offset; the texture is on the GPU path's MATERIAL_TEXTURE_UNIT.
TEXTURE_UNIFORMS = {
    "u_texture": "sampler2D",               # the texture unit (the GPU path's alone)
    "u_uv_scale": "vec2",                   # MaterialTexture.uv_scale
    "u_uv_offset": "vec2",                  # MaterialTexture.uv_offset
}
# The all-features build (renderer/gpu/shaders.py) reads the light counts at run time.
LIGHT_COUNT_UNIFORMS = {"u_num_directional_lights": "int", "u_num_point_lights": "int"}
# The shadow-map lookup (glsl/shadow/lookup.glsl), in programs of objects that receive shadows:
# the values are the frame's renderer/core/shadows.py ShadowPlan.uniforms; the arrays have a
# row per light of their kind (ROWS_PER_LIGHT rows for the cube's faces).
SHADOW_UNIFORMS = {
    "u_directional_shadow_maps": "sampler2DArrayShadow",   # the directional stack's unit (GPU only)
    "u_directional_shadow_map_size": "float",   # S, texels on a side of its layers
    "u_point_shadow_maps": "sampler2DArrayShadow",         # the point stack's unit (GPU only)
    "u_point_shadow_map_size": "float",     # S, texels on a side of its layers
    "u_directional_shadow_matrix": "mat4[]",   # camera-relative world -> (u, v, z_w, 1)
    "u_directional_shadow": "vec4[]",       # (layer, texel size, kernel, R/S; 0 when not drawn)
    "u_directional_shadow_bias": "vec4[]",  # (normal, constant, slope, 0) in texels
    "u_point_shadow": "vec4[]",             # (drawn, R / S, kernel, R: the faces' side)
    "u_point_shadow_depth": "vec4[]",       # (A, B, near, far): z_w = A + B / m
    "u_point_shadow_bias": "vec4[]",
    "u_point_shadow_tiles": "vec4[]",       # per cube face: (centre x, y, half, layer or -1: not drawn)
}
ROWS_PER_LIGHT = {"u_point_shadow_tiles": 6}   # other light arrays: 1
# Per receiving object of a frame with maps: which lights' maps hold its own texels (bit i:
# light i of the kind; ShadowPlan.self_masks), and its faces' normals (renderer/core/facets.py)
# on the GPU path's FACE_NORMALS_UNIT, fetched at gl_PrimitiveID (Phong and Gouraud; flat has
# its geometry stage's face normal).
SHADOW_OBJECT_UNIFORMS = {
    "u_shadow_self_directional": "int",
    "u_shadow_self_point": "int",
    "u_shadow_facets": "int",               # 1: its facets are its surface; 0: an analytic shape's
    "u_face_normals": "sampler2D",          # the face-normal texture's unit (the GPU path's alone)
}
# The depth pass (glsl/shadow/depth.vert): light clip from object coordinates, per pass and object.
SHADOW_PASS_UNIFORMS = {"u_clip_from_model": "mat4"}
# A tessellated sphere's (glsl/tess_control.glsl, tess_evaluation.glsl; renderer/core/tessellation.py):
# per object, and the viewport's height, which its levels' pixels are measured in.
TESSELLATION_UNIFORMS = {
    "u_viewport_height": "float",           # H, pixels
    "u_target_error": "float",              # pixels: an edge's bound, Tessellation.error x EDGE_ERROR_SHARE
    "u_surface_radius": "float",            # the sphere's radius in world units
    "u_max_level": "float",                 # tessellation.MAX_LEVEL
    "u_fixed_level": "float",               # Tessellation.level, 0 for levels by need
    "u_sphere": "vec4",                     # object space: centre, radius
    # a displaced mesh's (Tessellation.displacement)
    "u_height": "sampler2D",                # the height image's texture unit (the GPU path's alone)
    "u_height_size": "vec2",                # its width and height, texels
    "u_height_texel": "vec2",               # float32(1) / width, float32(1) / height
    "u_height_slope": "float",              # Displacement.slope: the largest step between texels
    "u_displacement_scale": "float",        # Displacement.scale: object units for a height of 1
    "u_height_uv_scale": "vec2",            # Displacement.uv_scale, uv_offset: st = uv * scale + offset
    "u_height_uv_offset": "vec2",
}
UNIFORM_TYPES = (FRAME_UNIFORMS | OBJECT_UNIFORMS | TEXTURE_UNIFORMS | LIGHT_COUNT_UNIFORMS
                 | SHADOW_UNIFORMS | SHADOW_OBJECT_UNIFORMS | SHADOW_PASS_UNIFORMS | TESSELLATION_UNIFORMS)


def _rows(values) -> np.ndarray:
    return np.asarray(values, dtype=np.float64).reshape(-1, 3)


def light_uniforms(scene: Scene, origin=(0.0, 0.0, 0.0)) -> dict[str, np.ndarray]:
    """The ambient light and the light arrays (LIGHT_UNIFORMS), float64; point-light positions
    relative to `origin` (the frame's camera-relative origin)."""
    directional, point = scene.directional_lights, scene.point_lights
    return {
        "u_ambient": np.asarray(scene.ambient, dtype=np.float64),
        "u_directional_direction": _rows([light.direction for light in directional]),
        "u_directional_intensity": _rows([light.intensity for light in directional]),
        "u_point_position": _rows([light.position for light in point]) - np.asarray(origin, dtype=np.float64),
        "u_point_intensity": _rows([light.intensity for light in point]),
        "u_point_attenuation": _rows([light.attenuation for light in point]),
    }


def frame_uniforms(scene: Scene, matrices: FrameMatrices) -> dict[str, np.ndarray]:
    """The uniforms shared by every object of a frame (FRAME_UNIFORMS), float64."""
    return {"u_view": matrices.view, "u_projection": matrices.projection,
            "u_eye": matrices.relative(scene.camera.eye),
            **light_uniforms(scene, matrices.origin)}


def material_uniforms(material: Material) -> dict[str, np.ndarray]:
    """A material's coefficients (MATERIAL_UNIFORMS), float64."""
    return {"u_ka": np.asarray(material.ka, dtype=np.float64),
            "u_kd": np.asarray(material.kd, dtype=np.float64),
            "u_ks": np.asarray(material.ks, dtype=np.float64),
            "u_n": np.asarray(material.n, dtype=np.float64)}


def texture_uniforms(texture: MaterialTexture | None) -> dict[str, np.ndarray]:
    """A material's texture's UV transform (TEXTURE_UNIFORMS but the texture unit), float64;
    empty for a material without a texture."""
    if texture is None:
        return {}
    return {"u_uv_scale": np.asarray(texture.uv_scale, dtype=np.float64),
            "u_uv_offset": np.asarray(texture.uv_offset, dtype=np.float64)}


def object_uniforms(obj: SceneObject, matrices: ObjectMatrices) -> dict[str, np.ndarray]:
    """One object's uniforms (OBJECT_UNIFORMS): its matrices and its material, and its
    material's UV transform when it is textured."""
    return {"u_model": matrices.model, "u_normal_matrix": matrices.normal,
            **material_uniforms(obj.material),
            "u_two_sided": np.asarray(int(bool(obj.material.two_sided))),
            **texture_uniforms(obj.material.texture)}


def tessellation_uniforms(obj: SceneObject, matrices: ObjectMatrices, height: int) -> dict[str, np.ndarray]:
    """A tessellated object's uniforms (TESSELLATION_UNIFORMS) in a frame `height` pixels tall;
    empty for an object drawn without the tessellation stages. A PN-triangle mesh has no
    sphere: radius 0 and u_sphere 0, which its stages do not read."""
    settings = obj.tessellation
    if settings is None:
        return {}
    if settings.surface == "sphere":
        sphere = obj.shape
        scale = float(np.linalg.norm(np.asarray(matrices.model, dtype=np.float64)[:3, 0]))   # a similarity's
        radius, centre_radius = float(sphere.radius) * scale, [*sphere.centre, sphere.radius]
    else:
        radius, centre_radius = 0.0, [0.0, 0.0, 0.0, 0.0]
    values = {"u_viewport_height": np.asarray(float(height)),
              "u_target_error": np.asarray(float(settings.error) * EDGE_ERROR_SHARE),
              "u_surface_radius": np.asarray(radius),
              "u_max_level": np.asarray(MAX_LEVEL),
              "u_fixed_level": np.asarray(0.0 if settings.level is None else float(settings.level)),
              "u_sphere": np.asarray(centre_radius, dtype=np.float64)}
    displacement = settings.displacement
    if displacement is not None:
        size = np.asarray([displacement.texture.width, displacement.texture.height], np.float32)
        values |= {"u_height_size": size, "u_height_texel": np.float32(1) / size,
                   "u_height_slope": np.asarray(displacement.slope),
                   "u_displacement_scale": np.asarray(float(displacement.scale)),
                   "u_height_uv_scale": np.asarray(displacement.uv_scale, np.float64),
                   "u_height_uv_offset": np.asarray(displacement.uv_offset, np.float64)}
    return values
