"""The GPU's depth held against ray casts (`renderer compare SCENE --depth-vs-truth`;
docs/conventions.md, "Depth").

A check that shares none of the rasteriser's decisions: the frame's depth (the camera-space
distance -z_eye the GPU's Frame carries, float32) is held, pixel by pixel, against a float64
ray cast from the camera through the same pixel centre (renderer/core/camera_rays.py: rays
from the inverse of the rasteriser's P V, so s is the view depth; docs/conventions.md,
"Window, pixels and images") against exactly the surfaces the rasteriser draws:

- the triangles of every object's mesh (a sphere's icosphere tessellation too), through the
  object's camera-relative model matrix in float64; of a tessellated sphere, the triangles the
  tessellation stages make in this frame (their twin, reference/tessellation/surface.py, bit
  for bit the GPU's points: tests/test_tessellation_stages.py);
- for an analytic plane, the infinite plane itself (Scene.world_shape), not the polygon the
  rasteriser draws of it (renderer/core/drawn.py), whose making is what is checked;
- each only where the rasteriser draws it: a culled object's triangles that face away from
  the camera are left out, and a hit counts where near < s < far (the clip volume in depth).

Relative error e = |depth_gpu - s| / s where both hit. Silhouettes: where a pixel centre lies
within a snapped vertex's or a rounding's reach of a triangle edge that changes the surface
(an object's outline, a self-occlusion, the far plane's cut), the fill rule and sub-pixel
snapping may give the GPU the other surface, a depth error of no meaning here. Such pixels
are *ambiguous* and left out: four more rays per pixel, EDGE_OFFSET pixels to the left,
right, below and above the centre, each either hits the centre's object on the centre's
surface plane (its s within SURFACE_JUMP of what the centre hit's plane gives along it) or
misses with it; any other outcome makes the pixel ambiguous. Outside them, pixels that only
one of the two hits are counted (`gpu_only`, `truth_only`): a surface drawn where none is, or
missing (as a plane's finite square ending in view would be).

The error is also given in units of the depth buffer's own float32 step at s (`depth_step`):
about 1 to 2 means that nothing is left to gain but from the depth mapping (reversed-Z, a
farther near plane).

    result = depth_vs_truth(scene, 320, 240)      # renders on the GPU (EGL, else OSMesa)
    result.as_dict()                              # the figures: p99.9 and max of e, counts
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from reference.raytrace.bvh import closest_hit
from reference.raytrace.camera import camera_ray, pixel_windows
from reference.raytrace.intersect import ray_plane
from reference.tessellation.surface import tessellated_mesh
from renderer.core.bvh import build_bvh
from renderer.core.camera_rays import camera_ray_uniforms, is_perspective
from renderer.core.gl_rules import depth_mapping
from renderer.core.scene import Plane, Scene, world_shape

EDGE_OFFSET = 1.0 / 64.0       # pixels: 8 times llvmpipe's largest snap of a vertex (1/512)
SURFACE_JUMP = 1e-3            # relative: an offset ray this far off the centre's plane hit another surface
PERCENTILE = 99.9
TARGET = 2e-5                  # issue 28: the relative error's 99.9th percentile on every built-in scene
OFFSETS = ((-EDGE_OFFSET, 0.0), (EDGE_OFFSET, 0.0), (0.0, -EDGE_OFFSET), (0.0, EDGE_OFFSET))


@dataclass
class Surfaces:
    """What the rasteriser draws, for ray casting, camera-relative world, float64."""
    triangles: np.ndarray          # (T, 3, 3) the drawn (not culled) triangles
    triangle_object: np.ndarray    # (T,) int
    plane_normal: np.ndarray       # (Q, 3) unit
    plane_offset: np.ndarray       # (Q,)
    plane_object: np.ndarray       # (Q,) int
    near: float
    far: float

    def __post_init__(self):
        self.bvh = build_bvh(self.triangles) if len(self.triangles) else None


def _culled(obj, facing: np.ndarray) -> np.ndarray:
    """(K,) which of an object's surfaces GL culls, from `facing` (> 0: the front, as wound, is
    turned to the camera)."""
    if obj.cull == "back":
        return facing <= 0.0
    if obj.cull == "front":
        return facing >= 0.0
    return np.zeros(facing.shape, bool)


def drawn_surfaces(scene: Scene, width: int, height: int) -> Surfaces:
    """The scene's surfaces as the rasteriser draws them (module docstring)."""
    matrices = scene.matrices(width, height)
    perspective = is_perspective(matrices.projection)
    forward = -matrices.view[2, :3]                     # unit view direction, world
    tris, tri_owner, normals, offsets, plane_owner = [], [], [], [], []
    for k, (obj, m) in enumerate(zip(scene.objects, matrices.objects)):
        if isinstance(obj.shape, Plane):
            plane = world_shape(obj.shape, m.model)     # m.model is camera-relative already
            facing = plane.offset if perspective else -float(forward @ plane.normal)
            if not _culled(obj, np.asarray([facing]))[0]:
                normals.append(plane.normal)
                offsets.append(plane.offset)
                plane_owner.append(k)
            continue
        if obj.tessellation is not None:            # the tessellation stages' triangles
            positions, _, faces = tessellated_mesh(obj, m, matrices.view, matrices.projection, height)
        else:
            positions, faces = obj.mesh.positions, obj.mesh.faces
        if not len(faces):
            continue
        world = np.asarray(positions, np.float64) @ m.model[:3, :3].T + m.model[:3, 3]
        corners = world[np.asarray(faces, np.int64)]
        n = np.cross(corners[:, 1] - corners[:, 0], corners[:, 2] - corners[:, 0])
        # The eye (the origin) or the view direction on the front side: GL's CCW in the window.
        facing = -np.einsum("ij,ij->i", corners[:, 0], n) if perspective else -(n @ forward)
        keep = ~_culled(obj, facing)
        tris.append(corners[keep])
        tri_owner.append(np.full(int(keep.sum()), k))
    camera = scene.camera
    return Surfaces(np.concatenate(tris) if tris else np.zeros((0, 3, 3)),
                    np.concatenate(tri_owner) if tri_owner else np.zeros(0, np.int64),
                    np.asarray(normals, np.float64).reshape(-1, 3),
                    np.asarray(offsets, np.float64), np.asarray(plane_owner, np.int64),
                    float(camera.near), float(camera.far))


def cast(surfaces: Surfaces, O: np.ndarray, D: np.ndarray):
    """The nearest drawn surface along rays O, D (R, 3) within near < s < far: (s (R,), inf on a
    miss; object (R,), -1 on a miss; the hit surface's plane n (R, 3), d (R,), n.P + d = 0)."""
    R = len(D)
    s = np.full(R, np.inf)
    owner = np.full(R, -1, np.int64)
    n, d = np.zeros((R, 3)), np.zeros(R)
    if surfaces.bvh is not None:
        hit, s_hit, _, triangle = closest_hit(surfaces.bvh, O, D, surfaces.near, surfaces.far,
                                              vertices=surfaces.triangles)
        s[hit] = s_hit[hit]
        owner[hit] = surfaces.triangle_object[triangle[hit]]
        corners = surfaces.triangles[triangle[hit]]
        n[hit] = np.cross(corners[:, 1] - corners[:, 0], corners[:, 2] - corners[:, 0])
        d[hit] = -np.einsum("ij,ij->i", n[hit], corners[:, 0])
    for normal, offset, k in zip(surfaces.plane_normal, surfaces.plane_offset, surfaces.plane_object):
        hit, s_hit = ray_plane(O, D, normal, offset, surfaces.near, np.minimum(s, surfaces.far))
        s[hit], owner[hit], n[hit], d[hit] = s_hit[hit], k, normal, offset
    return s, owner, n, d


@dataclass
class TruthDepth:
    """The ray-cast depth of every pixel, image rows (row 0 at the top)."""
    depth: np.ndarray              # (H, W) float64 view depth, inf where no surface is hit
    object: np.ndarray             # (H, W) int the object hit, -1 for none
    ambiguous: np.ndarray          # (H, W) bool silhouette pixels (module docstring)
    step: np.ndarray               # (H, W) float64 the depth buffer's step there (depth_step)


def depth_step(projection: np.ndarray, reversed_z: bool, depth: np.ndarray) -> np.ndarray:
    """The relative depth one float32 step of the depth buffer spans at view depth `depth`
    (..., float64): ulp(z_w) / (z |dz_w/dz|), z_w the window depth of the camera's depth
    mapping (docs/conventions.md, "Depth mapping"). Under GL's default mapping it grows with
    z / near (2^-24 z / near far from the camera: 2e-5 at 33 units with near 0.1); under
    reversed-Z it stays near 2^-24. No depth read back from a float32 buffer can be closer to
    the truth than half of it."""
    mapping = depth_mapping(reversed_z)
    p22, p23 = float(projection[2, 2]), float(projection[2, 3])
    scale = 1.0 / (1.0 - mapping.ndc_min)                  # dz_w / dz_ndc
    with np.errstate(all="ignore"):
        if is_perspective(projection):                      # z_ndc = -p22 + p23 / z
            z_ndc, slope = -p22 + p23 / depth, -p23 / depth ** 2
        else:                                               # z_ndc = -p22 z + p23
            z_ndc, slope = -p22 * depth + p23, np.full_like(depth, -p22)
        z_w = mapping.window_depth(z_ndc)
        ulp = np.spacing(np.abs(z_w).astype(np.float32)).astype(np.float64)
        return ulp / (np.abs(scale * slope) * depth)


def truth_depth(scene: Scene, width: int, height: int) -> TruthDepth:
    """Cast the centre ray and the four offset rays of every pixel (module docstring)."""
    surfaces = drawn_surfaces(scene, width, height)
    matrices = scene.matrices(width, height)
    uniforms = camera_ray_uniforms(matrices.view, matrices.projection, width, height)

    def rays(offset):
        O, D = camera_ray(pixel_windows(width, height, offset), uniforms)
        return O.reshape(-1, 3), D.reshape(-1, 3)

    O, D = rays((0.0, 0.0))
    s, owner, n, d = cast(surfaces, O, D)
    ambiguous = np.zeros(len(s), bool)
    with np.errstate(divide="ignore", invalid="ignore"):
        for offset in OFFSETS:
            O_k, D_k = rays(offset)
            s_k, owner_k, _, _ = cast(surfaces, O_k, D_k)
            # Along the offset ray, the centre hit's own plane.
            on_plane = -(np.einsum("ij,ij->i", O_k, n) + d) / np.einsum("ij,ij->i", D_k, n)
            same = (owner_k == owner) & ((owner < 0) | (np.abs(s_k - on_plane) <= SURFACE_JUMP * s))
            ambiguous |= ~same
    image = lambda a: a.reshape(height, width)[::-1]           # noqa: E731  GL rows -> image rows
    step = depth_step(matrices.projection, scene.camera.reversed_z, s)
    return TruthDepth(image(s), image(owner), image(ambiguous), image(step))


# depth_truth.png: a compared pixel grey, brighter with its error up to TARGET; the others:
OVER_TARGET = (255, 40, 40)        # red: a compared pixel whose error is over TARGET
AMBIGUOUS = (40, 80, 255)          # blue: a silhouette pixel, left out
ONE_HIT = (255, 0, 255)            # magenta: only one of the GPU and the rays hit (not silhouette)


@dataclass
class DepthTruth:
    """One frame's depth against the ray casts (depth_vs_truth); images (H, W), row 0 on top."""
    scene: str
    context: str
    relative: np.ndarray           # float64 e where both hit (silhouettes aside), NaN elsewhere
    step: np.ndarray               # float64 the depth buffer's relative step there (depth_step)
    object: np.ndarray             # int the object the ray hit, -1 for none
    ambiguous: np.ndarray          # bool silhouette pixels, left out
    gpu_only: np.ndarray           # bool the GPU drew where the ray hit nothing (not silhouette)
    truth_only: np.ndarray         # bool the ray hit where the GPU drew nothing (not silhouette)
    object_names: list[str]

    @staticmethod
    def _summary(e: np.ndarray) -> dict:
        if not len(e):
            return {"pixels": 0, "p999": None, "max": None}
        return {"pixels": int(len(e)), "p999": float(np.percentile(e, PERCENTILE)),
                "max": float(e.max())}

    def as_dict(self) -> dict:
        """The figures: over the compared pixels, the relative error's 99.9th percentile and
        maximum (None without any) and where the largest is (x, y image pixel), the 99.9th
        percentile of the error in the depth buffer's own steps (depth_step: about 1 where
        float32 depth is all that is left), the pixels left out and those only one side hit,
        and the summary per object."""
        compared = np.isfinite(self.relative)
        summary = self._summary(self.relative[compared])
        steps = self._summary(self.relative[compared] / self.step[compared])
        worst = None
        if summary["pixels"]:
            y, x = np.unravel_index(np.nanargmax(self.relative), self.relative.shape)
            worst = [int(x), int(y)]
        height, width = self.relative.shape
        per_object = {name: self._summary(self.relative[compared & (self.object == k)])
                      for k, name in enumerate(self.object_names)
                      if (compared & (self.object == k)).any()}
        return {"scene": self.scene, "size": [width, height], "context": self.context,
                "compared_pixels": summary["pixels"], "relative_p999": summary["p999"],
                "relative_max": summary["max"], "worst_pixel": worst,
                "depth_steps_p999": steps["p999"],
                "silhouette_pixels": int(self.ambiguous.sum()),
                "gpu_only_pixels": int(self.gpu_only.sum()),
                "truth_only_pixels": int(self.truth_only.sum()),
                "target_p999": TARGET,
                "meets_target": summary["p999"] is None or summary["p999"] <= TARGET,
                "objects": per_object}

    def line(self) -> str:
        """The figures in one readable line."""
        f = self.as_dict()
        width, height = f["size"]
        if not f["compared_pixels"]:
            return f"{self.scene}: no pixel where both the GPU and the ray casts hit"
        return (f"{self.scene} ({self.context}, {width}x{height}): relative depth error "
                f"p99.9 {f['relative_p999']:.3g} (target {TARGET:g}), max {f['relative_max']:.3g} "
                f"over {f['compared_pixels']} pixels; {f['silhouette_pixels']} silhouette pixels "
                f"left out; {f['gpu_only_pixels']} drawn where the rays miss, "
                f"{f['truth_only_pixels']} missed where they hit")

    def image(self) -> np.ndarray:
        """(H, W, 3) uint8: depth_truth.png (the colours above; black: neither hit)."""
        image = np.zeros((*self.relative.shape, 3), np.uint8)
        compared = np.isfinite(self.relative)
        grey = 40.0 + 175.0 * np.clip(np.nan_to_num(self.relative) / TARGET, 0.0, 1.0)
        image[compared] = grey[compared, None].astype(np.uint8)
        image[compared & (np.nan_to_num(self.relative) > TARGET)] = OVER_TARGET
        image[self.ambiguous] = AMBIGUOUS
        image[self.gpu_only | self.truth_only] = ONE_HIT
        return image


def compare_depth(scene: Scene, gpu_depth: np.ndarray, truth: TruthDepth, context: str = "") -> DepthTruth:
    """`gpu_depth` (H, W) float32 (a Frame's depth, inf where nothing was drawn) against `truth`."""
    gpu = np.asarray(gpu_depth, np.float64)
    gpu_hit, truth_hit = np.isfinite(gpu), np.isfinite(truth.depth)
    clear = ~truth.ambiguous
    both = gpu_hit & truth_hit & clear
    relative = np.full(gpu.shape, np.nan)
    relative[both] = np.abs(gpu[both] - truth.depth[both]) / truth.depth[both]
    return DepthTruth(scene.name, context, relative, truth.step, truth.object, truth.ambiguous,
                      gpu_hit & ~truth_hit & clear, truth_hit & ~gpu_hit & clear,
                      [o.name for o in scene.objects])


def depth_vs_truth(scene: Scene, width: int, height: int, context="auto",
                   frame=None) -> DepthTruth:
    """Render `scene` on the GPU (`context`: a context kind, "auto", "egl" or "osmesa", or a
    moderngl context to draw in; or take `frame`, a GPU Frame of this size with depth) and
    hold its depth against the ray casts."""
    if frame is None:
        from renderer.methods import open_renderer
        where = {"context_kind": context} if isinstance(context, str) else {"context": context}
        with open_renderer(scene, (width, height), **where) as gpu:
            frame = gpu.render(depth=True)
    kind = (frame.gl_info or {}).get("context", str(context))
    return compare_depth(scene, frame.depth, truth_depth(scene, width, height), kind)
