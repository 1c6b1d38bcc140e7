"""Write the meshes of the extreme scenes in assets/extreme/meshes/ and their textures in
assets/extreme/textures/ (deterministic output).

    python tools/make_extreme_meshes.py

slivers.obj             a disc as a fan of 240 thin triangles (sub-pixel at the centre), each
                        followed by two zero-area ones, a repeated index and a repeated
                        position; four collinear ones along the axes; file normals
duplicate_vertices.obj  an octahedron with three vertices of its own per face (no normals in
                        the file: the loader merges them) and every face written twice
bad_normals.obj         a 16 x 8 sphere whose file normals are zero-length (every fifth),
                        1000 times too long or 1000 times too short
nan_vertex.obj          one triangle with a NaN vertex: refused when a scene is loaded
huge_uvs.obj            two unit squares facing +z whose texture coordinates are near
                        (+1e6, -1e6) and (-1e6, +1e6), one repeat across each
npot_37x23.png          (textures/) a 37 x 23 image, sides neither powers of two nor even: a
                        red ramp along u, a green ramp along v, a blue grid every 6 texels
"""

from __future__ import annotations

from pathlib import Path

import numpy as np

MESHES = Path(__file__).resolve().parent.parent / "assets" / "extreme" / "meshes"
TEXTURES = MESHES.parent / "textures"


def write_obj(path: Path, positions, faces, comment: str, normals=None, uvs=None) -> None:
    """OBJ with 9 significant digits (slivers are narrower than make_meshes.py's 5 decimals);
    with `uvs`, one `vt` per vertex (and then normals too)."""
    lines = [f"# {comment}", "# written by tools/make_extreme_meshes.py"]
    lines += ["v " + " ".join(f"{c:.9g}" for c in p) for p in positions]
    if uvs is not None:
        lines += ["vt " + " ".join(f"{c:.9g}" for c in uv) for uv in uvs]
        lines += ["vn " + " ".join(f"{c:.9g}" for c in n) for n in normals]
        lines += ["f " + " ".join(f"{i + 1}/{i + 1}/{i + 1}" for i in face) for face in faces]
    elif normals is not None:
        lines += ["vn " + " ".join(f"{c:.9g}" for c in n) for n in normals]
        lines += ["f " + " ".join(f"{i + 1}//{i + 1}" for i in face) for face in faces]
    else:
        lines += ["f " + " ".join(str(i + 1) for i in face) for face in faces]
    path.write_text("\n".join(lines) + "\n")


def slivers(count: int = 240):
    """Fan around the origin in the xy plane facing +z; after each fan triangle (0, a, b),
    a zero-area (0, a, a) and (0, a, a') with a' a copy of a. Collinear triangles (0, m, a),
    m halfway to a, only along the axes: there every transform keeps them exactly
    collinear, while elsewhere float rounding may give them a sliver of area in one
    pipeline and not in the other (GL promises nothing for such triangles)."""
    angles = np.linspace(0.0, 2 * np.pi, count, endpoint=False)
    rim = np.round(np.stack([np.cos(angles), np.sin(angles), np.zeros(count)], -1), 12) + 0.0
    positions = np.vstack([[[0.0, 0.0, 0.0]], rim, rim, rim / 2])
    faces = []
    for k in range(count):
        a, b, copy, m = 1 + k, 1 + (k + 1) % count, 1 + count + k, 1 + 2 * count + k
        faces += [[0, a, b], [0, a, a], [0, a, copy]]
        if k % (count // 4) == 0:
            faces.append([0, m, a])
    normals = np.tile([0.0, 0.0, 1.0], (len(positions), 1))
    return positions, np.array(faces), normals


def duplicate_vertices():
    """Octahedron, counter-clockwise from outside, every face with its own vertices, twice."""
    corners = np.array([[1, 0, 0], [-1, 0, 0], [0, 1, 0], [0, -1, 0], [0, 0, 1], [0, 0, -1]], float)
    faces = [[0, 2, 4], [2, 1, 4], [1, 3, 4], [3, 0, 4], [2, 0, 5], [1, 2, 5], [3, 1, 5], [0, 3, 5]]
    positions = corners[np.array(faces).reshape(-1)]
    own = np.arange(len(positions)).reshape(-1, 3)
    return positions, np.vstack([own, own])


def bad_normals(segments: int = 16, rings: int = 8):
    theta = np.linspace(0.0, np.pi, rings + 1)[1:-1]               # no pole vertices
    phi = np.linspace(0.0, 2 * np.pi, segments, endpoint=False)
    t, p = np.meshgrid(theta, phi, indexing="ij")
    unit = np.stack([np.sin(t) * np.sin(p), np.cos(t), np.sin(t) * np.cos(p)], -1).reshape(-1, 3)
    faces = []
    for r in range(rings - 2):
        for c in range(segments):
            a, b = r * segments + c, r * segments + (c + 1) % segments
            faces += [[a, a + segments, b + segments], [a, b + segments, b]]
    scale = np.array([1e-3, 1e3, 1.0, 1e3, 0.0])[np.arange(len(unit)) % 5]   # 0: zero-length
    return unit, np.array(faces), unit * scale[:, None]


def huge_uvs(repeats: float = 1.0):
    """Two squares of side 1 in the xy plane facing +z, 0.2 apart, counter-clockwise from the
    front; texture coordinates from (1e6, -1e6) (left) and (-1e6, 1e6) (right), `repeats`
    across each. float32 holds 1e6 to 1/16: a repeat has 16 distinct coordinates there."""
    corners = np.array([[0.0, 0.0], [1.0, 0.0], [1.0, 1.0], [0.0, 1.0]])
    positions, uvs, faces = [], [], []
    for k, (x0, origin) in enumerate(((-1.1, (1e6, -1e6)), (0.1, (-1e6, 1e6)))):
        positions += [[x0 + a, b - 0.5, 0.0] for a, b in corners]
        uvs += [[origin[0] + repeats * a, origin[1] + repeats * b] for a, b in corners]
        faces += [[4 * k, 4 * k + 1, 4 * k + 2], [4 * k, 4 * k + 2, 4 * k + 3]]
    return np.array(positions), np.array(faces), np.tile([0.0, 0.0, 1.0], (8, 1)), np.array(uvs)


def npot_image(width: int = 37, height: int = 23) -> np.ndarray:
    """(height, width, 3) uint8 sRGB, row 0 at the top: red grows along u (left to right),
    green along v (bottom to top), blue lines every 6 texels from the bottom-left."""
    row, column = np.mgrid[0:height, 0:width]
    up = height - 1 - row                                     # texel row from the bottom
    image = np.zeros((height, width, 3), dtype=np.uint8)
    image[..., 0] = np.round(40 + 200 * column / (width - 1))
    image[..., 1] = np.round(40 + 200 * up / (height - 1))
    image[..., 2] = np.where((column % 6 == 0) | (up % 6 == 0), 230, 60)
    return image


def main() -> None:
    from PIL import Image

    MESHES.mkdir(parents=True, exist_ok=True)
    TEXTURES.mkdir(parents=True, exist_ok=True)
    positions, faces, normals = slivers()
    write_obj(MESHES / "slivers.obj", positions, faces, "fan of slivers with zero-area triangles",
              normals)
    write_obj(MESHES / "duplicate_vertices.obj", *duplicate_vertices(),
              "octahedron: three vertices per face, every face twice")
    positions, faces, normals = bad_normals()
    write_obj(MESHES / "bad_normals.obj", positions, faces,
              "sphere with zero-length and non-unit file normals", normals)
    (MESHES / "nan_vertex.obj").write_text(
        "# a triangle with a NaN vertex: the loader refuses it\n"
        "# written by tools/make_extreme_meshes.py\n"
        "v 0 0 0\nv 1 0 0\nv nan 1 0\nf 1 2 3\n")
    positions, faces, normals, uvs = huge_uvs()
    write_obj(MESHES / "huge_uvs.obj", positions, faces, "two squares with texture coordinates "
              "near +-1e6", normals, uvs)
    Image.fromarray(npot_image(), "RGB").save(TEXTURES / "npot_37x23.png", optimize=True)
    for path in sorted([*MESHES.iterdir(), *TEXTURES.iterdir()]):
        print(f"{path.relative_to(MESHES.parent.parent.parent)}  {path.stat().st_size} bytes")


if __name__ == "__main__":
    main()
