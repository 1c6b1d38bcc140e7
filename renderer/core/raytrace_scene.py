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
- textures (renderer/core/ray_textures.py): None where no material is textured, else each
  object's texture slot and lookup, the triangles' vertex UVs, each sphere's world-to-object
  rotation and each plane's UV map;
- motion blur (`motion=True`; renderer/core/motion.py): every object's motion, and the BVH is
  a `forest`: the static triangles' tree first (if there are any), then one tree per moving
  mesh object over its time-0 triangles (each built eye-free and refitted as above), which the
  twins walk with the ray moved into that object's time-0 frame (`mesh_object`: the object
  each tree moves with, -1 for the static one). Without it, every triangle is in one tree.
"""

from __future__ import annotations

from dataclasses import dataclass, field

import numpy as np

from renderer.core.bvh import Bvh, build_bvh, forest, refit, roots
from renderer.core.motion import SceneMotion, declares_motion, has_motion, scene_motion
from renderer.core.ray_textures import RayTextures, mesh_uvs, ray_textures
from renderer.core.physical import is_physical
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
    fresnel_exact: np.ndarray        # (M,) bool: the exact Fresnel equations, else Schlick
    gloss_set: bool = False          # some material sets `gloss` (inf included)
    glossy: bool = False             # some material is glossy (Material.is_glossy: the GLSL's GLOSSY)
    motion: SceneMotion | None = None    # per object; None: no motion code (the still scene)
    mesh_object: np.ndarray = field(default_factory=lambda: np.zeros(0, np.int64))
    # (K,) per tree of `bvh`: the object it moves with, -1 for the static triangles' tree
    textures: RayTextures | None = None  # None: no material is textured (no texture code)
    radiance_scaling: bool = False   # the physical model: refraction scales radiance by eta^2

    @property
    def mesh_roots(self) -> np.ndarray:
        """(K,) each tree's root node in `bvh`."""
        return roots(self.bvh) if self.bvh is not None else np.zeros(0, np.int64)

    @property
    def static_tree(self) -> bool:
        """Whether `bvh` starts with a tree of static triangles (walked as it is)."""
        return bool(len(self.mesh_object)) and self.mesh_object[0] < 0

    @property
    def specular(self) -> bool:
        return bool((self.ks > 0).any())

    @property
    def secondary(self) -> bool:
        """Whether any material reflects or transmits (secondary rays exist)."""
        return bool((self.kr > 0).any() or (self.kt > 0).any())



def _normalize_or_zero(v):
    length = np.sqrt((v * v).sum(-1, keepdims=True))
    return v / np.where(length > 0, length, 1.0)


def ray_scene(scene: Scene, tree: Bvh | None = None, motion: bool | None = None) -> RayScene:
    """The scene's surfaces and materials for the ray tracer. `tree`: the BVH of an earlier
    ray_scene of this scene's very triangles (another camera, other materials or lights; the
    same `motion`), refitted instead of built again. `motion`: with motion blur's data and
    trees (module docstring); default: where some object declares a motion (the twin's rule)."""
    motion = declares_motion(scene) if motion is None else bool(motion)
    shapes = scene.world_shapes()
    matrices = scene.matrices(1, 1)
    world_matrices = scene.world_matrices()
    textured = any(obj.material.textured for obj in scene.objects)
    spheres = [(k, s) for k, s in enumerate(shapes) if isinstance(s, WorldSphere)]
    planes = [(k, s) for k, s in enumerate(shapes) if isinstance(s, WorldPlane)]
    tris, world_tris, normals, owner, uvs = [], [], [], [], []
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
        if textured:
            uvs.append(mesh_uvs(obj)[faces])
    triangles = np.concatenate(tris) if tris else np.zeros((0, 3, 3))
    owners = np.concatenate(owner) if owner else np.zeros(0, np.int64)
    mesh_object = _tree_objects(scene, owners, motion)
    bvh = None
    if len(triangles):
        bvh = (refit(tree, triangles) if tree is not None
               else _build_trees(np.concatenate(world_tris), triangles, owners, mesh_object))
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
        bvh=bvh,
        ka=rows("ka"), kd=rows("kd"), ks=rows("ks"), n=rows("n", 1), kr=rows("kr"), kt=rows("kt"),
        ior=rows("ior", 1), two_sided=np.array([bool(m.two_sided) for m in mats], bool),
        gloss=np.array([m.gloss_exponent for m in mats], np.float64),
        fresnel_exact=np.array([m.fresnel == "exact" for m in mats], bool),
        gloss_set=any(m.gloss is not None for m in mats),
        glossy=any(m.is_glossy for m in mats),
        motion=scene_motion(scene) if motion else None, mesh_object=mesh_object,
        textures=ray_textures(scene, [k for k, _ in spheres], [k for k, _ in planes],
                              np.concatenate(uvs) if uvs else np.zeros((0, 3, 2))),
        radiance_scaling=is_physical(scene),
    )


def _tree_objects(scene: Scene, owners: np.ndarray, motion: bool) -> np.ndarray:
    """The object each tree of the BVH moves with (-1: the static triangles' tree, first)."""
    present = np.unique(owners)
    moving = [k for k in present if motion and has_motion(scene.objects[k])]
    static = [-1] if len(present) > len(moving) else []
    return np.array(static + moving, np.int64)


def _build_trees(absolute: np.ndarray, placed: np.ndarray, owners: np.ndarray,
                 mesh_object: np.ndarray) -> Bvh:
    """The BVH (a `forest` where some mesh moves) over world-space triangles, each tree built
    relative to its triangles' bounds' centre (independent of the eye) and laid out over the
    camera-relative triangles `placed` (the refit of that tree to them, in one go)."""
    trees = []
    for k in mesh_object:
        ids = np.flatnonzero(~np.isin(owners, mesh_object[mesh_object >= 0]) if k < 0 else owners == k)
        group = absolute[ids]
        centre = (group.min((0, 1)) + group.max((0, 1))) / 2
        built = build_bvh(group - centre, layout=placed[ids])
        triangles = built.triangles.copy()
        triangles[:, 0, 3] = ids[built.original_index]           # the scene's numbering
        trees.append(Bvh(built.nodes, triangles, built.depth))
    return trees[0] if len(trees) == 1 else forest(trees)
