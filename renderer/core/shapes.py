"""The meshes of the analytic shapes (renderer.core.scene.Sphere, Plane), as a SceneObject's `mesh`.

The ray tracer intersects the shape itself. The rasteriser draws:

- for a sphere, this icosphere (primitives.icosphere: 20 · 4^subdivisions triangles, default
  SPHERE_SUBDIVISIONS) of the sphere's radius moved to its centre, with exact normals, in
  every pass;
- for a plane, in the camera pass, not a mesh made here but each frame's polygon where the
  infinite plane meets the view volume (renderer/core/plane_clip.py, renderer/core/drawn.py),
  so that it sees the surface the ray tracer intersects to the view's edge. The square made
  here (side `size`, default PLANE_SIZE object units, segments × segments cells, centred on
  the point of the plane nearest the object's origin, -d N / |N|², counter-clockwise seen from
  the side N points to) is what the shadow passes draw (renderer/core/shadows.py), until
  they too clip the plane to each light's view.

Both are deterministic and counted before they are built (TRIANGLES, as primitives.TRIANGLES;
renderer/core/memory.py). Their UVs are the shapes' own (renderer/core/uv_rules.py), which the
ray tracer computes at its hits: the sphere's from the direction from its centre, the plane's
from the object-space point (the polygon's too), so every rendering textures a shape alike.
"""

from __future__ import annotations

import numpy as np

from renderer.core.primitives import icosphere, plane as plane_primitive
from renderer.core.scene import Mesh, Plane, Sphere
from renderer.core.uv_rules import plane_uv

SPHERE_SUBDIVISIONS = 3          # 1280 triangles
PLANE_SIZE = 1000.0
PLANE_SEGMENTS = 1

TRIANGLES = {
    "sphere": lambda subdivisions=SPHERE_SUBDIVISIONS, **_: 20 * 4 ** subdivisions,
    "plane": lambda segments=PLANE_SEGMENTS, **_: 2 * segments * segments,
}


def sphere_mesh(sphere: Sphere, subdivisions: int = SPHERE_SUBDIVISIONS) -> Mesh:
    mesh = icosphere(float(sphere.radius), subdivisions)
    positions = mesh.positions + np.asarray(sphere.centre, dtype=np.float64)
    return Mesh(positions, mesh.normals, mesh.faces, f"sphere(subdivisions={subdivisions})",
                uvs=mesh.uvs)


def plane_basis(normal) -> np.ndarray:
    """A rotation (3, 3) whose columns (u, n, w) are unit, right-handed, n along `normal`:
    it takes the +y-facing xz square of primitives.plane onto the plane, keeping its winding.
    u = n × z (n × x where n is within about 8 degrees of ±z); a normal along +y gives the
    identity."""
    n = np.asarray(normal, dtype=np.float64)
    n = n / np.linalg.norm(n)
    reference = np.array([0.0, 0.0, 1.0]) if abs(n[2]) < 0.99 else np.array([1.0, 0.0, 0.0])
    u = np.cross(n, reference)
    u /= np.linalg.norm(u)
    w = np.cross(u, n)
    return np.stack([u, n, w], axis=1)


def plane_mesh(shape: Plane, size: float = PLANE_SIZE, segments: int = PLANE_SEGMENTS) -> Mesh:
    n = np.asarray(shape.normal, dtype=np.float64)
    foot = -float(shape.offset) * n / float(n @ n)
    basis = plane_basis(n)
    square = plane_primitive(size, segments)
    positions = square.positions @ basis.T + foot
    normals = np.tile(basis[:, 1], (len(positions), 1))
    return Mesh(positions, normals, square.faces, f"plane(size={size:g}, segments={segments})",
                uvs=plane_uv(positions, n))
