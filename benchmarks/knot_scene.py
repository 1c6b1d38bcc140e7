"""Issue 32's scene: the built-in `mesh_shadow` (a torus knot over a floor plane, a directional
and a point light, shadows) with its 5,040-triangle knot made again at 512 x 128: 131,072
triangles, the size of a user's scanned mesh. The knot is written as a binary PLY beside the
scene file, in a folder of the caller's (tools/make_meshes.py's torus_knot, the built-in mesh's
maker), so that loading it is timed as a user's mesh file would be.

    knot_toml(folder, segments=512, sides=128) -> Path of the scene file
"""

from __future__ import annotations

import sys
from pathlib import Path

import numpy as np

from renderer.core.builtin import builtin_scenes

TOOLS = Path(__file__).resolve().parent.parent / "tools"
BUILT_IN_MESH = '"meshes/torus_knot.obj"'


def knot_file(folder, segments: int = 512, sides: int = 128) -> Path:
    """A binary PLY of the torus knot at `segments` x `sides` (2 segments sides triangles)."""
    sys.path.insert(0, str(TOOLS))
    from make_meshes import torus_knot
    positions, _, faces = torus_knot(segments=segments, sides=sides)
    path = Path(folder) / f"torus_knot_{segments}x{sides}.ply"
    header = (f"ply\nformat binary_little_endian 1.0\nelement vertex {len(positions)}\n"
              "property float x\nproperty float y\nproperty float z\n"
              f"element face {len(faces)}\nproperty list uchar int vertex_indices\nend_header\n")
    rows = np.zeros(len(faces), dtype=[("n", "u1"), ("v", "<i4", 3)])
    rows["n"], rows["v"] = 3, faces
    with open(path, "wb") as out:
        out.write(header.encode("ascii"))
        out.write(np.asarray(positions, "<f4").tobytes())
        out.write(rows.tobytes())
    return path


def knot_toml(folder, segments: int = 512, sides: int = 128) -> Path:
    """mesh_shadow.toml with its knot's mesh the PLY of `knot_file`, both in `folder`."""
    mesh = knot_file(folder, segments, sides)
    text = builtin_scenes()["mesh_shadow"].read_text()
    if BUILT_IN_MESH not in text:
        raise RuntimeError(f"mesh_shadow.toml no longer names {BUILT_IN_MESH}")
    path = Path(folder) / "knot.toml"
    path.write_text(text.replace(BUILT_IN_MESH, f'"{mesh.name}"'))
    return path
