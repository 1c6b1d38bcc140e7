"""Write the generated meshes in assets/meshes/ (run from anywhere; the output is deterministic).

    python tools/make_meshes.py

torus_knot.obj   a (2, 3) torus knot tube with analytic vertex normals (scene mesh_file)
bowl.obj         an open hemisphere, normals pointing out of the sphere (scene open_mesh_inside)
octahedron.ply   ASCII PLY with per-vertex normals (tests, scene mesh_file)
tetrahedron.stl  ASCII STL, three vertices per facet as STL has it (tests, scene mesh_file)
checker_dark.obj, checker_light.obj
                 the dark and the light squares of an 8 x 8 checkerboard (scene tir_bubble:
                 there are no textures, so the pattern is geometry, one mesh per colour)

Every face is counter-clockwise seen from the side its normals point to; main() checks it.
"""

from __future__ import annotations

from pathlib import Path

import numpy as np

MESHES = Path(__file__).resolve().parent.parent / "assets" / "meshes"


def grid_faces(rows: int, cols: int, wrap_rows: bool) -> np.ndarray:
    """Two triangles per cell of a rows x cols vertex grid, columns wrapping around."""
    faces = []
    row_count = rows if wrap_rows else rows - 1
    for r in range(row_count):
        for c in range(cols):
            a = r * cols + c
            b = r * cols + (c + 1) % cols
            d = ((r + 1) % rows) * cols + c
            e = ((r + 1) % rows) * cols + (c + 1) % cols
            faces += [[a, b, e], [a, e, d]]
    return np.array(faces, dtype=np.int64)


def torus_knot(p: int = 2, q: int = 3, radius: float = 1.0, tube: float = 0.22,
               segments: int = 180, sides: int = 14):
    """Tube of `tube` radius around the (p, q) torus knot on a torus of major radius
    `radius` and minor radius radius/2. The Frenet frame is periodic for a torus knot
    (its curvature never vanishes), so the tube closes without a twist at the seam."""
    t = np.linspace(0.0, 2 * np.pi, segments, endpoint=False)

    def curve(t):
        r = radius + 0.5 * radius * np.cos(q * t)
        return np.stack([r * np.cos(p * t), 0.5 * radius * np.sin(q * t), r * np.sin(p * t)], -1)

    h = 1e-4
    d1 = (curve(t + h) - curve(t - h)) / (2 * h)                       # first derivative
    d2 = (curve(t + h) - 2 * curve(t) + curve(t - h)) / h ** 2        # second derivative
    tangent = d1 / np.linalg.norm(d1, axis=1, keepdims=True)
    binormal = np.cross(d1, d2)
    binormal /= np.linalg.norm(binormal, axis=1, keepdims=True)
    normal = np.cross(binormal, tangent)
    v = np.linspace(0.0, 2 * np.pi, sides, endpoint=False)
    ring = (np.cos(v)[None, :, None] * normal[:, None, :]
            + np.sin(v)[None, :, None] * binormal[:, None, :])          # (segments, sides, 3)
    positions = (curve(t)[:, None, :] + tube * ring).reshape(-1, 3)
    return positions, ring.reshape(-1, 3), grid_faces(segments, sides, wrap_rows=True)


def bowl(radius: float = 1.0, segments: int = 32, rings: int = 8):
    """The lower half of a sphere (y <= 0), open at the top, rim at y = 0."""
    theta = np.linspace(np.pi / 2, np.pi, rings + 1)[:-1]              # rim down to above the pole
    phi = np.linspace(0.0, 2 * np.pi, segments, endpoint=False)
    tt, pp = np.meshgrid(theta, phi, indexing="ij")
    ring_normals = np.stack([np.sin(tt) * np.sin(pp), np.cos(tt), np.sin(tt) * np.cos(pp)], -1)
    normals = np.concatenate([ring_normals.reshape(-1, 3), [[0.0, -1.0, 0.0]]])
    faces = list(grid_faces(rings, segments, wrap_rows=False))
    pole = len(normals) - 1
    last = (rings - 1) * segments
    for c in range(segments):
        faces.append([last + c, last + (c + 1) % segments, pole])
    # rows run from the rim downwards, which makes the grid clockwise seen from outside
    return normals * radius, normals, np.array(faces, dtype=np.int64)[:, ::-1].copy()


def octahedron():
    positions = np.array([[1, 0, 0], [-1, 0, 0], [0, 1, 0], [0, -1, 0], [0, 0, 1], [0, 0, -1]],
                         dtype=float)
    faces = np.array([[0, 2, 4], [4, 2, 1], [1, 2, 5], [5, 2, 0],
                      [4, 3, 0], [1, 3, 4], [5, 3, 1], [0, 3, 5]], dtype=np.int64)
    return positions, positions.copy(), faces


def tetrahedron():
    positions = np.array([[1, 1, 1], [1, -1, -1], [-1, 1, -1], [-1, -1, 1]], dtype=float)
    faces = np.array([[0, 1, 2], [0, 2, 3], [0, 3, 1], [1, 3, 2]], dtype=np.int64)
    return positions, faces


def checker(squares: int = 8, side: float = 1.0):
    """The two colours of a squares x squares board of `side`-long squares in the xz plane,
    facing +y, centred on the origin: [(positions, normals, faces) of the squares whose
    column + row is even, ... odd]. Each square has its own four corners (two triangles), so
    the two meshes share no vertex; the corner square at -x, -z is of the first colour."""
    boards = []
    for parity in (0, 1):
        corners, faces = [], []
        for row in range(squares):
            for col in range(squares):
                if (row + col) % 2 != parity:
                    continue
                x0, z0 = (col - squares / 2) * side, (row - squares / 2) * side
                a = len(corners)
                corners += [(x0, 0.0, z0), (x0, 0.0, z0 + side), (x0 + side, 0.0, z0 + side),
                            (x0 + side, 0.0, z0)]
                faces += [[a, a + 1, a + 2], [a, a + 2, a + 3]]    # CCW seen from +y
        positions = np.array(corners, dtype=float)
        normals = np.tile([0.0, 1.0, 0.0], (len(positions), 1))
        boards.append((positions, normals, np.array(faces, dtype=np.int64)))
    return boards


def check_outward(positions, normals, faces, name):
    """Each face's winding normal agrees with its vertices' normals (CCW seen from outside)."""
    tri = positions[faces]
    face_normal = np.cross(tri[:, 1] - tri[:, 0], tri[:, 2] - tri[:, 0])
    agree = np.einsum("fj,fj->f", face_normal, normals[faces].mean(axis=1))
    assert (agree > 0).all(), f"{name}: {int((agree <= 0).sum())} faces wound the wrong way"


def write_obj(path: Path, positions, normals, faces, comment: str) -> None:
    lines = [f"# {comment}", f"# written by tools/make_meshes.py: {len(positions)} vertices, "
             f"{len(faces)} triangles"]
    lines += [f"v {x:.5f} {y:.5f} {z:.5f}" for x, y, z in positions]
    lines += [f"vn {x:.5f} {y:.5f} {z:.5f}" for x, y, z in normals]
    lines += ["f " + " ".join(f"{i + 1}//{i + 1}" for i in face) for face in faces]
    path.write_text("\n".join(lines) + "\n")


def write_ply(path: Path, positions, normals, faces) -> None:
    header = ["ply", "format ascii 1.0", "comment written by tools/make_meshes.py",
              f"element vertex {len(positions)}",
              "property float x", "property float y", "property float z",
              "property float nx", "property float ny", "property float nz",
              f"element face {len(faces)}", "property list uchar int vertex_indices", "end_header"]
    body = [" ".join(f"{c:g}" for c in (*p, *n)) for p, n in zip(positions, normals)]
    body += ["3 " + " ".join(str(i) for i in face) for face in faces]
    path.write_text("\n".join(header + body) + "\n")


def write_stl(path: Path, positions, faces) -> None:
    lines = ["solid tetrahedron"]
    for face in faces:
        a, b, c = positions[face]
        n = np.cross(b - a, c - a)
        n /= np.linalg.norm(n)
        lines.append(f"  facet normal {n[0]:g} {n[1]:g} {n[2]:g}")
        lines.append("    outer loop")
        lines += [f"      vertex {x:g} {y:g} {z:g}" for x, y, z in (a, b, c)]
        lines += ["    endloop", "  endfacet"]
    lines.append("endsolid tetrahedron")
    path.write_text("\n".join(lines) + "\n")


def main() -> None:
    MESHES.mkdir(parents=True, exist_ok=True)
    knot = torus_knot()
    check_outward(*knot, "torus_knot")
    write_obj(MESHES / "torus_knot.obj", *knot, "(2, 3) torus knot tube, analytic normals")
    cup = bowl()
    check_outward(*cup, "bowl")
    write_obj(MESHES / "bowl.obj", *cup, "open hemisphere (bowl), normals out of the sphere")
    octa = octahedron()
    check_outward(*octa, "octahedron")
    write_ply(MESHES / "octahedron.ply", *octa)
    tetra_positions, tetra_faces = tetrahedron()
    check_outward(tetra_positions, tetra_positions, tetra_faces, "tetrahedron")
    write_stl(MESHES / "tetrahedron.stl", tetra_positions, tetra_faces)
    for colour, board in zip(("dark", "light"), checker()):
        check_outward(*board, f"checker_{colour}")
        write_obj(MESHES / f"checker_{colour}.obj", *board,
                  f"the {colour} squares of an 8 x 8 checkerboard of unit squares in y = 0, facing +y")
    for path in sorted(MESHES.iterdir()):
        print(f"{path.relative_to(MESHES.parent.parent)}  {path.stat().st_size} bytes")


if __name__ == "__main__":
    main()
