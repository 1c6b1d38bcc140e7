"""Built-in primitives as triangle meshes with exact normals.

Each returns a `Mesh` centred on the origin, faces counter-clockwise seen from outside.
Curved surfaces carry analytic normals (so Gouraud and Phong shade the true surface, not
averaged facets); flat faces get their own vertices so their normals stay flat. Every
primitive has UVs by docs/conventions.md's "Texture coordinates" (the sphere and plane rules
of renderer/core/uv_rules.py), a seam's vertices duplicated with u (or v) 0 and 1, so that no
triangle's UVs span the texture the wrong way round.
"""

from __future__ import annotations

import functools

import numpy as np

from renderer.core.scene import Mesh
from renderer.core.trimesh_import import trimesh
from renderer.core.uv_rules import plane_uv, sphere_uv, weld_corners


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


def _seam_columns(segments: int) -> tuple[np.ndarray, np.ndarray, int]:
    """A ring of `segments` angles 2 pi c / segments (c = 0 faces +z) laid out in the
    longitude rule's order (renderer/core/uv_rules.py): column k = 0..segments holds angle
    c_k = (shift + k) mod segments, so that u grows with k and the seam (-z) falls before
    column 0 and after column `segments`, a copy of column 0 one turn on. Returns (c_k, u_k,
    shift): u_k = (k + shift - segments / 2) / segments, which is the rule's 1/2 +
    lambda / (2 pi) (an even count has a column on the seam: u 0 and 1 exactly; an odd one
    has the seam inside the last cell, u from 1 - 1/(2 segments) to 1 + 1/(2 segments))."""
    shift = (segments + 1) // 2
    k = np.arange(segments + 1)
    return (shift + k) % segments, (k + shift - segments / 2) / segments, shift


def _seamed_grid_faces(rows: int, cols: int, row_shift: int, col_shift: int) -> np.ndarray:
    """_grid_faces of the (rows+1) x (cols+1) grid whose seam rows and columns are
    duplicated, in the order _grid_faces(rows, cols, wrap) gives the cells of the grid that
    wraps (cell (r, c) there is cell ((r - row_shift) % rows, (c - col_shift) % cols) here):
    the same triangles, drawn in the same order, as before the seams had UVs."""
    faces = _grid_faces(rows, cols, wrap_cols=False)
    r, c = np.divmod(np.arange(rows * cols), cols)
    order = (r - row_shift) % rows * cols + (c - col_shift) % cols
    return np.concatenate([faces[:rows * cols][order], faces[rows * cols:][order]])


def _drop_degenerate(mesh: Mesh) -> Mesh:
    p = mesh.positions[mesh.faces]
    area2 = np.linalg.norm(np.cross(p[:, 1] - p[:, 0], p[:, 2] - p[:, 0]), axis=1)
    return Mesh(mesh.positions, mesh.normals, mesh.faces[area2 > 1e-12], mesh.source,
                uvs=mesh.uvs)


def _drop_unused(mesh: Mesh) -> Mesh:
    """The mesh without the vertices no face uses, the others in their order."""
    used = np.zeros(len(mesh.positions), dtype=bool)
    used[mesh.faces] = True
    index = np.cumsum(used) - 1
    return Mesh(mesh.positions[used], mesh.normals[used], index[mesh.faces], mesh.source,
                uvs=mesh.uvs[used])


def uv_sphere(radius: float = 1.0, segments: int = 32, rings: int = 16) -> Mesh:
    """Latitude/longitude sphere: `segments` around the y axis, `rings` from pole to pole.

    UVs by the sphere rule (uv_rules.sphere_uv), exactly: u = k / segments on column k of
    _seam_columns, v = 1 - ring / rings; each pole has one vertex per segment, at u = the
    centre of its segment."""
    theta = np.linspace(0.0, np.pi, rings + 1)            # polar angle from +y
    column, u, shift = _seam_columns(segments)
    phi = np.linspace(0.0, 2 * np.pi, segments, endpoint=False)[column]
    t, p = np.meshgrid(theta, phi, indexing="ij")
    normals = np.stack([np.sin(t) * np.sin(p), np.cos(t), np.sin(t) * np.cos(p)], -1).reshape(-1, 3)
    faces = _seamed_grid_faces(rings, segments, 0, shift)
    uu = np.tile(u, (rings + 1, 1))
    centres = (u[:-1] + u[1:]) / 2
    uu[0, :-1] = centres           # the north pole's vertex k serves segment k (k + 1 unused)
    uu[-1, 1:] = centres           # the south pole's vertex k + 1 serves segment k (0 unused)
    vv = np.repeat(1.0 - np.arange(rings + 1) / rings, segments + 1).reshape(rings + 1, -1)
    uvs = np.stack([uu, vv], -1).reshape(-1, 2)
    mesh = Mesh(normals * radius, normals, faces, f"uv_sphere({segments}x{rings})", uvs=uvs)
    return _drop_unused(_drop_degenerate(mesh))


def icosphere(radius: float = 1.0, subdivisions: int = 2) -> Mesh:
    """Subdivided icosahedron (trimesh); 20 * 4^subdivisions triangles.

    UVs by the sphere rule per vertex (uv_rules.sphere_uv), made continuous per triangle
    (_sphere_corner_uvs): a triangle across the seam gets vertices of its own at u + 1, a
    vertex on the seam one with u = 0 and one with u = 1, a pole vertex one per triangle."""
    normals, faces, uvs = _unit_icosphere(subdivisions)
    return Mesh(normals * radius, normals.copy(), faces.copy(), f"icosphere({subdivisions})",
                uvs=uvs.copy())


@functools.lru_cache(maxsize=None)
def _unit_icosphere(subdivisions: int) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """The unit icosphere's normals (= positions), faces and UVs, made once per subdivision
    count (icosphere() scales copies: a scene of forty at 6 subdivisions builds one)."""
    ico = trimesh.creation.icosphere(subdivisions=subdivisions, radius=1.0)
    normals = np.asarray(ico.vertices, dtype=float)
    normals /= np.linalg.norm(normals, axis=1, keepdims=True)
    faces = np.asarray(ico.faces, dtype=np.int64)
    vertex, faces, uvs = weld_corners(faces, _sphere_corner_uvs(normals, faces))
    return normals[vertex], faces, uvs


def _sphere_corner_uvs(directions: np.ndarray, faces: np.ndarray) -> np.ndarray:
    """(F, 3, 2) UVs of each face's corners by the sphere rule, continuous across the face:
    each corner's u is taken within half a turn of the u of the face's centroid direction
    (u - 1 or u + 1 where it lies further), and a face left with some u < 0 moves one turn
    on, so that a face across the seam has u just past 1 and a corner on the seam u = 0 or
    1 by its face's side. A pole corner (x = z = 0) takes its face's mean u of the others."""
    d = directions[faces]                                             # (F, 3, 3)
    uv = sphere_uv(d.reshape(-1, 3)).reshape(*faces.shape, 2)
    centre = sphere_uv(d.sum(axis=1))[:, :1]                          # (F, 1)
    u = uv[..., 0]
    u = u - np.round(u - centre)                                      # within 1/2 of it
    u = u + (u.min(axis=1, keepdims=True) < 0.0)
    pole = (d[..., 0] == 0.0) & (d[..., 2] == 0.0)
    others = np.where(pole, 0.0, u).sum(axis=1, keepdims=True)
    count = (~pole).sum(axis=1, keepdims=True)
    uv[..., 0] = np.where(pole, others / np.maximum(count, 1), u)
    return uv


def plane(size: float = 2.0, segments: int = 1) -> Mesh:
    """A square in the xz plane facing +y, split into segments x segments cells; UVs by the
    plane rule (uv_rules.plane_uv: u = x, v = -z)."""
    s = np.linspace(-size / 2, size / 2, segments + 1)
    z, x = np.meshgrid(s, s, indexing="ij")
    positions = np.stack([x, np.zeros_like(x), z], -1).reshape(-1, 3)
    normals = np.tile([0.0, 1.0, 0.0], (len(positions), 1))
    faces = _grid_faces(segments, segments, wrap_cols=False)
    return Mesh(positions, normals, faces, f"plane({segments})",
                uvs=plane_uv(positions, (0.0, 1.0, 0.0)))


def _unit_cube() -> tuple[np.ndarray, np.ndarray, np.ndarray, np.ndarray]:
    """The cube of edge 2 (corners at +-1), four vertices per face: positions, normals, faces
    and UVs. Made once (cube() scales it: a scene of thousands of cubes builds each in
    microseconds). Each face's UVs are [0, 1]² seen from outside: v up (+y on the sides, -z
    on top, +z below) and u to the right (up x n)."""
    positions, normals, faces, uvs = [], [], [], []
    for axis in range(3):
        for sign in (1.0, -1.0):
            n = np.zeros(3)
            n[axis] = sign
            u = np.zeros(3)
            u[(axis + 1) % 3] = 1.0
            v = np.cross(n, u)
            corners = [n + (a * u + b * v) for a, b in ((-1, -1), (1, -1), (1, 1), (-1, 1))]
            up = np.array([0.0, 1.0, 0.0]) if axis != 1 else np.array([0.0, 0.0, -sign])
            right = np.cross(up, n)
            base = len(positions)
            positions += corners
            normals += [n] * 4
            uvs += [((c @ right + 1) / 2, (c @ up + 1) / 2) for c in corners]
            faces += [[base, base + 1, base + 2], [base, base + 2, base + 3]]
    return (np.array(positions), np.array(normals), np.array(faces, dtype=np.int64),
            np.array(uvs))


_UNIT_CUBE = _unit_cube()


def cube(size: float = 2.0) -> Mesh:
    """An axis-aligned cube of edge `size`, four vertices per face (the unit cube's corners
    times size / 2: the same numbers as placing each corner at n h + (a u + b v) h)."""
    positions, normals, faces, uvs = _UNIT_CUBE
    return Mesh(positions * (size / 2), normals.copy(), faces.copy(), "cube", uvs=uvs.copy())


def cylinder(radius: float = 1.0, height: float = 2.0, segments: int = 32) -> Mesh:
    """A capped cylinder along the y axis.

    UVs: the side by the longitude rule (u of _seam_columns, the seam column duplicated),
    v = 0 at the bottom rim and 1 at the top; the caps 1/2 + x / (2r) across and
    1/2 -+ z / (2r) up (top -, bottom +: seen from outside, v points away from +z on top)."""
    column, u, shift = _seam_columns(segments)
    angles = np.linspace(0.0, 2 * np.pi, segments, endpoint=False)
    ring = np.stack([np.sin(angles), np.zeros_like(angles), np.cos(angles)], -1)
    side_ring = ring[column]
    side_pos = np.concatenate([side_ring * radius + [0, -height / 2, 0],
                               side_ring * radius + [0, height / 2, 0]])
    side_nrm = np.concatenate([side_ring, side_ring])
    side_uvs = np.stack([np.tile(u, 2), np.repeat([0.0, 1.0], segments + 1)], -1)
    # Grid rows run bottom to top; the ring is CCW seen from +y, so flip to face outwards.
    side_faces = _seamed_grid_faces(1, segments, 0, shift)[:, ::-1]
    positions, normals, faces, uvs = [side_pos], [side_nrm], [side_faces], [side_uvs]
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
        uvs.append(np.stack([0.5 + cap[:, 0] / (2 * radius), 0.5 - sign * cap[:, 2] / (2 * radius)], -1))
        base += len(cap)
    return Mesh(np.concatenate(positions), np.concatenate(normals),
                np.concatenate(faces).astype(np.int64), f"cylinder({segments})",
                uvs=np.concatenate(uvs))


def torus(major_radius: float = 1.0, minor_radius: float = 0.35,
          major_segments: int = 48, minor_segments: int = 24) -> Mesh:
    """A torus around the y axis.

    UVs: u by the longitude rule around y (_seam_columns), v = the minor angle / (2 pi) from
    the outer equator upward; both seams duplicated (v = 0 and 1 on the outer equator)."""
    major, u, shift = _seam_columns(major_segments)
    angles = np.linspace(0.0, 2 * np.pi, major_segments, endpoint=False)[major]
    minor = np.linspace(0.0, 2 * np.pi, minor_segments, endpoint=False)
    tube = np.append(minor, minor[0])                                  # the seam ring again
    uu, vv = np.meshgrid(angles, tube, indexing="ij")
    centre = np.stack([np.sin(uu), np.zeros_like(uu), np.cos(uu)], -1) * major_radius
    normals = np.stack([np.cos(vv) * np.sin(uu), np.sin(vv), np.cos(vv) * np.cos(uu)], -1)
    positions = (centre + normals * minor_radius).reshape(-1, 3)
    faces = _seamed_grid_faces(major_segments, minor_segments, shift, 0)
    v = np.arange(minor_segments + 1) / minor_segments
    uvs = np.stack(np.meshgrid(u, v, indexing="ij"), -1).reshape(-1, 2)
    return Mesh(positions, normals.reshape(-1, 3), faces,
                f"torus({major_segments}x{minor_segments})", uvs=uvs)


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
