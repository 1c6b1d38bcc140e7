"""Mesh files in, checked `Mesh` out (OBJ, PLY, STL, and the other mesh formats trimesh reads).

`load_mesh(path)` returns positions (V, 3) float64, unit normals (V, 3) float64 and faces
(F, 3) int64, or raises a one-line `SceneError` naming the file (and, when a scene file named
the mesh, that scene file and its key). What it checks:

- the file exists, has a mesh suffix and trimesh can read it;
- it holds at least one triangle, every vertex is finite (no NaN or Inf), every face index
  lies in range (OBJ files are also scanned line by line, because trimesh silently turns an
  OBJ index of 0 into a wrong triangle);
- normals: those in the file are kept and renormalised; a zero-length or non-finite one is
  replaced by the computed smooth normal at that vertex. A file without normals (STL never
  has them) has its coincident vertices merged and gets angle-weighted vertex normals with a
  crease angle (`crease_vertex_normals`, default DEFAULT_CREASE_ANGLE): smooth across an
  edge where the two faces' normals differ by up to the angle, split into one vertex per side
  where they differ by more, as modelling tools do. `crease_angle=180` is smooth everywhere
  (`smooth_vertex_normals`).
- texture coordinates (`Mesh.uvs`, docs/conventions.md "Texture coordinates"): OBJ `vt`,
  PLY `texture_u texture_v` / `u v` / `s t`, glTF TEXCOORD_0 (trimesh turns glTF's v, which
  points down the image, into ours: v = 1 - v_gltf). Kept only when every part of the file
  has them, and they must be finite. Merging and crease splitting keep them: positions merge
  for the normals' sake, then a vertex splits where its corners' UVs differ (a seam).
"""

from __future__ import annotations

import contextlib
import io
import logging
import os
import warnings
from pathlib import Path

import numpy as np

from renderer.core.trimesh_import import trimesh

from renderer.core import memory
from renderer.core.paths import checked_path
from renderer.core.user_files import (MESH_FILE, FileRefused, confined, open_user_file,
                                      read_capped, read_resource)
from renderer.errors import SceneError, show_number
from renderer.core.scene import Mesh
from renderer.core.uv_rules import weld_corners

# Suffixes we hand to trimesh; the first three are the ones the tests cover.
MESH_SUFFIXES = (".obj", ".ply", ".stl", ".off", ".glb", ".gltf")

# Largest |coordinate| a mesh file may hold: the GPU computes in float32 (largest 3.4e38), and
# a coordinate is multiplied by scales and matrices (renderer/core/scene_file.py MAX_NUMBER).
MAX_COORDINATE = 1e18

# A normal shorter than this (before renormalising) counts as missing.
MIN_NORMAL_LENGTH = 1e-8

# Given to vertices no triangle uses (or only zero-area ones): any unit vector will do.
FALLBACK_NORMAL = (0.0, 0.0, 1.0)

# Degrees: where the normals of two faces sharing an edge (in a file without normals) differ
# by more than this, the edge is hard: each side gets vertices of its own. 180: no creases.
DEFAULT_CREASE_ANGLE = 30.0


class _MeshProblem(Exception):
    """Raised inside this module; `load_mesh` turns it into a SceneError with the right names."""


def load_mesh(path, *, source: str | None = None, key: str | None = None,
              crease_angle: float = DEFAULT_CREASE_ANGLE,
              tally: memory.TriangleTally | None = None) -> Mesh:
    """Read and check a triangle mesh file.

    path:   the mesh file.
    source: the scene file that names the mesh, if any; with `key` (e.g.
            "objects[2].mesh.file") it makes the error line point at the scene entry:
            "scene.toml: objects[2].mesh.file: /abs/knot.obj: 4 faces index ...".
    crease_angle: degrees, 0 < angle <= 180, for a file without normals (see
            `crease_vertex_normals`); a file with normals keeps its own.
    tally:  the scene's triangles so far (renderer/core/memory.py): once the file is parsed,
            its triangles are counted there and refused, before the mesh is built, when
            building them or the command planned would go over the memory limit.
    """
    if not 0.0 < crease_angle <= 180.0:
        raise ValueError(f"crease_angle must be in (0, 180] degrees, got {crease_angle!r}")
    if source is not None:
        path = checked_path(path, file=source, key=key, error=SceneError)
    else:
        path = checked_path(path, key=key, error=SceneError)
    try:
        with _quiet_libraries():
            return _load_checked(path, crease_angle, memory.TriangleTally() if tally is None else tally)
    except _MeshProblem as problem:
        if source is not None:
            raise SceneError(f"{path}: {problem}", file=source, key=key) from None
        raise SceneError(str(problem), file=str(path), key=key) from None


def _load_checked(path: Path, crease_angle: float, tally: memory.TriangleTally) -> Mesh:
    data = _read_file(path)
    suffix = path.suffix.lower()
    if suffix == ".obj":
        _check_obj_face_indices(data)
    if suffix == ".ply":
        _check_ascii_ply_face_indices(data)
    positions, faces, file_normals, uvs = _read_with_trimesh(path, data)
    del data
    too_much = tally.add(len(faces))              # before building: half a minute at 5M
    if too_much:
        raise _MeshProblem(too_much)
    _check_geometry(positions, faces)
    _check_uvs(uvs)
    if file_normals is not None:
        normals = _repair_normals(file_normals, smooth_vertex_normals(positions, faces))
        return Mesh(positions, normals, faces, str(path), uvs=uvs)
    # The normals see the surface as its positions join it (a UV seam is no crease); the
    # UVs then split the vertices they differ at.
    kept, merged = _coincident(positions)
    source, normals, creased = _crease(positions[kept], merged[faces], crease_angle)
    positions = positions[kept][source]
    if uvs is None:
        return Mesh(positions, normals, creased, str(path))
    vertex, creased, uvs = weld_corners(creased, uvs[faces])
    return Mesh(positions[vertex], normals[vertex], creased, str(path), uvs=uvs)


def _read_file(path: Path) -> bytes:
    """The mesh file's bytes, read through renderer/core/user_files.py (a regular file, at
    most its cap), after its suffix and its size against the memory limit are checked."""
    try:
        with open_user_file(path, MESH_FILE) as handle:
            suffix = path.suffix.lower()
            if suffix not in MESH_SUFFIXES:
                raise _MeshProblem(f"unsupported mesh format {suffix or '(no suffix)'!r}; "
                                   f"expected one of {', '.join(MESH_SUFFIXES)}")
            # Checked before parsing: the parsers take up to MESH_PARSE_FACTOR times the size.
            size = os.fstat(handle.fileno()).st_size
            too_much = memory.over_limit(size * memory.MESH_PARSE_FACTOR, loading=True)
            if too_much:
                raise _MeshProblem(f"a mesh file of {memory.show(size)} {too_much}")
            return read_capped(handle, MESH_FILE)
    except FileRefused as refused:
        raise _MeshProblem(refused.reason) from None


class _ConfinedResolver(trimesh.resolvers.FilePathResolver):
    """What trimesh reads beside a mesh file (an OBJ's MTL and its images, a .gltf's buffers
    and images): files in the mesh file's own folder only (user_files.confined), read
    through user_files (regular files, at most GLTF_RESOURCE's cap). trimesh's own resolver
    also tries the name's last part in the folder, and opens FIFOs and devices."""

    def __init__(self, source: str, owner: str):
        super().__init__(source)
        self.owner = owner                       # "glTF", "OBJ": the refusals name it
        self.what = "uri" if owner == "glTF" else "file"

    def get(self, name: str) -> bytes:
        try:
            return read_resource(Path(self.parent), name.strip(), self.what, self.owner)
        except FileRefused as refused:
            raise _MeshProblem(refused.reason) from None

    def namespaced(self, namespace: str) -> "_ConfinedResolver":
        try:
            inner = confined(Path(self.parent), namespace, "folder", self.owner)
        except FileRefused as refused:
            raise _MeshProblem(refused.reason) from None
        return _ConfinedResolver(str(inner / "_"), self.owner)


@contextlib.contextmanager
def _quiet_libraries():
    """Our contract is one error line or nothing, so while we read a user's file nothing a
    library says reaches the terminal: trimesh's logger (materials, sparse fallbacks) is
    raised above CRITICAL, Python warnings (trimesh's and NumPy's RuntimeWarnings on inf or
    1e300 coordinates) are dropped, and NumPy's floating-point errors are ignored. What is
    wrong with the file is found by our own checks, which say it in one line."""
    logger = logging.getLogger("trimesh")
    level = logger.level
    logger.setLevel(logging.CRITICAL + 1)
    try:
        with warnings.catch_warnings(), np.errstate(all="ignore"):
            warnings.simplefilter("ignore")
            yield
    finally:
        logger.setLevel(level)


def _neither(kind: str) -> str:
    return f"could not be read as {kind}: not a valid {kind} file (neither binary {kind} nor text)"


def _neither_binary_nor_text(data: bytes, kind: str) -> bool:
    """Whether an OBJ (text only) or STL file is neither UTF-8 text nor, for STL, the binary
    layout (an 84-byte header and count, then 50 bytes per triangle)."""
    if kind not in ("OBJ", "STL"):
        return False
    try:
        data.decode("utf-8")
        return False
    except UnicodeDecodeError:
        pass
    return kind == "OBJ" or len(data) < 84 or len(data) != 84 + 50 * int.from_bytes(data[80:84], "little")


def _read_with_trimesh(path: Path, data: bytes):
    """(positions (V, 3), faces (F, 3), normals (V, 3) or None, UVs (V, 2) or None) of every
    triangle mesh in the file (its bytes `data`; what it names beside it through
    _ConfinedResolver).

    process=False keeps the file's vertices and normals as written (no merging, no repair).
    """
    kind = path.suffix.lower()[1:].upper()
    if _neither_binary_nor_text(data, kind):
        # Said before trimesh sees the file: with charset_normalizer installed (Ray's extra
        # brings it) trimesh "decodes" any bytes as some code page and reads what it can.
        raise _MeshProblem(_neither(kind))
    try:
        loaded = trimesh.load_scene(io.BytesIO(data), file_type=path.suffix.lower()[1:],
                                    resolver=_ConfinedResolver(str(path), _owner(kind)),
                                    process=False)
    except _MeshProblem:
        raise
    except ImportError:
        # trimesh falls back to guessing a text encoding (charset_normalizer, not installed)
        # when a file is neither its binary layout nor UTF-8 text.
        raise _MeshProblem(_neither(kind)) from None
    except Exception as exc:   # trimesh raises anything from ValueError to IndexError
        reason = str(exc).strip().splitlines()[0] if str(exc).strip() else type(exc).__name__
        raise _MeshProblem(f"could not be read as {kind}: not a valid {kind} file: {reason}") \
            from None

    parts = []
    for node in loaded.graph.nodes_geometry:
        transform, geometry_name = loaded.graph[node]
        geometry = loaded.geometry[geometry_name]
        if isinstance(geometry, trimesh.Trimesh):
            parts.append((np.asarray(transform, dtype=float), geometry))
    if not parts:
        raise _MeshProblem("mesh has no triangles")

    positions, faces, normals, uvs, offset = [], [], [], [], 0
    all_have_normals = all(_has_file_normals(g) for _, g in parts)
    all_have_uvs = all(_file_uvs(g) is not None for _, g in parts)
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
        if all_have_uvs:
            uvs.append(_file_uvs(geometry))
        offset += len(v)
    return (np.concatenate(positions), np.concatenate(faces),
            np.concatenate(normals) if all_have_normals else None,
            np.concatenate(uvs) if all_have_uvs else None)


def _owner(kind: str) -> str:
    """How the refusals name the mesh file whose resources they are ("glTF" for GLB too)."""
    return "glTF" if kind in ("GLTF", "GLB") else kind


def _file_uvs(geometry: trimesh.Trimesh) -> np.ndarray | None:
    """The part's UVs (V, 2) float64 as trimesh read them (v up, glTF's already turned), or
    None. trimesh keeps glTF's TEXCOORD_0 only on primitives that name a material."""
    uv = getattr(geometry.visual, "uv", None)
    if uv is None or np.shape(uv)[0] != len(geometry.vertices) or np.ndim(uv) != 2:
        return None
    return np.asarray(uv, dtype=np.float64)[:, :2]


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
        i, shown = _first(bad, positions)
        raise _MeshProblem(f"vertex {i} is not finite ({shown}); "
                           f"{int(bad.sum())} of {len(positions)} vertices are NaN or Inf")
    large = (np.abs(positions) > MAX_COORDINATE).any(axis=1)
    if large.any():
        i, shown = _first(large, positions)
        raise _MeshProblem(f"vertex {i} ({shown}) is too large for the GPU's float32 "
                           f"arithmetic; coordinates must satisfy |x| <= {MAX_COORDINATE:g} "
                           f"({int(large.sum())} of {len(positions)} vertices do not)")
    out = (faces < 0) | (faces >= len(positions))
    if out.any():
        f = int(np.argmax(out.any(axis=1)))
        raise _MeshProblem(f"face {f} has vertex index {int(faces[f][out[f]][0])} out of range "
                           f"(the mesh has {len(positions)} vertices, indices 0 to "
                           f"{len(positions) - 1})")


def _check_uvs(uvs: np.ndarray | None) -> None:
    if uvs is None:
        return
    bad = ~np.isfinite(uvs).all(axis=1) | (np.abs(uvs) > MAX_COORDINATE).any(axis=1)
    if bad.any():
        i, shown = _first(bad, uvs)
        raise _MeshProblem(f"vertex {i} has texture coordinates ({shown}) that are not finite "
                           f"numbers within |x| <= {MAX_COORDINATE:g} ({int(bad.sum())} of "
                           f"{len(uvs)} vertices)")


def _first(bad: np.ndarray, rows: np.ndarray) -> tuple[int, str]:
    """The first bad row's index and its numbers as a message shows them."""
    i = int(np.argmax(bad))
    return i, ", ".join(show_number(x) for x in rows[i])


def _check_obj_face_indices(data: bytes) -> None:
    """Check every `f` line's vertex indices lie in 1..V or -V..-1 (OBJ counts from 1)."""
    lines = data.decode("utf-8", errors="replace").splitlines()
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


def _check_ascii_ply_face_indices(data: bytes) -> None:
    """Check an ASCII PLY's face indices as written, in Python integers: trimesh narrows them
    to the header's type first (an index of 2**31 + 10 would come out as -2147483648).
    Binary PLY cannot hold a value its type does not; trimesh reads those as they are."""
    end = data.find(b"end_header")
    if end < 0:
        return                                       # trimesh says what is wrong
    header = data[:end].decode("ascii", errors="replace").splitlines()
    if not any(line.split()[:2] == ["format", "ascii"] for line in header):
        return
    elements = []                                    # [name, count, [(name, is_list)]]
    for line in header:
        fields = line.split()
        if fields[:1] == ["element"] and len(fields) == 3 and fields[2].isdigit():
            elements.append([fields[1], int(fields[2]), []])
        elif fields[:1] == ["property"] and elements and len(fields) >= 3:
            elements[-1][2].append((fields[-1], fields[1] == "list"))
    vertex_count = next((count for name, count, _ in elements if name == "vertex"), 0)
    body = data[end:].split(b"\n", 1)[1] if b"\n" in data[end:] else b""
    lines = iter(body.decode("ascii", errors="replace").splitlines())
    face = 0
    for name, count, properties in elements:
        for _ in range(count):
            tokens = next(lines, "").split()
            position = 0
            for prop, is_list in properties:
                if position >= len(tokens):
                    return                           # short line: trimesh says what is wrong
                try:
                    length = int(tokens[position]) if is_list else 1
                    values = [int(t) for t in tokens[position + is_list:
                                                     position + is_list + length]]
                except ValueError:
                    values, length = [], (int(is_list) and 0)
                    if name == "face" and prop in ("vertex_indices", "vertex_index"):
                        return                       # not integers: trimesh says what is wrong
                if name == "face" and prop in ("vertex_indices", "vertex_index"):
                    for index in values:
                        if not 0 <= index < vertex_count:
                            raise _MeshProblem(
                                f"face {face} has vertex index {index} out of range (the mesh "
                                f"has {vertex_count} vertices, indices 0 to {vertex_count - 1})")
                position += (1 + length) if is_list else 1
            if name == "face":
                face += 1


def merge_coincident_vertices(positions: np.ndarray, faces: np.ndarray):
    """Join vertices with exactly equal positions (STL stores three per triangle), keeping
    the order of first appearance. Returns (positions, faces)."""
    kept, merged = _coincident(positions)
    return positions[kept], merged[faces]


def _coincident(positions: np.ndarray):
    """(kept, merged): the first vertex of each distinct position, in order of first
    appearance, and each vertex's index among them."""
    _, first, inverse = np.unique(positions, axis=0, return_index=True, return_inverse=True)
    order = np.argsort(first)                 # unique rows in order of first appearance
    rank = np.empty_like(order)
    rank[order] = np.arange(len(order))
    return first[order], rank[np.asarray(inverse).reshape(-1)]


def _cross(a: np.ndarray, b: np.ndarray) -> np.ndarray:
    """np.cross of (n, 3) rows, the same products and differences (bit for bit) in a third of
    its time."""
    out = np.empty_like(a)
    for i, j, k in ((0, 1, 2), (1, 2, 0), (2, 0, 1)):
        np.subtract(a[:, j] * b[:, k], a[:, k] * b[:, j], out=out[:, i])
    return out


def _face_normals_and_angles(positions: np.ndarray, faces: np.ndarray):
    """Unit face normals (F, 3), zero for a face whose cross product is exactly zero, and the
    corner angles (F, 3) in radians (trimesh: all three 0 for a degenerate face)."""
    triangles = positions[faces]                                   # (F, 3, 3)
    cross = _cross(triangles[:, 1] - triangles[:, 0], triangles[:, 2] - triangles[:, 0])
    length = np.linalg.norm(cross, axis=1, keepdims=True)
    face_normals = np.divide(cross, length, out=np.zeros_like(cross), where=length > 0)
    return face_normals, trimesh.triangles.angles(triangles)


def smooth_vertex_normals(positions: np.ndarray, faces: np.ndarray) -> np.ndarray:
    """Unit vertex normals: each face's normal weighted by its corner angle at the vertex
    (Thürrner and Wüthrich, as trimesh does). Vertices no face with area uses get
    FALLBACK_NORMAL."""
    face_normals, corner_angles = _face_normals_and_angles(positions, faces)
    summed = np.zeros_like(positions)
    for corner in range(3):
        np.add.at(summed, faces[:, corner], face_normals * corner_angles[:, corner:corner + 1])
    return _unit_or_fallback(summed, np.broadcast_to(FALLBACK_NORMAL, positions.shape))


def crease_vertex_normals(positions: np.ndarray, faces: np.ndarray,
                          crease_angle: float = DEFAULT_CREASE_ANGLE):
    """Angle-weighted vertex normals with a crease angle (degrees), as modelling tools make
    them (Blender's auto smooth, Houdini's cusp angle); returns (positions, normals, faces),
    each vertex split into one per fan of faces around it.

    The rule: an edge is *hard* where the unit normals of two faces sharing it differ by more
    than `crease_angle` (n_f . n_g < cos(crease_angle)), and *soft* otherwise. Around each
    vertex, faces joined through soft edges form a fan (faces that only touch at the vertex
    are separate fans). Every corner of a fan gets the fan's normal: the sum of its faces'
    unit normals, each weighted by its corner angle at the vertex (as
    `smooth_vertex_normals`), normalised. A face without area (zero cross product) joins no
    fan: its corners take the smooth normal of all the faces at the vertex. So a pyramid's
    sides are flat, and a surface that turns by less than the angle from face to face keeps
    one normal per position.

    Exact and deterministic: a fan's sum adds its faces in the order smooth_vertex_normals
    adds them, so where all of a vertex's faces are one fan its normal is the smooth one bit
    for bit; corners of a vertex whose sums are equal share one vertex. Vertex i of the
    output is vertex i of the input where nothing splits; a split vertex's copies follow it,
    in the order their corners first appear in `faces`; vertices no face uses are kept
    (FALLBACK_NORMAL). `crease_angle >= 180` is smooth_vertex_normals, nothing split.
    """
    positions = np.asarray(positions, dtype=np.float64)
    source, normals, faces = _crease(positions, faces, crease_angle)
    return positions[source], normals, faces


def _crease(positions: np.ndarray, faces: np.ndarray, crease_angle: float):
    """crease_vertex_normals as (the input vertex of each output vertex, normals, faces)."""
    faces = np.asarray(faces, dtype=np.int64)
    if crease_angle >= 180.0:
        return np.arange(len(positions)), smooth_vertex_normals(positions, faces), faces
    cos_crease = np.cos(np.radians(crease_angle))
    face_count, vertex_count = len(faces), len(positions)
    corner_count = 3 * face_count
    face_normals, corner_angles = _face_normals_and_angles(positions, faces)
    has_area = face_normals.any(axis=1)

    # Corners in smooth_vertex_normals' order: corner c = k * F + f is corner k of face f.
    corner = np.arange(corner_count)
    corner_vertex = faces.T.reshape(-1)
    corner_face = corner % face_count
    weighted = face_normals[corner_face] * corner_angles.T.reshape(-1, 1)

    # Soft edges: two faces with area on one undirected edge, within the angle. Each joins
    # the two faces' corners at either end of the edge. Edge k of a face runs from its
    # corner k to its corner k + 1.
    next_corner = (corner + face_count) % corner_count
    a, b = corner_vertex, corner_vertex[next_corner]
    keep = (a != b) & has_area[corner_face]
    low_corner = np.where(a < b, corner, next_corner)[keep]       # the corner at the lower index
    high_corner = np.where(a < b, next_corner, corner)[keep]
    edges = np.column_stack([np.minimum(a, b)[keep], np.maximum(a, b)[keep]])
    order = np.lexsort((low_corner, edges[:, 1], edges[:, 0]))
    first, second = (order[i] for i in _pairs_of_equal_rows(edges[order]))
    soft = np.einsum("ij,ij->i", face_normals[corner_face[low_corner[first]]],
                     face_normals[corner_face[low_corner[second]]]) >= cos_crease
    first, second = first[soft], second[soft]
    fan = _components(corner_count, np.concatenate([low_corner[first], high_corner[first]]),
                      np.concatenate([low_corner[second], high_corner[second]]))

    summed = np.empty((corner_count, 3))
    for axis in range(3):     # bincount adds in input order: a fan's corners in corner order
        fan_sum = np.bincount(fan, weights=weighted[:, axis], minlength=corner_count)
        vertex_sum = np.bincount(corner_vertex, weights=weighted[:, axis], minlength=vertex_count)
        summed[:, axis] = np.where(has_area[corner_face], fan_sum[fan], vertex_sum[corner_vertex])
    summed += 0.0                                                   # -0.0 -> 0.0

    # One output vertex per (vertex, distinct sum), then each vertex no face uses.
    group, group_count = _groups_of_equal_sums(corner_vertex, summed, vertex_count)
    appearance = corner_face * 3 + corner // face_count            # f * 3 + k: file order
    group_first = np.full(group_count, corner_count, dtype=np.int64)
    np.minimum.at(group_first, group, appearance)
    group_vertex = np.zeros(group_count, dtype=np.int64)
    group_vertex[group] = corner_vertex
    group_sum = np.zeros((group_count, 3))
    group_sum[group] = summed
    unused = np.flatnonzero(np.bincount(corner_vertex, minlength=vertex_count) == 0)
    out_vertex = np.concatenate([group_vertex, unused])
    out_first = np.concatenate([group_first, np.full(len(unused), -1, dtype=np.int64)])
    out_sum = np.concatenate([group_sum, np.zeros((len(unused), 3))])
    out_order = np.lexsort((out_first, out_vertex))
    new_index = np.empty(len(out_order), dtype=np.int64)
    new_index[out_order] = np.arange(len(out_order))
    new_faces = new_index[group].reshape(3, face_count).T.copy()
    fallback = np.broadcast_to(FALLBACK_NORMAL, (len(out_order), 3))
    normals = _unit_or_fallback(out_sum[out_order], fallback)
    return out_vertex[out_order], normals, new_faces


def _groups_of_equal_sums(corner_vertex: np.ndarray, summed: np.ndarray, vertex_count: int):
    """(group of each corner, group count): corners share a group where they share a vertex
    and their sums are equal. Most vertices are one fan, every corner's sum the same: those
    are a group each, found by comparing each corner with one corner of its vertex; only the
    corners of split vertices are sorted (a sort of every corner was a fifth of a creased
    mesh's load)."""
    corner_count = len(corner_vertex)
    one = np.empty(vertex_count, dtype=np.int64)
    one[corner_vertex] = np.arange(corner_count)           # a corner of each vertex
    same = (summed == summed[one[corner_vertex]]).all(axis=1)
    split = np.zeros(vertex_count, dtype=bool)
    split[corner_vertex[~same]] = True
    group = np.empty(corner_count, dtype=np.int64)
    plain = ~split[corner_vertex]
    used = np.zeros(vertex_count, dtype=bool)
    used[corner_vertex[plain]] = True
    number = np.cumsum(used) - 1                           # a group per unsplit vertex
    group[plain] = number[corner_vertex[plain]]
    count = int(used.sum())
    rest = np.flatnonzero(~plain)
    if len(rest):
        order = rest[np.lexsort((summed[rest, 2], summed[rest, 1], summed[rest, 0], corner_vertex[rest]))]
        key = np.column_stack([corner_vertex[order], summed[order]])
        starts = np.concatenate([[True], (key[1:] != key[:-1]).any(axis=1)])
        group[order] = count + np.cumsum(starts) - 1
        count += int(starts.sum())
    return group, count


def _pairs_of_equal_rows(rows: np.ndarray):
    """(i, j), i < j, for every two equal rows of `rows` (sorted, so that equal rows are
    adjacent): the faces that share an edge, two on a closed surface, more where the mesh
    is not a manifold."""
    count = len(rows)
    if count == 0:
        return np.zeros(0, dtype=np.int64), np.zeros(0, dtype=np.int64)
    starts = np.flatnonzero(np.concatenate([[True], (rows[1:] != rows[:-1]).any(axis=1)]))
    lengths = np.diff(np.append(starts, count))
    later = np.repeat(starts + lengths, lengths) - np.arange(count) - 1   # rows after it in its run
    first = np.repeat(np.arange(count), later)
    step = np.arange(int(later.sum())) - np.repeat(np.cumsum(later) - later, later)
    return first, first + 1 + step


def _components(count: int, u: np.ndarray, v: np.ndarray) -> np.ndarray:
    """Connected components of the graph on nodes 0..count-1 with edges (u[i], v[i]): each
    node's label is the least node of its component. The least labels spread along the
    edges, and by pointer jumping, until nothing changes."""
    label = np.arange(count)
    while True:
        lowest = np.minimum(label[u], label[v])
        new = label.copy()
        np.minimum.at(new, u, lowest)
        np.minimum.at(new, v, lowest)
        while True:
            jumped = new[new]
            if np.array_equal(jumped, new):
                break
            new = jumped
        if np.array_equal(new, label):
            return label
        label = new


def _repair_normals(file_normals: np.ndarray, computed: np.ndarray) -> np.ndarray:
    """Renormalise the file's normals; zero-length or non-finite ones take the computed normal."""
    finite = np.isfinite(file_normals).all(axis=1, keepdims=True)
    return _unit_or_fallback(np.where(finite, file_normals, 0.0), computed)


def _unit_or_fallback(vectors: np.ndarray, fallback: np.ndarray) -> np.ndarray:
    length = np.linalg.norm(vectors, axis=1, keepdims=True)
    ok = length > MIN_NORMAL_LENGTH
    unit = np.divide(vectors, length, out=np.zeros_like(vectors), where=ok)
    return np.where(ok, unit, fallback).astype(np.float64)


