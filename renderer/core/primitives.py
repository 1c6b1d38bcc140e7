"""Built-in primitives as triangle meshes with exact normals.

Each returns a `Mesh` centred on the origin, faces counter-clockwise seen from outside.
Curved surfaces carry analytic normals (so Gouraud and Phong shade the true surface, not
averaged facets); flat faces get their own vertices so their normals stay flat.
"""

from __future__ import annotations

import numpy as np
import trimesh

from renderer.core.scene import Mesh


def _grid_faces(rows: int, cols: int, wrap_cols: bool) -> np.ndarray:
    """Two CCW triangles per cell of a (rows+1) x (cols(+1)) vertex grid laid out row-major."""
    stride = cols if wrap_cols else cols + 1
    r, c = np.meshgrid(np.arange(rows), np.arange(cols), indexing="ij")
    a = r * stride + c
    b = r * stride + (c + 1) % stride if wrap_cols else a + 1
    d = a + stride
    e = b + stride
    quads = np.stack([a, d, e, b], axis=-1).reshape(-1, 4)
    return np.concatenate([quads[:, [0, 1, 2]], quads[:, [0, 2, 3]]]).astype(np.int64)


def _drop_degenerate(mesh: Mesh) -> Mesh:
    p = mesh.positions[mesh.faces]
    area2 = np.linalg.norm(np.cross(p[:, 1] - p[:, 0], p[:, 2] - p[:, 0]), axis=1)
    return Mesh(mesh.positions, mesh.normals, mesh.faces[area2 > 1e-12], mesh.source)


def uv_sphere(radius: float = 1.0, segments: int = 32, rings: int = 16) -> Mesh:
    """Latitude/longitude sphere: `segments` around the y axis, `rings` from pole to pole."""
    theta = np.linspace(0.0, np.pi, rings + 1)            # polar angle from +y
    phi = np.linspace(0.0, 2 * np.pi, segments, endpoint=False)
    t, p = np.meshgrid(theta, phi, indexing="ij")
    normals = np.stack([np.sin(t) * np.sin(p), np.cos(t), np.sin(t) * np.cos(p)], -1).reshape(-1, 3)
    faces = _grid_faces(rings, segments, wrap_cols=True)
    return _drop_degenerate(Mesh(normals * radius, normals, faces, f"uv_sphere({segments}x{rings})"))


def icosphere(radius: float = 1.0, subdivisions: int = 2) -> Mesh:
    """Subdivided icosahedron (trimesh); 20 * 4^subdivisions triangles."""
    ico = trimesh.creation.icosphere(subdivisions=subdivisions, radius=1.0)
    normals = np.asarray(ico.vertices, dtype=float)
    normals /= np.linalg.norm(normals, axis=1, keepdims=True)
    return Mesh(normals * radius, normals, np.asarray(ico.faces, dtype=np.int64),
                f"icosphere({subdivisions})")


def plane(size: float = 2.0, segments: int = 1) -> Mesh:
    """A square in the xz plane facing +y, split into segments x segments cells."""
    s = np.linspace(-size / 2, size / 2, segments + 1)
    z, x = np.meshgrid(s, s, indexing="ij")
    positions = np.stack([x, np.zeros_like(x), z], -1).reshape(-1, 3)
    normals = np.tile([0.0, 1.0, 0.0], (len(positions), 1))
    faces = _grid_faces(segments, segments, wrap_cols=False)
    return Mesh(positions, normals, faces, f"plane({segments})")


def _unit_cube() -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """The cube of edge 2 (corners at +-1), four vertices per face: positions, normals, faces.
    Made once (cube() scales it: a scene of thousands of cubes builds each in microseconds)."""
    positions, normals, faces = [], [], []
    for axis in range(3):
        for sign in (1.0, -1.0):
            n = np.zeros(3)
            n[axis] = sign
            u = np.zeros(3)
            u[(axis + 1) % 3] = 1.0
            v = np.cross(n, u)
            corners = [n + (a * u + b * v) for a, b in ((-1, -1), (1, -1), (1, 1), (-1, 1))]
            base = len(positions)
            positions += corners
            normals += [n] * 4
            faces += [[base, base + 1, base + 2], [base, base + 2, base + 3]]
    return np.array(positions), np.array(normals), np.array(faces, dtype=np.int64)


_UNIT_CUBE = _unit_cube()


def cube(size: float = 2.0) -> Mesh:
    """An axis-aligned cube of edge `size`, four vertices per face (the unit cube's corners
    times size / 2: the same numbers as placing each corner at n h + (a u + b v) h)."""
    positions, normals, faces = _UNIT_CUBE
    return Mesh(positions * (size / 2), normals.copy(), faces.copy(), "cube")


def cylinder(radius: float = 1.0, height: float = 2.0, segments: int = 32) -> Mesh:
    """A capped cylinder along the y axis."""
    phi = np.linspace(0.0, 2 * np.pi, segments, endpoint=False)
    ring = np.stack([np.sin(phi), np.zeros_like(phi), np.cos(phi)], -1)
    side_pos = np.concatenate([ring * radius + [0, -height / 2, 0], ring * radius + [0, height / 2, 0]])
    side_nrm = np.concatenate([ring, ring])
    # Grid rows run bottom to top; the ring is CCW seen from +y, so flip to face outwards.
    side_faces = _grid_faces(1, segments, wrap_cols=True)[:, ::-1]
    positions, normals, faces = [side_pos], [side_nrm], [side_faces]
    base = len(side_pos)
    for sign in (1.0, -1.0):
        centre = np.array([[0.0, sign * height / 2, 0.0]])
        cap = np.concatenate([centre, ring * radius + centre])
        idx = np.arange(segments)
        tri = np.stack([np.zeros(segments, int), 1 + idx, 1 + (idx + 1) % segments], -1)
        if sign < 0:
            tri = tri[:, ::-1]
        positions.append(cap)
        normals.append(np.tile([0.0, sign, 0.0], (len(cap), 1)))
        faces.append(tri + base)
        base += len(cap)
    return Mesh(np.concatenate(positions), np.concatenate(normals),
                np.concatenate(faces).astype(np.int64), f"cylinder({segments})")


def torus(major_radius: float = 1.0, minor_radius: float = 0.35,
          major_segments: int = 48, minor_segments: int = 24) -> Mesh:
    """A torus around the y axis."""
    u = np.linspace(0.0, 2 * np.pi, major_segments, endpoint=False)   # around y
    v = np.linspace(0.0, 2 * np.pi, minor_segments, endpoint=False)   # around the tube
    uu, vv = np.meshgrid(u, v, indexing="ij")
    centre = np.stack([np.sin(uu), np.zeros_like(uu), np.cos(uu)], -1) * major_radius
    normals = np.stack([np.cos(vv) * np.sin(uu), np.sin(vv), np.cos(vv) * np.cos(uu)], -1)
    positions = (centre + normals * minor_radius).reshape(-1, 3)
    faces = _grid_faces(major_segments, minor_segments, wrap_cols=True)
    # wrap the major direction too: the last row of cells joins row 0
    faces %= major_segments * minor_segments
    return Mesh(positions, normals.reshape(-1, 3), faces, f"torus({major_segments}x{minor_segments})")


# The most triangles each primitive makes with given arguments, known before it is built (a
# scene's memory is estimated before any mesh exists: renderer/core/memory.py).
TRIANGLES = {
    "uv_sphere": lambda segments=32, rings=16, **_: 2 * segments * rings,
    "icosphere": lambda subdivisions=2, **_: 20 * 4 ** subdivisions,
    "plane": lambda segments=1, **_: 2 * segments * segments,
    "cube": lambda **_: 12,
    "cylinder": lambda segments=32, **_: 4 * segments,
    "torus": lambda major_segments=48, minor_segments=24, **_: 2 * major_segments * minor_segments,
}


PRIMITIVES = {
    "uv_sphere": uv_sphere,
    "icosphere": icosphere,
    "plane": plane,
    "cube": cube,
    "cylinder": cylinder,
    "torus": torus,
}
