"""A scene as the ray tracer's two twins read it (glsl/raytrace/trace.glsl through
renderer/gpu/raytracer.py, reference/raytrace/trace.py): made once per scene, camera-relative
(docs/conventions.md, "Rays"), float64 here (each twin casts to float32).

- analytic spheres and planes (`Scene.world_shapes()`), each with its object's index;
- every other object's triangles in world space relative to the eye, one list for the whole
  scene, with their unit world-space vertex normals (the normal matrix, then normalised, as the
  rasteriser's vertex stage) and object indices, and one BVH over them (renderer/core/bvh.py);
  the BVH's tree does not depend on the eye: it is built over the world-space triangles
  relative to their bounds' centre, then its boxes fitted to the camera-relative triangles
  (`refit`), so that a new eye needs only a refit (`ray_scene(scene, tree=...)`: the bytes a
  build for that eye gives);
- the materials, one row per object: k_a, k_d, k_s, n, k_r, k_t, ior, two-sided, gloss (the
  reflected rays' lobe exponent, inf for a mirror).
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from renderer.core.bvh import Bvh, build_bvh, refit
from renderer.core.scene import Scene, WorldPlane, WorldSphere


@dataclass
class RayScene:
    sphere_centre: np.ndarray        # (S, 3)
    sphere_radius: np.ndarray        # (S,)
    sphere_object: np.ndarray        # (S,) int
    plane_normal: np.ndarray         # (Q, 3) unit
    plane_offset: np.ndarray         # (Q,)
    plane_object: np.ndarray         # (Q,) int
    triangles: np.ndarray            # (T, 3, 3) camera-relative vertices
    triangle_normals: np.ndarray     # (T, 3, 3) unit vertex normals
    triangle_object: np.ndarray      # (T,) int
    bvh: Bvh | None                  # over `triangles` (None when T = 0)
    ka: np.ndarray                   # (M, 3) per object
    kd: np.ndarray
    ks: np.ndarray
    n: np.ndarray                    # (M,)
    kr: np.ndarray                   # (M, 3)
    kt: np.ndarray                   # (M, 3)
    ior: np.ndarray                  # (M,)
    two_sided: np.ndarray            # (M,) bool
    gloss: np.ndarray                # (M,) lobe exponent, inf: a mirror (Material.gloss_exponent)
    gloss_set: bool = False          # some material sets `gloss` (inf included)

    @property
    def specular(self) -> bool:
        return bool((self.ks > 0).any())

    @property
    def secondary(self) -> bool:
        """Whether any material reflects or transmits (secondary rays exist)."""
        return bool((self.kr > 0).any() or (self.kt > 0).any())

    @property
    def glossy(self) -> bool:
        """Whether some material that reflects (k_r or k_t > 0) has a finite gloss: the
        reflected rays' lobe is sampled somewhere (the GLSL's GLOSSY)."""
        reflects = (self.kr > 0).any(-1) | (self.kt > 0).any(-1)
        return bool((reflects & np.isfinite(self.gloss)).any())


def _normalize_or_zero(v):
    length = np.sqrt((v * v).sum(-1, keepdims=True))
    return v / np.where(length > 0, length, 1.0)


def ray_scene(scene: Scene, tree: Bvh | None = None) -> RayScene:
    """The scene's surfaces and materials for the ray tracer. `tree`: the BVH of an earlier
    ray_scene of this scene's very triangles (another camera, other materials or lights),
    refitted instead of built again."""
    shapes = scene.world_shapes()
    matrices = scene.matrices(1, 1)
    world_matrices = scene.world_matrices()
    spheres = [(k, s) for k, s in enumerate(shapes) if isinstance(s, WorldSphere)]
    planes = [(k, s) for k, s in enumerate(shapes) if isinstance(s, WorldPlane)]
    tris, world_tris, normals, owner = [], [], [], []
    for k, (obj, shape) in enumerate(zip(scene.objects, shapes)):
        if shape is not None or len(obj.mesh.faces) == 0:
            continue
        m = matrices.objects[k]
        positions = np.asarray(obj.mesh.positions, np.float64)
        world = positions @ m.model[:3, :3].T + m.model[:3, 3]          # camera-relative
        absolute = positions @ world_matrices[k][:3, :3].T + world_matrices[k][:3, 3]
        vertex_normals = _normalize_or_zero(np.asarray(obj.mesh.normals, np.float64) @ m.normal.T)
        faces = np.asarray(obj.mesh.faces, np.int64)
        tris.append(world[faces])
        world_tris.append(absolute[faces])
        normals.append(vertex_normals[faces])
        owner.append(np.full(len(faces), k, np.int64))
    triangles = np.concatenate(tris) if tris else np.zeros((0, 3, 3))
    if len(triangles) and tree is None:
        absolute = np.concatenate(world_tris)
        centre = (absolute.min((0, 1)) + absolute.max((0, 1))) / 2
        tree = build_bvh(absolute - centre)
    mats = [obj.material for obj in scene.objects]

    def rows(name, width=3):
        return np.asarray([getattr(m, name) for m in mats], np.float64).reshape(len(mats), width) \
            if width > 1 else np.asarray([getattr(m, name) for m in mats], np.float64).reshape(len(mats))

    return RayScene(
        sphere_centre=np.array([s.centre for _, s in spheres], np.float64).reshape(-1, 3),
        sphere_radius=np.array([s.radius for _, s in spheres], np.float64),
        sphere_object=np.array([k for k, _ in spheres], np.int64),
        plane_normal=np.array([s.normal for _, s in planes], np.float64).reshape(-1, 3),
        plane_offset=np.array([s.offset for _, s in planes], np.float64),
        plane_object=np.array([k for k, _ in planes], np.int64),
        triangles=triangles,
        triangle_normals=np.concatenate(normals) if normals else np.zeros((0, 3, 3)),
        triangle_object=np.concatenate(owner) if owner else np.zeros(0, np.int64),
        bvh=refit(tree, triangles) if len(triangles) else None,
        ka=rows("ka"), kd=rows("kd"), ks=rows("ks"), n=rows("n", 1), kr=rows("kr"), kt=rows("kt"),
        ior=rows("ior", 1), two_sided=np.array([bool(m.two_sided) for m in mats], bool),
        gloss=np.array([m.gloss_exponent for m in mats], np.float64),
        gloss_set=any(m.gloss is not None for m in mats),
    )
