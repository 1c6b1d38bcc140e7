"""renderer/core/meshio.py: OBJ, PLY and STL files in, checked meshes out, bad files refused;
vertex normals of a file without them by the crease-angle rule."""

from pathlib import Path

import numpy as np
import pytest
import trimesh

from renderer.core.builtin import assets_dir
from renderer.errors import SceneError
from renderer.core.meshio import (DEFAULT_CREASE_ANGLE, crease_vertex_normals, load_mesh,
                                  merge_coincident_vertices, smooth_vertex_normals)

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


def test_obj_without_normals_gets_smooth_normals_at_crease_angle_180(tmp_path):
    # a closed regular tetrahedron: the smooth normal at a corner points away from the centre
    corners = np.array([[1, 1, 1], [1, -1, -1], [-1, 1, -1], [-1, -1, 1]], dtype=float)
    text = "".join(f"v {x} {y} {z}\n" for x, y, z in corners)
    text += "f 1 2 3\nf 1 3 4\nf 1 4 2\nf 2 4 3\n"
    mesh = load_mesh(write(tmp_path, "tet.obj", text), crease_angle=180)
    np.testing.assert_allclose(mesh.normals, corners / np.sqrt(3), atol=1e-12)
    # its face normals differ by 109.5 degrees: at the default crease angle each face is flat
    mesh = load_mesh(tmp_path / "tet.obj")
    assert mesh.positions.shape == (12, 3) and mesh.faces.shape == (4, 3)
    opposite = np.array([3, 1, 2, 0])            # face i does not touch corner opposite[i]
    np.testing.assert_allclose(mesh.normals[mesh.faces],
                               np.repeat(-corners[opposite, None] / np.sqrt(3), 3, axis=1), atol=1e-12)


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
    mesh = load_mesh(path, crease_angle=180)
    assert mesh.positions.shape == (8, 3) and mesh.faces.shape == (12, 3)
    np.testing.assert_allclose(np.abs(mesh.normals), 3 ** -0.5, atol=1e-12)
    # each corner's normal points away from the centre
    assert (np.einsum("vj,vj->v", mesh.normals, mesh.positions) > 0).all()
    assert_outward(mesh)
    # at the default crease angle the box has hard edges: four vertices per side, each
    # with the side's axis as its normal
    mesh = load_mesh(path)
    assert mesh.positions.shape == (24, 3) and mesh.faces.shape == (12, 3)
    axis = np.argmax(np.abs(mesh.normals), axis=1)
    np.testing.assert_array_equal(mesh.normals, np.eye(3)[axis] * np.sign(mesh.positions[np.arange(24), axis])[:, None])


def test_builtin_ply_octahedron():
    mesh = load_mesh(assets_dir() / "meshes" / "octahedron.ply")
    assert mesh.positions.shape == (6, 3) and mesh.faces.shape == (8, 3)
    np.testing.assert_allclose(mesh.normals, mesh.positions)       # unit vertices, radial normals
    assert_outward(mesh)


def test_builtin_stl_tetrahedron():
    path = assets_dir() / "meshes" / "tetrahedron.stl"
    mesh = load_mesh(path, crease_angle=180)
    assert mesh.positions.shape == (4, 3) and mesh.faces.shape == (4, 3)   # 12 corners merged
    np.testing.assert_allclose(mesh.normals, mesh.positions / np.sqrt(3), atol=1e-6)
    assert_outward(mesh)
    # the default: merged, then split again at its edges (normals 109.5 degrees apart),
    # one normal per face
    mesh = load_mesh(path)
    assert mesh.positions.shape == (12, 3) and mesh.faces.shape == (4, 3)
    corner_sum = mesh.positions[mesh.faces].sum(axis=1)     # = -(the corner a face lacks)
    expected = corner_sum / np.linalg.norm(corner_sum, axis=1, keepdims=True)
    np.testing.assert_allclose(mesh.normals[mesh.faces], np.repeat(expected[:, None], 3, axis=1),
                               atol=1e-6)
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


# --------------------------------------------------------------------------- the crease angle

# A square pyramid: base corners (+-1, 0, +-1), apex (0, 1, 0), the base one quad (two
# triangles). Sides meet at 60 degrees, sides and base at 135: every edge is a crease at 30.
PYRAMID_OBJ = ("v 1 0 1\nv 1 0 -1\nv -1 0 -1\nv -1 0 1\nv 0 1 0\n"
               "f 1 2 5\nf 2 3 5\nf 3 4 5\nf 4 1 5\nf 1 4 3 2\n")
PYRAMID_FACE_NORMALS = np.array([[1, 1, 0], [0, 1, -1], [-1, 1, 0], [0, 1, 1]]) / np.sqrt(2)


def obj_text(positions, faces) -> str:
    """An OBJ file without normals (repr keeps every float64 exactly)."""
    return ("".join(f"v {float(x)!r} {float(y)!r} {float(z)!r}\n" for x, y, z in positions)
            + "".join(f"f {a + 1} {b + 1} {c + 1}\n" for a, b, c in faces))


def old_smooth_normals(path):
    """What a file without normals got before the crease angle: merged, smooth normals."""
    loaded = trimesh.load(path, process=False, force="mesh")
    positions, faces = merge_coincident_vertices(np.asarray(loaded.vertices, dtype=np.float64),
                                                 np.asarray(loaded.faces, dtype=np.int64))
    return positions, smooth_vertex_normals(positions, faces), faces


def test_default_crease_angle_is_30_degrees():
    assert DEFAULT_CREASE_ANGLE == 30.0


def test_pyramid_without_normals_has_flat_sides(tmp_path):
    """Each corner's normal is its own face's normal, so the pyramid does not look like a
    cone; the apex is four vertices, each base corner three (two sides and the base)."""
    mesh = load_mesh(write(tmp_path, "pyramid.obj", PYRAMID_OBJ))
    assert mesh.faces.shape == (6, 3) and mesh.positions.shape == (16, 3)
    expected = np.concatenate([PYRAMID_FACE_NORMALS, [[0, -1, 0]] * 2])
    np.testing.assert_allclose(mesh.normals[mesh.faces], np.repeat(expected[:, None], 3, axis=1),
                               atol=1e-15)
    positions, counts = np.unique(mesh.positions, axis=0, return_counts=True)
    assert dict(zip(map(tuple, positions), counts)) == {
        (0, 1, 0): 4, (1, 0, 1): 3, (1, 0, -1): 3, (-1, 0, -1): 3, (-1, 0, 1): 3}
    assert_outward(mesh)


def test_pyramid_at_a_crease_angle_above_its_side_angle(tmp_path):
    """At 70 degrees the edges between sides (60) are soft and those to the base (135) hard.
    Around the apex the sides form one closed fan, although opposite sides are 90 degrees
    apart: one vertex, its normal straight up. A base corner gets the sum of its two sides
    (equal corner angles there), and the base its own copy."""
    mesh = load_mesh(write(tmp_path, "pyramid.obj", PYRAMID_OBJ), crease_angle=70)
    assert mesh.positions.shape == (5 + 4, 3)
    np.testing.assert_allclose(mesh.normals[mesh.faces[:4, 2]], [[0, 1, 0]] * 4, atol=1e-15)
    corner = mesh.faces[0, 0]                     # (1, 0, 1): the sides facing +x and +z
    np.testing.assert_allclose(mesh.normals[corner], np.array([1, 2, 1]) / np.sqrt(6), atol=1e-15)
    np.testing.assert_allclose(mesh.normals[mesh.faces[4:]], [[[0, -1, 0]] * 3] * 2, atol=1e-15)


def test_tessellated_sphere_without_normals_stays_smooth(tmp_path):
    """An icosphere (its faces at a vertex within 16 degrees of each other): one vertex per
    position, the file's faces, and exactly the smooth normals, close to radial."""
    ico = trimesh.creation.icosphere(subdivisions=3)
    path = write(tmp_path, "ico.obj", obj_text(ico.vertices, ico.faces))
    mesh = load_mesh(path)
    assert mesh.positions.shape == (642, 3)
    np.testing.assert_array_equal(mesh.positions, ico.vertices)
    np.testing.assert_array_equal(mesh.faces, ico.faces)
    np.testing.assert_array_equal(mesh.normals, smooth_vertex_normals(mesh.positions, mesh.faces))
    radial = mesh.positions / np.linalg.norm(mesh.positions, axis=1, keepdims=True)
    assert np.einsum("ij,ij->i", mesh.normals, radial).min() > np.cos(np.radians(1.0))


def test_crease_angle_180_is_the_smooth_normals_exactly(tmp_path):
    ico = trimesh.creation.icosphere(subdivisions=2)
    files = [write(tmp_path, "pyramid.obj", PYRAMID_OBJ),
             write(tmp_path, "ico.obj", obj_text(ico.vertices, ico.faces)),
             assets_dir() / "meshes" / "tetrahedron.stl"]
    for path in files:
        mesh = load_mesh(path, crease_angle=180)
        for got, expected in zip((mesh.positions, mesh.normals, mesh.faces), old_smooth_normals(path)):
            np.testing.assert_array_equal(got, expected)
    mesh = load_mesh(files[0], crease_angle=180)
    assert mesh.positions.shape == (5, 3)
    np.testing.assert_allclose(mesh.normals[4], [0, 1, 0], atol=1e-15)     # the cone's apex


def test_file_normals_are_kept_whatever_the_crease_angle():
    path = assets_dir() / "meshes" / "octahedron.ply"
    meshes = [load_mesh(path, crease_angle=angle) for angle in (1, 30, 180)]
    for mesh in meshes:
        np.testing.assert_array_equal(mesh.positions, meshes[0].positions)
        np.testing.assert_array_equal(mesh.faces, meshes[0].faces)
        np.testing.assert_array_equal(mesh.normals, meshes[0].normals)
    np.testing.assert_allclose(meshes[0].normals, meshes[0].positions)     # the file's, radial


def test_faces_without_area_at_a_crease():
    """Two faces folded at 90 degrees along p0-p1, a face with a repeated index on that edge,
    and a vertex no face uses. Each folded face keeps its own normal; the degenerate face's
    corners take the smooth normal of all faces there (both corner angles 90 degrees at p0,
    45 at p1); the unused vertex keeps its place and FALLBACK_NORMAL."""
    positions = np.array([[0, 0, 0], [1, 0, 0], [0, 1, 0], [0, 0, -1], [5, 5, 5]], dtype=float)
    faces = np.array([[0, 1, 2], [1, 0, 3], [0, 1, 1]])
    out_positions, normals, out_faces = crease_vertex_normals(positions, faces)
    assert np.isfinite(normals).all()
    np.testing.assert_allclose(np.linalg.norm(normals, axis=1), 1.0, atol=1e-15)
    np.testing.assert_array_equal(out_positions[out_faces], positions[faces])
    np.testing.assert_allclose(normals[out_faces[0]], [[0, 0, 1]] * 3, atol=1e-15)
    np.testing.assert_allclose(normals[out_faces[1]], [[0, -1, 0]] * 3, atol=1e-15)
    np.testing.assert_allclose(normals[out_faces[2]], [[0, -2 ** -0.5, 2 ** -0.5]] * 3, atol=1e-15)
    assert len(out_positions) == 3 + 3 + 1 + 1 + 1
    assert out_positions.tolist()[-1] == [5, 5, 5] and normals.tolist()[-1] == [0, 0, 1]


def test_vertex_order_copies_follow_their_vertex_in_order_of_first_use():
    """Vertex i stays vertex i where nothing splits; a split vertex's copies follow it, in the
    order the faces first use them."""
    positions, _, faces = crease_vertex_normals(
        np.array([[0, 0, 0], [1, 0, 0], [0, 1, 0], [0, 0, -1]], dtype=float),
        np.array([[1, 0, 3], [0, 1, 2]]))
    # vertex 0: face 0's copy, then face 1's; vertex 1 likewise; 2 and 3 as they were
    assert positions.tolist() == [[0, 0, 0], [0, 0, 0], [1, 0, 0], [1, 0, 0], [0, 1, 0], [0, 0, -1]]
    assert faces.tolist() == [[2, 0, 5], [1, 3, 4]]


def test_faces_touching_only_at_a_vertex_are_separate_fans():
    """Two triangles that share vertex 0 but no edge (a bow tie), 11 degrees apart: two fans,
    so vertex 0 is split, each copy with its own face's normal. Made coplanar, the two
    fans' normals are equal and they share one vertex again."""
    positions = np.array([[0, 0, 0], [1, 0, 0], [1, 1, 0], [-1, 0, 0], [-1, -1, 0.2]])
    faces = np.array([[0, 1, 2], [0, 3, 4]])
    out_positions, normals, out_faces = crease_vertex_normals(positions, faces)
    assert len(out_positions) == 6 and out_faces.tolist() == [[0, 2, 3], [1, 4, 5]]
    np.testing.assert_allclose(normals[out_faces[0]], [[0, 0, 1]] * 3, atol=1e-15)
    np.testing.assert_allclose(normals[out_faces[1]], [[0, 0.2 / 1.04 ** 0.5, 1 / 1.04 ** 0.5]] * 3,
                               atol=1e-15)
    positions[4, 2] = 0.0
    out_positions, normals, out_faces = crease_vertex_normals(positions, faces)
    np.testing.assert_array_equal(out_positions, positions)
    np.testing.assert_array_equal(out_faces, faces)
    np.testing.assert_array_equal(normals, [[0, 0, 1]] * 5)


def test_a_non_manifold_edge_joins_only_the_faces_within_the_angle():
    """Three faces on the edge p0-p1: A and B in the plane z = 0 on either side (+z), and a
    fin C hanging from it (-y, 90 degrees from both). A and B share their copies of p0 and p1;
    C has its own."""
    positions = np.array([[0, 0, 0], [1, 0, 0], [0, 1, 0], [1, -1, 0], [0, 0, -1]], dtype=float)
    faces = np.array([[0, 1, 2], [0, 3, 1], [1, 0, 4]])
    out_positions, normals, out_faces = crease_vertex_normals(positions, faces)
    assert len(out_positions) == 7
    np.testing.assert_array_equal(out_positions[out_faces], positions[faces])
    np.testing.assert_array_equal(normals[out_faces[:2]], [[[0, 0, 1]] * 3] * 2)
    np.testing.assert_array_equal(normals[out_faces[2]], [[0, -1, 0]] * 3)
    assert out_faces[0, 0] == out_faces[1, 0] != out_faces[2, 1]        # p0
    assert out_faces[0, 1] == out_faces[1, 2] != out_faces[2, 0]        # p1


@pytest.mark.parametrize("angle", [0, -5, 180.5, float("nan")])
def test_load_mesh_refuses_a_crease_angle_outside_0_to_180(tmp_path, angle):
    with pytest.raises(ValueError, match="crease_angle"):
        load_mesh(write(tmp_path, "t.obj", TRIANGLE_OBJ), crease_angle=angle)


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


# --------------------------------------------------------------------------- trimesh's import
# renderer/core/trimesh_import.py imports trimesh with scipy hidden (a fifth of a command's
# start); what trimesh reads for us must not change, and scipy must still import after.

TRIMESH_PROBE = r"""
import hashlib, sys
import numpy as np
if sys.argv[1] == "scipy first":
    import scipy.spatial
from renderer.core.builtin import assets_dir
from renderer.core.meshio import load_mesh
from renderer.core.primitives import icosphere
print("scipy" in sys.modules)
digest = hashlib.sha256()
for path in sorted((assets_dir() / "meshes").iterdir()):
    if path.suffix in (".obj", ".ply", ".stl"):
        mesh = load_mesh(path)
        for array in (mesh.positions, mesh.normals, mesh.faces):
            digest.update(np.ascontiguousarray(array).tobytes())
ball = icosphere(subdivisions=3)
digest.update(ball.positions.tobytes() + ball.faces.tobytes())
import scipy.spatial
print(scipy.spatial.cKDTree(np.zeros((2, 3))).n, digest.hexdigest())
"""


def test_trimesh_imports_without_scipy_and_reads_the_same():
    import subprocess
    import sys
    runs = {order: subprocess.run([sys.executable, "-c", TRIMESH_PROBE, order], capture_output=True,
                                  text=True, check=True).stdout.split()
            for order in ("scipy first", "trimesh first")}
    assert runs["trimesh first"][0] == "False"          # loading meshes did not import scipy
    assert runs["scipy first"][0] == "True"
    assert runs["trimesh first"][1:] == runs["scipy first"][1:] and runs["scipy first"][1] == "2"
