"""Mesh files in, checked `Mesh` out (OBJ, PLY, STL, and the other mesh formats trimesh reads).

`load_mesh(path)` returns positions (V, 3) float64, unit normals (V, 3) float64 and faces
(F, 3) int64, or raises a one-line `SceneError` naming the file (and, when a scene file named
the mesh, that scene file and its key). What it checks:

- the file exists, has a mesh suffix and trimesh can read it;
- it holds at least one triangle, every vertex is finite (no NaN or Inf), every face index
  lies in range (OBJ files are also scanned line by line, because trimesh silently turns an
  OBJ index of 0 into a wrong triangle);
- normals: those in the file are kept and renormalised; a zero-length or non-finite one is
  replaced by the computed normal at that vertex. A file without normals (STL never has
  them) has its coincident vertices merged and gets smooth, angle-weighted vertex normals.
"""

from __future__ import annotations

import contextlib
import logging
from pathlib import Path

import numpy as np
import trimesh

from renderer.errors import SceneError, show_number
from renderer.core.scene import Mesh

# Suffixes we hand to trimesh; the first three are the ones the tests cover.
MESH_SUFFIXES = (".obj", ".ply", ".stl", ".off", ".glb", ".gltf")

# A normal shorter than this (before renormalising) counts as missing.
MIN_NORMAL_LENGTH = 1e-8

# Given to vertices no triangle uses (or only zero-area ones): any unit vector will do.
FALLBACK_NORMAL = (0.0, 0.0, 1.0)


class _MeshProblem(Exception):
    """Raised inside this module; `load_mesh` turns it into a SceneError with the right names."""


def load_mesh(path, *, source: str | None = None, key: str | None = None) -> Mesh:
    """Read and check a triangle mesh file.

    path:   the mesh file.
    source: the scene file that names the mesh, if any; with `key` (e.g.
            "objects[2].mesh.file") it makes the error line point at the scene entry:
            "scene.toml: objects[2].mesh.file: /abs/knot.obj: 4 faces index ...".
    """
    path = Path(path)
    try:
        return _load_checked(path)
    except _MeshProblem as problem:
        if source is not None:
            raise SceneError(f"{path}: {problem}", file=source, key=key) from None
        raise SceneError(str(problem), file=str(path), key=key) from None


def _load_checked(path: Path) -> Mesh:
    if not path.exists():
        raise _MeshProblem("mesh file not found")
    if not path.is_file():
        raise _MeshProblem("is not a file")
    suffix = path.suffix.lower()
    if suffix not in MESH_SUFFIXES:
        raise _MeshProblem(f"unsupported mesh format {suffix or '(no suffix)'!r}; "
                           f"expected one of {', '.join(MESH_SUFFIXES)}")
    if suffix == ".obj":
        _check_obj_face_indices(path)
    positions, faces, file_normals = _read_with_trimesh(path)
    _check_geometry(positions, faces)
    if file_normals is None:
        positions, faces = merge_coincident_vertices(positions, faces)
        normals = smooth_vertex_normals(positions, faces)
    else:
        normals = _repair_normals(file_normals, smooth_vertex_normals(positions, faces))
    return Mesh(positions, normals, faces, str(path))


@contextlib.contextmanager
def _quiet_trimesh():
    """trimesh logs warnings (materials, sparse fallbacks) to stderr; our contract is one
    error line or nothing, so its logger is raised to ERROR while we read a file."""
    logger = logging.getLogger("trimesh")
    level = logger.level
    logger.setLevel(logging.ERROR)
    try:
        yield
    finally:
        logger.setLevel(level)


def _read_with_trimesh(path: Path):
    """(positions (V, 3), faces (F, 3), normals (V, 3) or None) of every triangle mesh in the file.

    process=False keeps the file's vertices and normals as written (no merging, no repair).
    """
    try:
        with _quiet_trimesh():
            loaded = trimesh.load_scene(str(path), process=False)
    except Exception as exc:   # trimesh raises anything from ValueError to IndexError
        reason = str(exc).strip().splitlines()[0] if str(exc).strip() else type(exc).__name__
        raise _MeshProblem(f"could not be read as {path.suffix.lower()[1:].upper()}: {reason}")

    parts = []
    for node in loaded.graph.nodes_geometry:
        transform, geometry_name = loaded.graph[node]
        geometry = loaded.geometry[geometry_name]
        if isinstance(geometry, trimesh.Trimesh):
            parts.append((np.asarray(transform, dtype=float), geometry))
    if not parts:
        raise _MeshProblem("mesh has no triangles")

    positions, faces, normals, offset = [], [], [], 0
    all_have_normals = all(_has_file_normals(g) for _, g in parts)
    for transform, geometry in parts:
        v = np.asarray(geometry.vertices, dtype=np.float64).reshape(-1, 3)
        f = np.asarray(geometry.faces, dtype=np.int64).reshape(-1, 3)
        if not np.allclose(transform, np.eye(4)):
            v = v @ transform[:3, :3].T + transform[:3, 3]
        positions.append(v)
        faces.append(f + offset)
        if all_have_normals:
            n = np.asarray(geometry.vertex_normals, dtype=np.float64).reshape(-1, 3)
            if not np.allclose(transform, np.eye(4)):
                n = n @ np.linalg.inv(transform[:3, :3])   # (M^-T n) for row vectors
            normals.append(n)
        offset += len(v)
    return (np.concatenate(positions), np.concatenate(faces),
            np.concatenate(normals) if all_have_normals else None)


def _has_file_normals(geometry: trimesh.Trimesh) -> bool:
    """Whether the loader stored normals read from the file.

    trimesh has no public flag for this: normals read from a file sit in the mesh's cache
    (which process=False leaves alone) until something edits the mesh; otherwise
    `vertex_normals` would be computed on first use.
    """
    return "vertex_normals" in geometry._cache


def _check_geometry(positions: np.ndarray, faces: np.ndarray) -> None:
    if len(faces) == 0:
        raise _MeshProblem("mesh has no triangles")
    bad = ~np.isfinite(positions).all(axis=1)
    if bad.any():
        i = int(np.argmax(bad))
        shown = ", ".join(show_number(x) for x in positions[i])
        raise _MeshProblem(f"vertex {i} is not finite ({shown}); "
                           f"{int(bad.sum())} of {len(positions)} vertices are NaN or Inf")
    out = (faces < 0) | (faces >= len(positions))
    if out.any():
        f = int(np.argmax(out.any(axis=1)))
        raise _MeshProblem(f"face {f} has vertex index {int(faces[f][out[f]][0])} out of range "
                           f"(the mesh has {len(positions)} vertices, indices 0 to "
                           f"{len(positions) - 1})")


def _check_obj_face_indices(path: Path) -> None:
    """Check every `f` line's vertex indices lie in 1..V or -V..-1 (OBJ counts from 1)."""
    try:
        lines = path.read_text(encoding="utf-8", errors="replace").splitlines()
    except OSError as exc:
        raise _MeshProblem(f"could not be read: {exc.strerror or exc}")
    statements = [line.split() for line in lines]
    vertex_count = sum(1 for fields in statements if fields and fields[0] == "v")
    for number, fields in enumerate(statements, start=1):
        if not fields or fields[0] != "f":
            continue
        for field in fields[1:]:
            text = field.split("/")[0]
            try:
                index = int(text)
            except ValueError:
                raise _MeshProblem(f"line {number}: face vertex {field!r} is not an integer index")
            if not (1 <= index <= vertex_count or -vertex_count <= index <= -1):
                raise _MeshProblem(
                    f"line {number}: face index {index} out of range (the file has "
                    f"{vertex_count} vertices; OBJ indices run from 1 to {vertex_count}, "
                    f"or -1 to -{vertex_count} counting back)")


def merge_coincident_vertices(positions: np.ndarray, faces: np.ndarray):
    """Join vertices with exactly equal positions (STL stores three per triangle), keeping
    the order of first appearance. Returns (positions, faces)."""
    unique, first, inverse = np.unique(positions, axis=0, return_index=True, return_inverse=True)
    order = np.argsort(first)                 # unique rows in order of first appearance
    rank = np.empty_like(order)
    rank[order] = np.arange(len(order))
    return unique[order], rank[np.asarray(inverse).reshape(-1)][faces]


def smooth_vertex_normals(positions: np.ndarray, faces: np.ndarray) -> np.ndarray:
    """Unit vertex normals: each face's normal weighted by its corner angle at the vertex
    (Thürrner and Wüthrich, as trimesh does). Vertices no face with area uses get
    FALLBACK_NORMAL."""
    triangles = positions[faces]                                   # (F, 3, 3)
    cross = np.cross(triangles[:, 1] - triangles[:, 0], triangles[:, 2] - triangles[:, 0])
    length = np.linalg.norm(cross, axis=1, keepdims=True)
    face_normals = np.divide(cross, length, out=np.zeros_like(cross), where=length > 0)
    corner_angles = trimesh.triangles.angles(triangles)   # (F, 3) radians, 0 if degenerate
    summed = np.zeros_like(positions)
    for corner in range(3):
        np.add.at(summed, faces[:, corner], face_normals * corner_angles[:, corner:corner + 1])
    return _unit_or_fallback(summed, np.broadcast_to(FALLBACK_NORMAL, positions.shape))


def _repair_normals(file_normals: np.ndarray, computed: np.ndarray) -> np.ndarray:
    """Renormalise the file's normals; zero-length or non-finite ones take the computed normal."""
    finite = np.isfinite(file_normals).all(axis=1, keepdims=True)
    return _unit_or_fallback(np.where(finite, file_normals, 0.0), computed)


def _unit_or_fallback(vectors: np.ndarray, fallback: np.ndarray) -> np.ndarray:
    length = np.linalg.norm(vectors, axis=1, keepdims=True)
    ok = length > MIN_NORMAL_LENGTH
    unit = np.divide(vectors, length, out=np.zeros_like(vectors), where=ok)
    return np.where(ok, unit, fallback).astype(np.float64)


