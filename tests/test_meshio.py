"""renderer/core/meshio.py: OBJ, PLY and STL files in, checked meshes out, bad files refused."""

from pathlib import Path

import numpy as np
import pytest
import trimesh

from renderer.core.builtin import assets_dir
from renderer.errors import SceneError
from renderer.core.meshio import load_mesh

TRIANGLE_OBJ = "v 0 0 0\nv 1 0 0\nv 0 1 0\nf 1 2 3\n"

PLY_HEADER = """ply
format ascii 1.0
element vertex {nv}
property float x
property float y
property float z
{normals}element face {nf}
property list uchar int vertex_indices
end_header
"""


def write(tmp_path: Path, name: str, text: str) -> Path:
    path = tmp_path / name
    path.write_text(text)
    return path


def ply(vertices, faces, normals=None) -> str:
    header = PLY_HEADER.format(nv=len(vertices), nf=len(faces),
                               normals="property float nx\nproperty float ny\nproperty float nz\n"
                               if normals is not None else "")
    rows = [" ".join(str(c) for c in (*v, *(normals[i] if normals is not None else ())))
            for i, v in enumerate(vertices)]
    rows += ["3 " + " ".join(str(i) for i in f) for f in faces]
    return header + "\n".join(rows) + "\n"


def refused(path, *fragments):
    with pytest.raises(SceneError) as info:
        load_mesh(path)
    line = info.value.line()
    assert line.startswith(f"{path}: "), line
    for fragment in fragments:
        assert fragment in line, line
    return line


def assert_unit(normals):
    np.testing.assert_allclose(np.linalg.norm(normals, axis=1), 1.0, atol=1e-12)


def assert_outward(mesh):
    """Every face's winding normal agrees with the mean of its vertex normals."""
    tri = mesh.positions[mesh.faces]
    face_normals = np.cross(tri[:, 1] - tri[:, 0], tri[:, 2] - tri[:, 0])
    assert (np.einsum("fj,fj->f", face_normals, mesh.normals[mesh.faces].mean(axis=1)) > 0).all()


# --------------------------------------------------------------------------- loading

def test_obj_triangle_without_normals(tmp_path):
    mesh = load_mesh(write(tmp_path, "t.obj", TRIANGLE_OBJ))
    assert mesh.positions.shape == (3, 3) and mesh.positions.dtype == np.float64
    assert mesh.faces.tolist() == [[0, 1, 2]] and mesh.faces.dtype == np.int64
    np.testing.assert_allclose(mesh.normals, [[0, 0, 1]] * 3)
    assert mesh.source == str(tmp_path / "t.obj")


def test_obj_keeps_file_normals_and_renormalises_them(tmp_path):
    text = TRIANGLE_OBJ.replace("f 1 2 3", "vn 0 3 4\nvn 0 0 2\nvn 1 1 1\nf 1//1 2//2 3//3")
    mesh = load_mesh(write(tmp_path, "n.obj", text))
    np.testing.assert_allclose(mesh.normals, [[0, 0.6, 0.8], [0, 0, 1], [3 ** -0.5] * 3])


def test_obj_zero_and_nan_normals_fall_back_to_computed(tmp_path):
    text = TRIANGLE_OBJ.replace("f 1 2 3", "vn 0 0 0\nvn nan 0 1\nvn 0 1 0\nf 1//1 2//2 3//3")
    mesh = load_mesh(write(tmp_path, "z.obj", text))
    np.testing.assert_allclose(mesh.normals, [[0, 0, 1], [0, 0, 1], [0, 1, 0]])


def test_obj_quads_and_negative_indices(tmp_path):
    text = "v 0 0 0\nv 1 0 0\nv 1 1 0\nv 0 1 0\nf -4 -3 -2 -1\n"
    mesh = load_mesh(write(tmp_path, "q.obj", text))
    assert mesh.positions.shape == (4, 3) and mesh.faces.shape == (2, 3)
    assert_outward(mesh)


def test_obj_with_several_objects_is_one_mesh(tmp_path):
    text = "o a\n" + TRIANGLE_OBJ + "o b\nv 0 0 1\nv 1 0 1\nv 0 1 1\nf 4 5 6\n"
    mesh = load_mesh(write(tmp_path, "two.obj", text))
    assert mesh.positions.shape == (6, 3) and mesh.faces.shape == (2, 3)
    assert sorted(mesh.positions[:, 2].tolist()) == [0, 0, 0, 1, 1, 1]


def test_obj_without_normals_gets_smooth_normals(tmp_path):
    # a closed regular tetrahedron: the smooth normal at a corner points away from the centre
    corners = np.array([[1, 1, 1], [1, -1, -1], [-1, 1, -1], [-1, -1, 1]], dtype=float)
    text = "".join(f"v {x} {y} {z}\n" for x, y, z in corners)
    text += "f 1 2 3\nf 1 3 4\nf 1 4 2\nf 2 4 3\n"
    mesh = load_mesh(write(tmp_path, "tet.obj", text))
    np.testing.assert_allclose(mesh.normals, corners / np.sqrt(3), atol=1e-12)


def test_ply_with_normals(tmp_path):
    text = ply([(0, 0, 0), (1, 0, 0), (0, 1, 0), (1, 1, 0)], [(0, 1, 2), (1, 3, 2)],
               normals=[(0, 0, 2), (0, 0, 1), (0, 1, 1), (0, 0, 1)])
    mesh = load_mesh(write(tmp_path, "quad.ply", text))
    assert mesh.positions.shape == (4, 3) and mesh.faces.shape == (2, 3)
    np.testing.assert_allclose(mesh.normals[2], [0, 2 ** -0.5, 2 ** -0.5])
    assert_unit(mesh.normals)


def test_ply_without_normals(tmp_path):
    text = ply([(0, 0, 0), (1, 0, 0), (0, 1, 0)], [(0, 1, 2)])
    mesh = load_mesh(write(tmp_path, "tri.ply", text))
    np.testing.assert_allclose(mesh.normals, [[0, 0, 1]] * 3)


def test_binary_stl_merges_corners_and_computes_normals(tmp_path):
    path = tmp_path / "box.stl"
    trimesh.creation.box(extents=(2, 2, 2)).export(path)
    mesh = load_mesh(path)
    assert mesh.positions.shape == (8, 3) and mesh.faces.shape == (12, 3)
    np.testing.assert_allclose(np.abs(mesh.normals), 3 ** -0.5, atol=1e-12)
    # each corner's normal points away from the centre
    assert (np.einsum("vj,vj->v", mesh.normals, mesh.positions) > 0).all()
    assert_outward(mesh)


def test_builtin_ply_octahedron():
    mesh = load_mesh(assets_dir() / "meshes" / "octahedron.ply")
    assert mesh.positions.shape == (6, 3) and mesh.faces.shape == (8, 3)
    np.testing.assert_allclose(mesh.normals, mesh.positions)       # unit vertices, radial normals
    assert_outward(mesh)


def test_builtin_stl_tetrahedron():
    mesh = load_mesh(assets_dir() / "meshes" / "tetrahedron.stl")
    assert mesh.positions.shape == (4, 3) and mesh.faces.shape == (4, 3)   # 12 corners merged
    np.testing.assert_allclose(mesh.normals, mesh.positions / np.sqrt(3), atol=1e-6)
    assert_outward(mesh)


@pytest.mark.parametrize("name, vertices, faces", [
    ("torus_knot.obj", 180 * 14, 2 * 180 * 14),
    ("bowl.obj", 8 * 32 + 1, 2 * 7 * 32 + 32),
])
def test_builtin_obj_meshes(name, vertices, faces):
    mesh = load_mesh(assets_dir() / "meshes" / name)
    assert mesh.positions.shape == (vertices, 3) and mesh.faces.shape == (faces, 3)
    assert_unit(mesh.normals)
    assert_outward(mesh)


# --------------------------------------------------------------------------- refusals

@pytest.mark.parametrize("bad", ["nan", "inf", "-inf"])
def test_obj_non_finite_vertex_refused(tmp_path, bad):
    path = write(tmp_path, "bad.obj", TRIANGLE_OBJ.replace("v 1 0 0", f"v 1 {bad} 0"))
    refused(path, "vertex 1 is not finite", bad, "NaN or Inf")


def test_ply_nan_vertex_refused(tmp_path):
    path = write(tmp_path, "bad.ply", ply([(0, 0, 0), (1, 0, 0), (0, "nan", 0)], [(0, 1, 2)]))
    refused(path, "vertex 2 is not finite (0, nan, 0)")


@pytest.mark.parametrize("name, text", [
    ("empty.obj", ""),
    ("points.obj", "v 0 0 0\nv 1 0 0\nv 0 1 0\n"),
    ("empty.stl", "solid nothing\nendsolid nothing\n"),
])
def test_empty_mesh_refused(tmp_path, name, text):
    refused(write(tmp_path, name, text), "mesh has no triangles")


def test_empty_ply_refused(tmp_path):
    refused(write(tmp_path, "empty.ply", ply([(0, 0, 0)], [])), "mesh has no triangles")


@pytest.mark.parametrize("face, index", [("f 1 2 7", 7), ("f 0 1 2", 0), ("f 1 2 -4", -4)])
def test_obj_face_index_out_of_range_refused(tmp_path, face, index):
    path = write(tmp_path, "range.obj", TRIANGLE_OBJ.replace("f 1 2 3", face))
    refused(path, f"line 4: face index {index} out of range", "the file has 3 vertices")


def test_ply_face_index_out_of_range_refused(tmp_path):
    path = write(tmp_path, "range.ply", ply([(0, 0, 0), (1, 0, 0), (0, 1, 0)], [(0, 1, 5)]))
    refused(path, "face 0 has vertex index 5 out of range", "3 vertices, indices 0 to 2")


def test_missing_file_refused(tmp_path):
    refused(tmp_path / "nope.obj", "mesh file not found")


def test_unsupported_suffix_refused(tmp_path):
    refused(write(tmp_path, "mesh.xyz", "0 0 0\n"), "unsupported mesh format '.xyz'", ".obj")


def test_unreadable_file_refused(tmp_path):
    refused(write(tmp_path, "junk.ply", "this is not a ply file"), "could not be read as PLY")


def test_error_names_the_scene_file_and_key_when_given(tmp_path):
    path = write(tmp_path, "bad.obj", TRIANGLE_OBJ.replace("v 0 1 0", "v 0 nan 0"))
    with pytest.raises(SceneError) as info:
        load_mesh(path, source="room.toml", key="objects[3].mesh.file")
    assert info.value.line() == (f"room.toml: objects[3].mesh.file: {path}: vertex 2 is not "
                                 f"finite (0, nan, 0); 1 of 3 vertices are NaN or Inf")
