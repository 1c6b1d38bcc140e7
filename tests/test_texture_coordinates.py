"""Texture coordinates (docs/conventions.md, "Texture coordinates"): each primitive's UVs at
points worked out by hand, seams duplicated so no triangle spans the texture the wrong way,
the analytic shapes' meshes agreeing with the rules the ray tracer uses (uv_rules), and mesh
files keeping their UVs through merging and crease splitting."""

from pathlib import Path

import numpy as np
import pytest

from renderer.core import primitives, shapes
from renderer.core.meshio import load_mesh
from renderer.core.scene import Plane, Sphere
from renderer.core.uv_rules import plane_uv, plane_uv_axes, sphere_uv


def uvs_at(mesh, point, normal=None) -> list:
    """The UVs of every vertex at `point` (with `normal`, if given), sorted."""
    here = np.isclose(mesh.positions, point, atol=1e-12).all(axis=1)
    if normal is not None:
        here &= np.isclose(mesh.normals, normal, atol=1e-12).all(axis=1)
    return sorted(np.round(mesh.uvs[here], 12).tolist())


def u_span(mesh) -> float:
    """The widest u range of any triangle."""
    u = mesh.uvs[mesh.faces][..., 0]
    return float((u.max(axis=1) - u.min(axis=1)).max())


# --------------------------------------------------------------------------- the rules

def test_the_sphere_rule_at_the_axes():
    """u = 1/2 faces +z (the default camera), 3/4 at +x (u grows to the right seen from +z),
    1/4 at -x; v = 1 at the north pole +y, 0 at the south, 1/2 on the equator."""
    uv = sphere_uv([[0, 0, 1], [1, 0, 0], [-1, 0, 0], [0, 1, 0], [0, -1, 0]])
    assert uv.tolist() == [[0.5, 0.5], [0.75, 0.5], [0.25, 0.5], [0.5, 1.0], [0.5, 0.0]]


def test_the_plane_rule():
    """n = +y: T = +x, B = -z (v grows away from a camera at +z); n = +z: u = x, v = y; a
    normal along x takes T from -z."""
    t, b = plane_uv_axes((0, 2, 0))
    assert t.tolist() == [1, 0, 0] and b.tolist() == [0, 0, -1]
    assert plane_uv([[3, 0, -2]], (0, 0, 1)).tolist() == [[3, 0]]
    assert plane_uv([[0, 5, 0]], (0, 0, 1)).tolist() == [[0, 5]]
    t, b = plane_uv_axes((1, 0, 0))
    assert t.tolist() == [0, 0, -1] and b.tolist() == [0, 1, 0]


# --------------------------------------------------------------------------- primitives

@pytest.mark.parametrize("segments", [32, 7])
def test_uv_sphere(segments):
    mesh = primitives.uv_sphere(1.0, segments, 4)
    assert uvs_at(mesh, (0, 0, 1)) == [[0.5, 0.5]]
    if segments % 4 == 0:
        assert uvs_at(mesh, (1, 0, 0)) == [[0.75, 0.5]]
        assert uvs_at(mesh, (0, 0, -1)) == [[0.0, 0.5], [1.0, 0.5]]         # the seam, twice
    # one north-pole vertex per segment, at the centre of its segment
    assert [u for u, _ in uvs_at(mesh, (0, 1, 0))] == pytest.approx(
        (np.arange(segments) + 0.5 + (segments % 2) / 2) / segments)
    assert u_span(mesh) == pytest.approx(1 / segments)
    off_pole = np.abs(mesh.normals[:, 1]) < 1
    expected = sphere_uv(mesh.normals[off_pole])
    np.testing.assert_allclose((mesh.uvs[off_pole] - expected + 0.5) % 1.0 - 0.5, 0, atol=1e-12)


def test_icosphere_follows_the_rule_and_splits_seam_and_poles():
    mesh = primitives.icosphere(2.0, 2)
    assert u_span(mesh) < 0.2                                  # no face across the texture
    seam_point = mesh.positions[(mesh.positions[:, 0] == 0) & (mesh.positions[:, 2] < 0)
                                & (mesh.positions[:, 1] == 0)][0]
    assert [u for u, _ in uvs_at(mesh, seam_point)] == [0.0, 1.0]
    assert len(uvs_at(mesh, (0, 2, 0))) == 6                   # the pole: one per face (6)
    assert uvs_at(mesh, (0, 0, 2)) == [[0.5, 0.5]]
    rule = sphere_uv(mesh.normals)
    np.testing.assert_allclose(mesh.uvs[:, 1], rule[:, 1])
    np.testing.assert_allclose(np.sin(2 * np.pi * mesh.uvs[:, 0])[np.abs(mesh.normals[:, 1]) < 1],
                               np.sin(2 * np.pi * rule[:, 0])[np.abs(mesh.normals[:, 1]) < 1],
                               atol=1e-12)


def test_plane_primitive_and_the_analytic_plane_agree():
    mesh = primitives.plane(4.0, 2)
    assert uvs_at(mesh, (2, 0, 2)) == [[2.0, -2.0]] and uvs_at(mesh, (-2, 0, -2)) == [[-2.0, 2.0]]
    shape = shapes.plane_mesh(Plane((0, 1, 0), 0.0), size=4.0, segments=2)
    np.testing.assert_array_equal(shape.uvs, mesh.uvs)
    tilted = Plane((1, 2, 3), -1.5)
    shape = shapes.plane_mesh(tilted, size=4.0)
    np.testing.assert_array_equal(shape.uvs, plane_uv(shape.positions, tilted.normal))


def test_cube_faces_are_the_unit_square_seen_from_outside():
    mesh = primitives.cube(2.0)
    front, right, top, bottom = (0, 0, 1), (1, 0, 0), (0, 1, 0), (0, -1, 0)
    assert uvs_at(mesh, (-1, -1, 1), front) == [[0.0, 0.0]]
    assert uvs_at(mesh, (1, 1, 1), front) == [[1.0, 1.0]]
    assert uvs_at(mesh, (1, -1, 1), right) == [[0.0, 0.0]]              # +x: u runs along -z
    assert uvs_at(mesh, (-1, 1, -1), top) == [[0.0, 1.0]]               # top: v along -z
    assert uvs_at(mesh, (-1, -1, 1), bottom) == [[0.0, 1.0]]            # bottom: v along +z
    assert sorted(map(tuple, mesh.uvs.tolist())) == sorted([(0.0, 0.0), (1.0, 0.0), (1.0, 1.0),
                                                           (0.0, 1.0)] * 6)


def test_cylinder_side_and_caps():
    mesh = primitives.cylinder(2.0, 2.0, 8)
    up, down, side = (0, 1, 0), (0, -1, 0), (0, 0, 1)
    assert uvs_at(mesh, (0, -1, 2), side) == [[0.5, 0.0]]
    assert uvs_at(mesh, (0, 1, 2), side) == [[0.5, 1.0]]
    assert uvs_at(mesh, (0, 1, -2), (0, 0, -1)) == [[0.0, 1.0], [1.0, 1.0]]   # seam, twice
    assert uvs_at(mesh, (0, 1, 0), up) == [[0.5, 0.5]]
    assert uvs_at(mesh, (2, 1, 0), up) == [[1.0, 0.5]]
    assert uvs_at(mesh, (0, 1, 2), up) == [[0.5, 0.0]]                  # top: v away from +z
    assert uvs_at(mesh, (0, -1, 2), down) == [[0.5, 1.0]]               # bottom: v towards +z
    assert u_span(mesh) <= 0.5 + 1e-12                                  # the caps' widest


def test_torus_seams():
    mesh = primitives.torus(1.0, 0.5, 8, 4)
    assert uvs_at(mesh, (0, 0, 1.5)) == [[0.5, 0.0], [0.5, 1.0]]        # outer equator, v seam
    assert uvs_at(mesh, (0, 0.5, 1.0)) == [[0.5, 0.25]]                 # the tube's top
    assert uvs_at(mesh, (0, 0, -1.5)) == [[0.0, 0.0], [0.0, 1.0], [1.0, 0.0], [1.0, 1.0]]
    assert u_span(mesh) == pytest.approx(1 / 8)


def test_the_sphere_shape_carries_the_icosphere_uvs():
    mesh = shapes.sphere_mesh(Sphere((5, 0, 0), 2.0), subdivisions=1)
    np.testing.assert_array_equal(mesh.uvs, primitives.icosphere(2.0, 1).uvs)


# --------------------------------------------------------------------------- mesh files

def write(tmp_path: Path, name: str, text: str) -> Path:
    path = tmp_path / name
    path.write_text(text)
    return path


def test_obj_vt_split_at_a_seam_and_normals_stay_smooth_across_it(tmp_path):
    """Two triangles folded by 10 degrees along the edge 1-2 (under the 30-degree crease
    angle: smooth), whose faces give that edge's vertices different UVs: the positions
    join for the normals, then each edge vertex splits in two with its face's UV."""
    z = np.tan(np.radians(10.0))
    text = (f"v 0 0 0\nv 1 0 0\nv 0 1 0\nv 1 1 {z}\n"
            "vt 0 0\nvt 1 0\nvt 0 1\nvt 0.5 0\nvt 0.5 1\nvt 1 1\n"
            "f 1/1 2/2 3/3\nf 2/4 4/6 3/5\n")
    mesh = load_mesh(write(tmp_path, "fold.obj", text))
    assert len(mesh.positions) == 6 and mesh.triangle_count == 2
    assert uvs_at(mesh, (1, 0, 0)) == [[0.5, 0.0], [1.0, 0.0]]
    both = np.isclose(mesh.positions, (1, 0, 0)).all(axis=1)
    assert np.ptp(mesh.normals[both], axis=0).max() == 0.0             # one smooth normal
    assert mesh.normals[both][0, 2] != 1.0                             # bent by the fold


def test_ply_texture_coordinates(tmp_path):
    header = ("ply\nformat ascii 1.0\nelement vertex 3\nproperty float x\nproperty float y\n"
              "property float z\nproperty float s\nproperty float t\nelement face 1\n"
              "property list uchar int vertex_indices\nend_header\n")
    mesh = load_mesh(write(tmp_path, "t.ply", header + "0 0 0 0 0\n1 0 0 1 0\n0 1 0 0.25 1\n3 0 1 2\n"))
    assert mesh.uvs.tolist() == [[0, 0], [1, 0], [0.25, 1]]


def test_a_mesh_file_without_uvs_has_none_and_a_bad_uv_is_one_line(tmp_path):
    assert load_mesh(write(tmp_path, "t.obj", "v 0 0 0\nv 1 0 0\nv 0 1 0\nf 1 2 3\n")).uvs is None
    from renderer.errors import SceneError
    with pytest.raises(SceneError) as info:
        load_mesh(write(tmp_path, "n.obj", "v 0 0 0\nv 1 0 0\nv 0 1 0\nvt 0 0\nvt nan 0\n"
                                           "vt 0 1\nf 1/1 2/2 3/3\n"))
    assert "has texture coordinates (nan, 0) that are not finite" in info.value.line()
