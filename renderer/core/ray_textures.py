"""What the ray tracer's two twins need to texture their hits (docs/conventions.md, "Texture
coordinates" and "Textures in the ray tracer"; glsl/raytrace/textures.glsl, reference/raytrace/
textures.py), made once per scene by renderer/core/raytrace_scene.py, float64 here:

- `textures`: one slot per distinct (texture, ray sampler) of the textured materials, in
  object order; `ray_sampler` is the LOD rule: the ray tracer has no screen-space derivatives,
  so it reads level 0 with the sampler's magnification filter (nearest stays nearest, every
  other filter is bilinear there; mipmaps and anisotropy never apply);
- per object: its slot (-1: untextured), (su, sv, ou, ov) of the lookup at
  (u su + ou, v sv + ov), and which of k_a, k_d, k_s the texel multiplies;
- per triangle of the ray scene its vertices' UVs (zeros for a mesh without UVs, which no
  textured material may have);
- per sphere its world-to-object rotation (the sphere rule reads the object-space direction:
  a rotated globe turns its texture), per plane the affine map (u, v) = U (P, 1) of
  camera-relative points P (the plane rule of renderer/core/uv_rules.py through the object's
  world matrix, so that the analytic plane and the `plane` primitive agree).
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from renderer.core.textures import MODULATED, MaterialTexture, Sampler
from renderer.core.uv_rules import plane_uv_axes
from renderer.errors import SceneError

# The most slots a scene may have: glsl/raytrace/textures.glsl's chain of constant-index
# lookups (GLSL 3.30 indexes a sampler array by constants only) has this many branches.
TEXTURE_SLOTS = 16


@dataclass
class RayTextures:
    textures: tuple                  # (K,) MaterialTexture per slot: its texture, ray_sampler
    slot: np.ndarray                 # (M,) int per object, -1 untextured
    uv_transform: np.ndarray         # (M, 4) su, sv, ou, ov (1, 1, 0, 0 untextured)
    modulate: np.ndarray             # (M, 3) bool: the texel multiplies k_a, k_d, k_s
    triangle_uvs: np.ndarray         # (T, 3, 2) per triangle of the ray scene
    sphere_rotation: np.ndarray      # (S, 3, 3) world to object, per sphere of the ray scene
    plane_map: np.ndarray            # (Q, 2, 4) rows of U: (u, v) = U (P, 1), P camera-relative


def ray_sampler(sampler: Sampler) -> Sampler:
    """The sampler the ray tracer reads a texture with: level 0 and the magnification filter
    (nearest for "nearest", bilinear for every other filter), the wrap kept."""
    return Sampler(wrap=sampler.wrap, filter="nearest" if sampler.filter == "nearest" else "bilinear")


def ray_textures(scene, sphere_object, plane_object, triangle_uvs) -> RayTextures | None:
    """The scene's RayTextures (module docstring) for the ray scene's spheres and planes (their
    objects) and triangles' UVs; None where no material is textured (no texture code)."""
    materials = [obj.material for obj in scene.objects]
    if not any(m.textured for m in materials):
        return None
    slots: dict[tuple, int] = {}
    textures = []
    slot = np.full(len(materials), -1, np.int64)
    uv_transform = np.tile([1.0, 1.0, 0.0, 0.0], (len(materials), 1))
    modulate = np.zeros((len(materials), 3), bool)
    for k, m in enumerate(materials):
        if not m.textured:
            continue
        sampler = ray_sampler(m.texture.sampler)
        key = (id(m.texture.texture), sampler)
        if key not in slots:
            slots[key] = len(textures)
            textures.append(MaterialTexture(m.texture.texture, sampler))
        slot[k] = slots[key]
        uv_transform[k] = (*m.texture.uv_scale, *m.texture.uv_offset)
        modulate[k] = [name in m.texture.modulate for name in MODULATED]
    if len(textures) > TEXTURE_SLOTS:
        raise SceneError(f"the ray tracer reads at most {TEXTURE_SLOTS} textures (distinct image "
                         f"and filter pairs); this scene has {len(textures)}",
                         file=getattr(scene, "source", "") or None)
    world = scene.world_matrices()
    eye = np.asarray(scene.camera.eye, np.float64)
    return RayTextures(
        textures=tuple(textures), slot=slot, uv_transform=uv_transform, modulate=modulate,
        triangle_uvs=triangle_uvs,
        sphere_rotation=np.array([_rotation(world[k]).T for k in sphere_object]).reshape(-1, 3, 3),
        plane_map=np.array([plane_map(scene.objects[k].shape.normal, world[k], eye)
                            for k in plane_object]).reshape(-1, 2, 4))


def mesh_uvs(obj) -> np.ndarray:
    """The object's vertex UVs (V, 2) for the ray scene's triangles: what its lookup reads
    (SceneObject.texture_coordinates: a ValueError for a textured material on a mesh without
    UVs), or zeros where its material is untextured (never looked up)."""
    uvs = obj.texture_coordinates()
    if uvs is None:
        return np.zeros((len(obj.mesh.positions), 2))
    return np.asarray(uvs, np.float64)


def _rotation(model) -> np.ndarray:
    """R of a similarity's linear part s R (a sphere's world matrix: scene.world_shape)."""
    a = np.asarray(model, np.float64)[:3, :3]
    return a / np.cbrt(np.linalg.det(a))


def plane_map(normal, model, eye) -> np.ndarray:
    """(2, 4) U with (u, v) = U (P, 1) for camera-relative points P of the plane with object
    normal `normal` under world matrix `model`: the object point p = A^-1 (P + eye - t) and
    (u, v) = (p.T, p.B) (uv_rules.plane_uv_axes)."""
    m = np.asarray(model, np.float64)
    inverse = np.linalg.inv(m[:3, :3])
    rows = np.stack(plane_uv_axes(normal)) @ inverse            # (2, 3): T A^-1, B A^-1
    return np.concatenate([rows, (rows @ (np.asarray(eye, np.float64) - m[:3, 3]))[:, None]], 1)
