"""A command's whole peak memory, measured, and the large inputs that test the memory limit
(renderer/core/memory.py): tests/test_memory_limits.py and benchmarks/bench_memory.py.

The peak is VmHWM, the kernel's high-water mark of resident memory for the command's own
process, read as the command ends. A child's ru_maxrss (os.wait4, RUSAGE_CHILDREN) would not
do: Linux keeps the high-water mark of the address space a child had before exec, and a child
forked from a large process (pytest, a benchmark that built a scene) starts with its parent's.
"""

from __future__ import annotations

import os
import subprocess
import sys
import tempfile
import time
from dataclasses import dataclass
from pathlib import Path

import numpy as np

# The child: the command line run in the new process, its peak written to a file as it ends.
_CHILD = """
import sys
from renderer.cli import main
try:
    status = main(sys.argv[2:])
finally:
    with open('/proc/self/status') as status_file:
        peak = next(line for line in status_file if line.startswith('VmHWM'))
    with open(sys.argv[1], 'w') as out:
        out.write(str(int(peak.split()[1]) * 1024))
sys.exit(status)
"""


@dataclass(frozen=True)
class Measured:
    status: int
    stderr: str
    peak: int              # bytes
    seconds: float


def measure_command(*args, timeout: float = 600) -> Measured:
    """`renderer ARGS` in a new process: its exit status, stderr, peak resident bytes and
    wall time."""
    with tempfile.TemporaryDirectory() as scratch:
        peak_file = Path(scratch) / "peak"
        start = time.perf_counter()
        result = subprocess.run([sys.executable, "-c", _CHILD, str(peak_file), *map(str, args)],
                                capture_output=True, text=True, timeout=timeout,
                                env=os.environ | {"PYTHONWARNINGS": "ignore"})
        seconds = time.perf_counter() - start
        return Measured(result.returncode, result.stderr, int(peak_file.read_text()), seconds)


def grid_ply(path, side: int) -> int:
    """A binary PLY of a wavy grid of side x side cells, without normals (so that loading
    merges its vertices and makes crease normals, its most expensive path): returns its
    triangle count, 2 side^2 (side 1582: 5,005,448 triangles, 91 MiB)."""
    xs = np.linspace(-1.0, 1.0, side + 1, dtype=np.float32)
    x, y = np.meshgrid(xs, xs)
    z = (0.1 * np.sin(20 * x) * np.cos(20 * y)).astype(np.float32)
    vertices = np.stack([x, y, z], axis=-1).reshape(-1, 3)
    corner = np.arange(side)[:, None] * (side + 1) + np.arange(side)[None, :]
    a, b, c, d = corner, corner + 1, corner + side + 1, corner + side + 2
    faces = np.concatenate([np.stack([a, b, d], -1).reshape(-1, 3),
                            np.stack([a, d, c], -1).reshape(-1, 3)])
    records = np.zeros(len(faces), dtype=[("n", "u1"), ("i", "<i4", 3)])
    records["n"], records["i"] = 3, faces
    header = (f"ply\nformat binary_little_endian 1.0\nelement vertex {len(vertices)}\n"
              "property float x\nproperty float y\nproperty float z\n"
              f"element face {len(faces)}\nproperty list uchar int vertex_indices\nend_header\n")
    with open(path, "wb") as out:
        out.write(header.encode())
        out.write(vertices.astype("<f4").tobytes())
        out.write(records.tobytes())
    return len(faces)


_CAMERA_AND_LIGHT = ('[camera]\neye = [0, -2, 3]\nlook = [0, 0, 0]\n\n[[lights]]\n'
                     'type = "directional"\ndirection = [0, 0.5, -1]\n\n')


def grid_scene(folder: Path, side: int) -> tuple[Path, int]:
    """A scene file in `folder` drawing grid_ply(side) ("grid.toml", "grid.ply"), and the
    triangle count."""
    triangles = grid_ply(folder / "grid.ply", side)
    scene = folder / "grid.toml"
    scene.write_text(_CAMERA_AND_LIGHT + '[[objects]]\nname = "grid"\nmesh = { file = "grid.ply" }\n')
    return scene, triangles


def texture_scene(folder: Path, side: int) -> Path:
    """A scene file in `folder` drawing a plane with a side x side noise PNG (which does not
    compress: its decode is the whole cost) as its texture."""
    from PIL import Image
    noise = np.random.default_rng(1).integers(0, 256, (side, side, 3), dtype=np.uint8)
    Image.fromarray(noise).save(folder / "noise.png", compress_level=1)
    scene = folder / "texture.toml"
    scene.write_text(_CAMERA_AND_LIGHT + '[[objects]]\nname = "floor"\nmesh = { primitive = '
                     '"plane" }\nmaterial = { texture = { image = "noise.png" } }\n')
    return scene
