"""What the camera pass rasterises of each object in a frame.

An object of triangles draws its mesh through its matrices. An analytic plane
(renderer.core.scene.Plane) draws the convex polygon where the infinite plane meets the
camera's view volume (renderer/core/plane_clip.py), made again for every frame's matrices, so
that the rasteriser sees the surface the ray tracer intersects, to the view volume's edge.

Both pipelines draw these (renderer/gpu/pipeline.py each update(), reference/pipeline.py each
frame), and so does everything that asks what a camera's frame draws: the culling of objects
outside the view (renderer/core/visibility.py), the memory estimates (`triangle_bound`,
renderer/core/memory.py), `renderer shaders`. An object's own `mesh` stays as it is: for a
plane, the square of renderer/core/shapes.py, which the shadow passes still draw.

A plane's polygon is in camera-relative world coordinates and drawn with the identity model
and normal matrices (IDENTITY): each vertex is rounded to float32 once, no farther from the
camera than the view volume reaches. The volume is the camera's widened by one pixel on
every side (`camera_volume`): a sample offset moves the view by at most half a pixel and the
polygon is not made again for one (GpuRenderer.render(sample_offset=...) uploads only the
projection), so the same polygon serves every offset, and GL clips the margin as it clips any
triangle. In depth it is the camera's near..far (reversed-Z's 0 <= z <= w too).

    drawn = drawn_meshes(scene, scene.matrices(640, 480))    # [DrawnMesh(mesh, matrices)]
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from renderer.core import transforms
from renderer.core.gl_rules import depth_mapping
from renderer.core.plane_clip import MAX_POLYGON_TRIANGLES, object_plane_polygon
from renderer.core.scene import FrameMatrices, Mesh, ObjectMatrices, Plane, Scene, SceneObject

# A plane's polygon is drawn as it is: camera-relative world, unit normals.
IDENTITY = ObjectMatrices(np.eye(4), np.eye(3))


@dataclass
class DrawnMesh:
    """One object as the camera pass draws it: `mesh` through `matrices` (the model matrix,
    camera-relative, and the normal matrix of the vertex stage)."""
    mesh: Mesh
    matrices: ObjectMatrices


def is_plane(obj: SceneObject) -> bool:
    """Whether the camera pass draws `obj` as a plane's polygon (its shape is a Plane)."""
    return isinstance(obj.shape, Plane)


def nothing(source: str) -> Mesh:
    """A mesh without vertices or triangles (with empty UVs, so that a textured material's
    lookup has its array)."""
    return Mesh(np.zeros((0, 3)), np.zeros((0, 3)), np.zeros((0, 3), np.int64), source,
                uvs=np.zeros((0, 2)))


def camera_volume(matrices: FrameMatrices) -> np.ndarray:
    """(4, 4) clip_from_world of the camera's view volume widened by one pixel on every side
    (the module docstring), unjittered, float64."""
    width, height = matrices.size
    widen = transforms.scale(1.0 / (1.0 + 2.0 / width), 1.0 / (1.0 + 2.0 / height), 1.0)
    return widen @ matrices.camera_projection @ matrices.view


def drawn_meshes(scene: Scene, matrices: FrameMatrices) -> list[DrawnMesh]:
    """Each object of `scene` as the camera pass draws it with `matrices` (Scene.matrices):
    its mesh and matrices, or a plane's polygon (an empty mesh where the plane misses the
    view). A ValueError where a transform flattens a plane (Scene.world_shape)."""
    volume, mapping = None, depth_mapping(scene.camera.reversed_z)
    drawn = []
    for obj, object_matrices in zip(scene.objects, matrices.objects):
        if not is_plane(obj):
            drawn.append(DrawnMesh(obj.mesh, object_matrices))
            continue
        volume = camera_volume(matrices) if volume is None else volume
        polygon = object_plane_polygon(obj.shape, object_matrices.model, volume, mapping)
        drawn.append(DrawnMesh(nothing("a plane outside the view") if polygon is None else polygon,
                               IDENTITY))
    return drawn


def triangle_bound(obj: SceneObject) -> int:
    """The most triangles the camera pass draws of `obj` in any frame: a plane's polygon's at
    most MAX_POLYGON_TRIANGLES, else its mesh's."""
    return MAX_POLYGON_TRIANGLES if is_plane(obj) else obj.mesh.triangle_count
