"""Scene files: the built-in scenes, the documented example, and every refusal's message.

Each bad input must raise a SceneError whose line is "FILE: KEY.PATH: reason"; the command
line must turn it into that one line on stderr, exit status 2 and no output file.
"""

import dataclasses
import re
import tomllib
from pathlib import Path

import numpy as np
import pytest

from renderer.core.builtin import (DEFAULT_SCENE, assets_dir, builtin_scenes, resolve_scene,
                              scene_descriptions)
from renderer.errors import SceneError
from renderer.core.primitives import cube, plane, uv_sphere
from renderer.core.scene import (Camera, DirectionalLight, Material, Plane, PointLight, Scene, SceneObject,
                            Transform)
from renderer.core.meshio import load_mesh
from renderer.core.scene_file import load_scene, scene_from_dict
from renderer.core.shadow_settings import RESOLUTIONS, BiasRule, Shadow, auto_bias

REPO = Path(__file__).resolve().parent.parent
BUILTIN_NAMES = {"sphere", "gouraud_vs_phong", "coloured_lights", "point_light_plane",
                 "mesh_file", "open_mesh_inside", "orthographic", "near_plane", "flat_shading",
                 "hierarchy", "classic", "cornell_box", "mesh_shadow", "tir_bubble",
                 "shadow_plane", "shadow_room", "shadow_curved", "depth_of_field", "soft_shadows",
                 "glossy", "motion_blur", "textured_mesh", "checker_horizon", "globe",
                 "shadow_boxes", "shadow_thin_contact", "shadow_big_floor", "shadow_lowpoly_sphere",
                 "shadow_knot_floor", "radiosity_furnace", "radiosity_plates", "cornell_box_radiosity",
                 "radiosity_window", "radiosity_specular", "tessellated_sphere", "pn_triangles",
                 "displaced_plane"}
# Scenes whose objects deliberately reach outside the view: through the near plane (a room
# around the camera, a ground under it), or a backdrop (tir_bubble's checkerboard) filling
# the view.
PARTLY_OUTSIDE = {"near_plane", "tir_bubble", "shadow_room", "checker_horizon", "shadow_boxes", "radiosity_furnace",
                  "shadow_big_floor", "radiosity_window", "radiosity_specular", "tessellated_sphere",
                  "pn_triangles"}
IMAGE_SIZES = [(640, 480), (320, 240)]
# Objects out of view by design: the wall behind a camera inside a closed room (the white
# furnace: closed, so that B = E / (1 - rho) holds; the window room's wall beside the camera,
# which the light bounces off all the same).
BEHIND_THE_CAMERA = {("radiosity_furnace", "front"), ("radiosity_window", "left_wall")}

OBJ_TRIANGLE = "v 0 0 0\nv 1 0 0\nv 0 1 0\nf 1 2 3\n"


def write(folder: Path, name: str, text: str) -> Path:
    path = folder / name
    path.write_text(text)
    return path


def load_error(tmp_path: Path, text: str, name: str = "scene.toml") -> tuple[Path, str]:
    path = write(tmp_path, name, text)
    with pytest.raises(SceneError) as info:
        load_scene(path)
    return path, info.value.line()


# --------------------------------------------------------------------------- built-in scenes

def test_the_builtin_scenes_are_all_there():
    assert set(builtin_scenes()) == BUILTIN_NAMES
    for name, path in builtin_scenes().items():
        assert path == assets_dir() / "scenes" / f"{name}.toml"


@pytest.mark.parametrize("name", sorted(BUILTIN_NAMES))
def test_builtin_scene_loads(name):
    scene = load_scene(builtin_scenes()[name])
    assert scene.name == name
    assert scene.source == str(builtin_scenes()[name])
    # lit: by lights, or (radiosity's scenes) by surfaces that emit
    emits = any(any(obj.material.emission) for obj in scene.objects)
    assert scene.objects and (scene.directional_lights or scene.point_lights or emits)
    description = scene_descriptions()[name]
    assert description and "\n" not in description
    for obj in scene.objects:
        assert obj.mesh.triangle_count > 0
        assert np.isfinite(obj.mesh.positions).all()
    world = scene.world_matrices()
    assert all(abs(np.linalg.det(m[:3, :3])) > 1e-6 for m in world)


def clip_coordinates(scene: Scene, width: int, height: int):
    """Per object: clip coordinates of its vertices, triangle centroids and edge midpoints."""
    frame = scene.matrices(width, height)
    out = []
    for obj, matrices in zip(scene.objects, frame.objects):
        tri = obj.mesh.positions[obj.mesh.faces]
        samples = np.concatenate([obj.mesh.positions, tri.mean(axis=1),
                                  (tri + np.roll(tri, 1, axis=1)).reshape(-1, 3) / 2])
        homogeneous = np.c_[samples, np.ones(len(samples))]
        clip = (frame.projection @ frame.view @ matrices.model @ homogeneous.T).T
        out.append((obj.name, clip, len(obj.mesh.positions)))
    return out


def inside_clip_volume(clip):
    w = clip[:, 3]
    return (w > 0) & (np.abs(clip[:, :3]) <= w[:, None]).all(axis=1)


# The second size is the full run's (--all): both are 4:3, so the projection, and with it
# every clip coordinate checked, is the first size's.
@pytest.mark.parametrize("name", sorted(BUILTIN_NAMES))
@pytest.mark.parametrize("size", [pytest.param(size, marks=[pytest.mark.slow] if index else [])
                                  for index, size in enumerate(IMAGE_SIZES)])
def test_every_object_of_a_builtin_scene_is_in_view(name, size):
    scene = load_scene(builtin_scenes()[name])
    shapes = {obj.name: obj.shape for obj in scene.objects}
    for obj_name, clip, vertex_count in clip_coordinates(scene, *size):
        inside = inside_clip_volume(clip)
        if (name, obj_name) in BEHIND_THE_CAMERA:
            assert not inside.any(), f"{name}: {obj_name} is in view"
            continue
        assert inside.any(), f"{name}: {obj_name} is out of view"
        # A plane is infinite: its square (renderer/core/shapes.py) reaches out of view by design.
        if name not in PARTLY_OUTSIDE and not isinstance(shapes[obj_name], Plane):
            assert inside[:vertex_count].all(), f"{name}: {obj_name} is partly out of view"


def test_near_plane_scene_has_triangles_crossing_the_near_plane():
    scene = load_scene(builtin_scenes()["near_plane"])
    frame = scene.matrices(640, 480)
    crossing = 0
    for obj, matrices in zip(scene.objects, frame.objects):
        homogeneous = np.c_[obj.mesh.positions, np.ones(len(obj.mesh.positions))]
        eye_z = (frame.view @ matrices.model @ homogeneous.T).T[:, 2]
        depth = -eye_z[obj.mesh.faces]                                   # (F, 3) distances
        crossing += int(((depth < scene.camera.near).any(axis=1)
                         & (depth > scene.camera.near).any(axis=1)).sum())
        if obj.name in ("room", "rail"):
            assert (depth < 0).any(), f"{obj.name} should reach behind the camera"
    assert crossing >= 4


def test_builtin_scenes_cover_shading_modes_sides_and_projections():
    scenes = {name: load_scene(path) for name, path in builtin_scenes().items()}
    materials = [obj.material for s in scenes.values() for obj in s.objects]
    assert {m.shading for m in materials} == {"flat", "gouraud", "phong"}
    assert {m.two_sided for m in materials} == {True, False}
    assert {s.camera.projection for s in scenes.values()} == {"perspective", "parallel"}
    assert scenes["orthographic"].camera.projection == "parallel"


def test_default_sphere_scene():
    scene = load_scene(resolve_scene(None))
    assert scene.name == DEFAULT_SCENE == "sphere"
    assert len(scene.directional_lights) == 1 and len(scene.point_lights) == 1
    [ball] = scene.objects
    assert ball.material.shading == "phong" and min(ball.material.ks) > 0


def test_gouraud_vs_phong_is_the_same_coarse_sphere_twice():
    a, b = load_scene(builtin_scenes()["gouraud_vs_phong"]).objects
    assert (a.material.shading, b.material.shading) == ("gouraud", "phong")
    assert dataclasses.replace(a.material, shading="phong") == b.material
    np.testing.assert_array_equal(a.mesh.positions, b.mesh.positions)
    assert a.mesh.triangle_count <= 512


def test_point_light_plane_puts_the_light_over_the_middle_of_a_grid_cell():
    scene = load_scene(builtin_scenes()["point_light_plane"])
    shadings = {obj.material.shading for obj in scene.objects}
    assert shadings == {"gouraud", "phong"}
    world = scene.world_matrices()
    for obj, model in zip(scene.objects, world):
        vertices = (model @ np.c_[obj.mesh.positions, np.ones(len(obj.mesh.positions))].T).T
        nearest = min(np.linalg.norm(vertices[:, :3] - light.position, axis=1).min()
                      for light in scene.point_lights)
        lowest = min(light.position[1] for light in scene.point_lights)
        assert nearest > 1.2 * lowest            # no vertex right under a light


def test_mesh_file_scene_uses_obj_ply_and_stl():
    scene = load_scene(builtin_scenes()["mesh_file"])
    suffixes = {Path(obj.mesh.source).suffix for obj in scene.objects}
    assert suffixes == {".obj", ".ply", ".stl"}


def test_open_mesh_inside_scene_has_both_sides():
    scene = load_scene(builtin_scenes()["open_mesh_inside"])
    assert sorted(obj.material.two_sided for obj in scene.objects) == [False, True]


def test_hierarchy_scene_has_parents_shear_and_rotation():
    scene = load_scene(builtin_scenes()["hierarchy"])
    by_name = {obj.name: obj for obj in scene.objects}
    assert by_name["ring"].parent == "planet" and by_name["planet"].parent == "sun"
    assert any(obj.transform.shear for obj in scene.objects)
    assert any(obj.parent and by_name[obj.parent].transform.shear for obj in scene.objects)


# --------------------------------------------------------------------------- resolving names

def test_resolve_scene_by_name_and_by_path(tmp_path):
    assert resolve_scene(None) == builtin_scenes()["sphere"]
    assert resolve_scene("hierarchy") == builtin_scenes()["hierarchy"]
    mine = write(tmp_path, "mine.toml", "")
    assert resolve_scene(str(mine)) == mine


def test_resolve_scene_unknown_lists_the_builtin_names():
    with pytest.raises(SceneError) as info:
        resolve_scene("spher")
    assert info.value.line() == (
        "spher: no such scene file or built-in scene; did you mean 'sphere'? built-in scenes: "
        + ", ".join(sorted(BUILTIN_NAMES)))


def test_resolve_scene_missing_path(tmp_path):
    missing = str(tmp_path / "nothing.toml")
    with pytest.raises(SceneError) as info:
        resolve_scene(missing)
    assert info.value.line().startswith(f"{missing}: no such scene file or built-in scene; ")


def test_load_scene_takes_a_builtin_name_from_any_folder(tmp_path, monkeypatch):
    monkeypatch.chdir(tmp_path)
    scene = load_scene("hierarchy")
    assert scene.name == "hierarchy" and scene.source == str(builtin_scenes()["hierarchy"])
    assert summary(scene) == summary(load_scene(builtin_scenes()["hierarchy"]))
    assert load_scene(Path("sphere")).source == str(builtin_scenes()["sphere"])


def test_load_scene_an_existing_file_wins_over_a_name(tmp_path, monkeypatch):
    monkeypatch.chdir(tmp_path)
    write(tmp_path, "sphere", 'name = "mine"\n')        # a file without .toml named like one
    assert load_scene("sphere").name == "mine"
    assert resolve_scene("sphere") == Path("sphere")     # the command line's rule is the same
    (tmp_path / "sphere").unlink()
    (tmp_path / "sphere").mkdir()                        # a folder of that name does not shadow it
    assert load_scene("sphere").source == str(builtin_scenes()["sphere"])
    assert resolve_scene("sphere") == builtin_scenes()["sphere"]


def test_load_scene_unknown_name_is_the_command_lines_line(tmp_path, monkeypatch, capsys):
    from renderer.cli import main
    monkeypatch.chdir(tmp_path)
    with pytest.raises(SceneError) as info:
        load_scene("spher")
    assert info.value.line() == (
        "spher: no such scene file or built-in scene; did you mean 'sphere'? built-in scenes: "
        + ", ".join(sorted(BUILTIN_NAMES)))
    assert main(["render", "spher", "--backend", "reference", "--size", "8x6"]) == 2
    assert capsys.readouterr().err.splitlines() == [f"renderer: {info.value.line()}"]
    assert list(tmp_path.iterdir()) == []


def test_load_scene_a_missing_path_is_still_not_found(tmp_path):
    for missing in (tmp_path / "nothing.toml", tmp_path / "nothing", "nothing.toml"):
        with pytest.raises(SceneError) as info:
            load_scene(missing)
        assert info.value.line() == f"{missing}: scene file not found"


# --------------------------------------------------------------------------- the complete example

def documented_example() -> str:
    text = (REPO / "docs" / "scene-format.md").read_text()
    return re.search(r"## Complete example.*?```toml\n(.*?)```", text, re.S)[1]


def summary(scene: Scene) -> dict:
    """Everything in a scene, comparable with == (meshes by their arrays)."""
    return {
        "camera": dataclasses.asdict(scene.camera), "ambient": scene.ambient,
        "background": scene.background, "name": scene.name,
        "directional": [dataclasses.asdict(x) for x in scene.directional_lights],
        "point": [dataclasses.asdict(x) for x in scene.point_lights],
        "objects": [(o.name, o.parent, o.cull, o.casts_shadows, o.receives_shadows,
                     dataclasses.asdict(o.material),
                     dataclasses.asdict(o.transform), o.mesh.positions.tolist(),
                     o.mesh.normals.tolist(), o.mesh.faces.tolist()) for o in scene.objects],
    }


# The example's directional light: shadow_bias names normal and slope; constant keeps the
# automatic rule's value for its filter (0.5 texels).
EXAMPLE_SHADOW = Shadow(resolution=2048, filter="pcf3x3",
                        bias=BiasRule(normal=2.0, constant=0.5, slope=0.5))


def test_complete_example_loads_with_every_value(tmp_path):
    scene = load_scene(write(tmp_path, "example.toml", documented_example()))
    assert scene.name == "example"
    assert scene.background == (0.05, 0.05, 0.1) and scene.ambient == (0.2, 0.2, 0.2)
    assert scene.camera == Camera(eye=(0.0, 2.0, 8.0), look=(0.0, 0.5, 0.0), up=(0.0, 1.0, 0.0),
                                  projection="perspective", fov_y=50.0, height=4.0, near=0.5,
                                  far=60.0)
    assert scene.directional_lights == [DirectionalLight((-1.0, -1.0, -1.0), (0.8, 0.8, 0.8),
                                                        EXAMPLE_SHADOW)]
    assert scene.point_lights == [PointLight((2.0, 3.0, 2.0), (0.5, 0.4, 0.3), (1.0, 0.1, 0.01),
                                             Shadow(enabled=False))]
    floor, ball, box, knot, gem = scene.objects
    assert [(o.casts_shadows, o.receives_shadows) for o in scene.objects] == [
        (False, True), (True, True), (True, True), (True, True), (True, False)]
    red = Material((0.3, 0.05, 0.05), (0.8, 0.1, 0.1), (0.6, 0.6, 0.6), 50.0, False, "phong")
    grey = Material((0.4, 0.4, 0.4), (0.5, 0.5, 0.5), (0.0, 0.0, 0.0), 1.0, True, "gouraud")
    assert (floor.name, floor.material, floor.cull, floor.parent) == ("floor", grey, "none", None)
    assert floor.transform == Transform(translate=(0.0, -1.0, 0.0))
    np.testing.assert_array_equal(floor.mesh.positions, plane(10.0, 4).positions)
    assert (ball.material, ball.cull) == (red, "back")
    assert ball.transform == Transform((1.0, 1.5, 1.0), {}, (0.0, 0.0, 10.0), (-2.0, 0.5, 0.0))
    np.testing.assert_array_equal(ball.mesh.faces, uv_sphere(1.0, 24, 12).faces)
    assert box.parent == "ball"
    assert box.material == Material(kd=(0.1, 0.2, 0.9), ks=(0.5, 0.5, 0.5), n=10.0,
                                    shading="flat")
    assert box.transform == Transform((0.8, 0.8, 0.8), {"xy": 0.3, "zx": -0.2},
                                      (30.0, 45.0, 0.0), (0.0, 1.2, 0.0))
    np.testing.assert_array_equal(box.mesh.positions, cube(0.5).positions)
    assert Path(knot.mesh.source) == assets_dir() / "meshes" / "torus_knot.obj"
    assert knot.material == Material() and knot.cull == "back"
    # crease_angle 120 is above the 109.5 degrees between the tetrahedron's face normals:
    # smooth, 4 vertices (the default 30 would give 12, flat)
    assert Path(gem.mesh.source) == assets_dir() / "meshes" / "tetrahedron.stl"
    assert gem.mesh.positions.shape == (4, 3) and gem.mesh.faces.shape == (4, 3)
    np.testing.assert_allclose(gem.mesh.normals, gem.mesh.positions / np.sqrt(3), atol=1e-6)
    assert gem.transform == Transform((0.5, 0.5, 0.5), translate=(0.0, 0.5, -2.0))
    # the child's world matrix is its parent's times its own
    world = dict(zip([o.name for o in scene.objects], scene.world_matrices()))
    np.testing.assert_allclose(world["box"], world["ball"] @ box.transform.matrix())


def test_complete_example_round_trip_file_dict_and_dataclasses(tmp_path):
    text = documented_example()
    from_file = load_scene(write(tmp_path, "example.toml", text))
    from_dict = scene_from_dict(tomllib.loads(text), source="example", base_dir=tmp_path)
    assert summary(from_file) == summary(from_dict)
    # the same scene written with the dataclasses
    red = Material((0.3, 0.05, 0.05), (0.8, 0.1, 0.1), (0.6, 0.6, 0.6), 50.0, False, "phong")
    grey = Material((0.4, 0.4, 0.4), (0.5, 0.5, 0.5), (0.0, 0.0, 0.0), 1.0, True, "gouraud")
    built = Scene(
        camera=Camera((0.0, 2.0, 8.0), (0.0, 0.5, 0.0), (0.0, 1.0, 0.0), "perspective",
                      50.0, 4.0, 0.5, 60.0),
        objects=[
            SceneObject("floor", plane(10.0, 4), grey, Transform(translate=(0.0, -1.0, 0.0)),
                        casts_shadows=False),
            SceneObject("ball", uv_sphere(1.0, 24, 12), red,
                        Transform((1.0, 1.5, 1.0), {}, (0.0, 0.0, 10.0), (-2.0, 0.5, 0.0)),
                        cull="back"),
            SceneObject("box", cube(0.5),
                        Material(kd=(0.1, 0.2, 0.9), ks=(0.5, 0.5, 0.5), n=10.0, shading="flat"),
                        Transform((0.8, 0.8, 0.8), {"xy": 0.3, "zx": -0.2}, (30.0, 45.0, 0.0),
                                  (0.0, 1.2, 0.0)), parent="ball"),
            from_file.objects[3],
            SceneObject("gem", load_mesh(assets_dir() / "meshes" / "tetrahedron.stl",
                                         crease_angle=120.0),
                        transform=Transform((0.5, 0.5, 0.5), translate=(0.0, 0.5, -2.0)),
                        receives_shadows=False),
        ],
        directional_lights=[DirectionalLight((-1.0, -1.0, -1.0), (0.8, 0.8, 0.8), EXAMPLE_SHADOW)],
        point_lights=[PointLight((2.0, 3.0, 2.0), (0.5, 0.4, 0.3), (1.0, 0.1, 0.01),
                                 Shadow(enabled=False))],
        ambient=(0.2, 0.2, 0.2), background=(0.05, 0.05, 0.1), name="example")
    assert summary(built) == summary(from_file)
    for a, b in zip(built.world_matrices(), from_file.world_matrices()):
        np.testing.assert_array_equal(a, b)


def test_empty_file_gives_the_defaults(tmp_path):
    scene = load_scene(write(tmp_path, "blank.toml", ""))
    assert scene.name == "blank"
    assert summary(scene) == summary(Scene(name="blank"))


def test_defaults_of_objects_lights_and_scalars(tmp_path):
    scene = load_scene(write(tmp_path, "d.toml", """
ambient = 0.3
[[lights]]
type = "point"
[[lights]]
type = "directional"
[[objects]]
mesh = { primitive = "cube" }
scale = 2
"""))
    assert scene.ambient == (0.3, 0.3, 0.3)
    assert scene.point_lights == [PointLight()] and scene.directional_lights == [DirectionalLight()]
    [obj] = scene.objects
    assert obj.name == "object0" and obj.material == Material() and obj.cull == "none"
    assert obj.casts_shadows and obj.receives_shadows
    assert scene.point_lights[0].shadow == Shadow(enabled=True, resolution=None, filter="pcf2x2",
                                                  bias=None)
    assert obj.transform == Transform(scale=(2.0, 2.0, 2.0))


def light_shadow(tmp_path, keys: str, kind: str = "directional") -> Shadow:
    scene = load_scene(write(tmp_path, "s.toml", f'[[lights]]\ntype = "{kind}"\n{keys}'))
    return (scene.directional_lights or scene.point_lights)[0].shadow


@pytest.mark.parametrize("kind", ["directional", "point"])
def test_shadow_keys_of_a_light(tmp_path, kind):
    assert light_shadow(tmp_path, "shadows = false\n", kind) == Shadow(enabled=False)
    for resolution in RESOLUTIONS:
        assert light_shadow(tmp_path, f"shadow_resolution = {resolution}\n", kind).resolution \
            == resolution
    assert light_shadow(tmp_path, 'shadow_resolution = "auto"\n', kind).resolution is None
    for name in ("hard", "pcf2x2", "pcf3x3", "pcf5x5"):
        assert light_shadow(tmp_path, f'shadow_filter = "{name}"\n', kind).filter == name


def test_shadow_bias_terms_not_given_keep_the_automatic_rule(tmp_path):
    """auto_bias: a normal offset of the filter's footprint radius (1/2 texel for hard, K/2
    for K x K) and 1/2 texel towards the light; a shadow_bias table replaces what it names."""
    shadow = light_shadow(tmp_path, 'shadow_filter = "pcf5x5"\nshadow_bias = { slope = 2 }\n')
    assert shadow.bias_rule() == BiasRule(normal=2.5, constant=0.5, slope=2.0)
    shadow = light_shadow(tmp_path, 'shadow_filter = "hard"\nshadow_bias = { constant = 0 }\n')
    assert shadow.bias_rule() == BiasRule(normal=0.5, constant=0.0, slope=0.0)
    shadow = light_shadow(tmp_path, "shadow_bias = { normal = 0, constant = 1, slope = 0.5 }\n")
    assert shadow.bias_rule() == BiasRule(normal=0.0, constant=1.0, slope=0.5)
    # an empty table is the automatic rule, written out
    assert light_shadow(tmp_path, "shadow_bias = {}\n").bias == auto_bias("pcf2x2") \
        == BiasRule(normal=1.0, constant=0.5)
    # the filter counts wherever its key stands
    shadow = light_shadow(tmp_path, 'shadow_bias = { slope = 1 }\nshadow_filter = "pcf3x3"\n')
    assert shadow.bias_rule() == BiasRule(normal=1.5, constant=0.5, slope=1.0)


def test_objects_cast_and_receive_shadows_as_told(tmp_path):
    scene = load_scene(write(tmp_path, "s.toml", OBJECT + "casts_shadows = false\n"
                             '[[objects]]\nmesh = { primitive = "cube" }\n'
                             "receives_shadows = false\ncasts_shadows = true\n"))
    assert [(o.casts_shadows, o.receives_shadows) for o in scene.objects] == [(False, True),
                                                                              (True, False)]


def test_parallel_camera_allows_a_negative_near(tmp_path):
    scene = load_scene(write(tmp_path, "p.toml", """
[camera]
projection = "parallel"
near = -5.0
far = 5.0
height = 3.0
"""))
    assert (scene.camera.projection, scene.camera.near, scene.camera.height) == ("parallel", -5.0, 3.0)


def test_extreme_but_renderable_values_load(tmp_path):
    """Up along the view (look_at's fallback), a zero scale (a singular model matrix, the
    cofactor normal matrix), Phong exponent 0 and reversed-Z: allowed, see conventions.md."""
    scene = load_scene(write(tmp_path, "x.toml", """
[camera]
eye = [0, 5, 0]
reversed_z = true
[[objects]]
mesh = { primitive = "cube" }
scale = [1, 0, 1]
material = { n = 0 }
"""))
    assert scene.camera.up == (0.0, 1.0, 0.0) and scene.camera.reversed_z is True
    assert scene.objects[0].transform.scale == (1.0, 0.0, 1.0)
    assert scene.objects[0].material.n == 0.0


def test_mesh_file_relative_to_the_scene_folder(tmp_path):
    (tmp_path / "meshes").mkdir()
    mesh_path = write(tmp_path / "meshes", "tri.obj", OBJ_TRIANGLE)
    scene = load_scene(write(tmp_path, "s.toml", '[[objects]]\nmesh = { file = "meshes/tri.obj" }\n'))
    assert scene.objects[0].mesh.source == str(mesh_path)
    assert scene.objects[0].mesh.triangle_count == 1


def test_scene_from_dict_accepts_tuples_and_names_its_source():
    scene = scene_from_dict({"camera": {"eye": (1, 2, 3)},
                             "objects": [{"name": "c", "mesh": {"primitive": "cube"}}]})
    assert scene.camera.eye == (1.0, 2.0, 3.0) and scene.source == "<dict>"
    with pytest.raises(SceneError) as info:
        scene_from_dict({"camera": {"eye": (1, 2)}}, source="built in Python")
    assert info.value.line() == ("built in Python: camera.eye: expected a list of 3 numbers, "
                                 "got a list of 2 items")


# --------------------------------------------------------------------------- refusals

OBJECT = '[[objects]]\nname = "ball"\nmesh = { primitive = "uv_sphere" }\n'
LIGHT = '[[lights]]\ntype = "directional"\n'
POINT = '[[lights]]\ntype = "point"\n'

# (test id, scene text, expected "KEY.PATH: reason" after "FILE: ")
BAD_SCENES = [
    # unknown keys, with the closest known key suggested
    ("unknown top-level key", "objcts = []\n", "objcts: unknown key; did you mean 'objects'?"),
    ("unknown camera key", "[camera]\nfovy = 40\n", "camera.fovy: unknown key; did you mean 'fov_y'?"),
    ("unknown key, no close match", "[camera]\nzoom = 2\n",
     "camera.zoom: unknown key; known keys here: eye, look, up, projection, fov_y, height, near, far, reversed_z, "
     "aperture, focus_distance, shutter"),
    ("unknown inline material key", OBJECT + 'material = { kdd = [1, 0, 0] }\n',
     "objects[0].material.kdd: unknown key; did you mean 'kd'?"),
    ("unknown light key for its type", '[[lights]]\ntype = "directional"\nposition = [0, 1, 0]\n',
     "lights[0].position: belongs to point lights, not directional ones; keys here: type, "
     "direction, intensity, shadows, shadow_resolution, shadow_filter, shadow_bias"),
    ("unknown object key", OBJECT + "translation = [0, 1, 0]\n",
     "objects[0].translation: unknown key; did you mean 'translate'?"),
    ("unknown shear factor", OBJECT + "shear = { xx = 1.0 }\n",
     "objects[0].shear.xx: unknown key; known keys here: xy, xz, yx, yz, zx, zy"),
    # wrong types
    ("string for a vector", '[camera]\nup = "y"\n',
     "camera.up: expected a list of 3 numbers, got a string ('y')"),
    ("short vector", "[camera]\neye = [0, 5]\n",
     "camera.eye: expected a list of 3 numbers, got a list of 2 items"),
    ("string inside a vector", '[camera]\nlook = [0, "up", 0]\n',
     "camera.look: expected a list of 3 numbers, item 1 is a string ('up')"),
    ("string for a number", '[camera]\nfov_y = "wide"\n',
     "camera.fov_y: expected a number, got a string ('wide')"),
    ("boolean for a number", "[materials.m]\nn = true\n",
     "materials.m.n: expected a number, got a boolean (true)"),
    ("number for a boolean", "[materials.m]\ntwo_sided = 1\n",
     "materials.m.two_sided: expected true or false, got an integer (1)"),
    ("float for a count", '[[objects]]\nmesh = { primitive = "uv_sphere", segments = 16.0 }\n',
     "objects[0].mesh.segments: expected an integer, got a number (16)"),
    ("string for a colour", 'background = "black"\n',
     "background: expected a number or a list of 3 numbers, got a string ('black')"),
    ("table for a scale", OBJECT + "scale = { x = 2 }\n",
     "objects[0].scale: expected a number or a list of 3 numbers, got a table"),
    ("objects as a table", "[objects]\nname = 'a'\n",
     "objects: expected a list of tables ([[objects]]), got a table"),
    ("camera as a list", "camera = [1, 2, 3]\n",
     "camera: expected a table, got a list of 3 items"),
    ("mesh as a string", '[[objects]]\nmesh = "cube"\n',
     "objects[0].mesh: expected a table such as {primitive = \"uv_sphere\"} or "
     "{file = \"meshes/knot.obj\"}, got a string ('cube')"),
    ("material as a number", OBJECT + "material = 3\n",
     "objects[0].material: expected a material name (string) or an inline table, got an integer (3)"),
    ("parent as a number", OBJECT + "parent = 1\n",
     "objects[0].parent: expected a string, got an integer (1)"),
    # NaN and Inf (TOML allows them)
    ("nan number", "[camera]\nfov_y = nan\n", "camera.fov_y: expected a finite number, got nan"),
    ("inf in a vector", "[camera]\neye = [0, inf, 5]\n",
     "camera.eye: expected finite numbers, item 1 is inf"),
    ("nan in a colour", "[materials.m]\nkd = [0.5, nan, 0.5]\n",
     "materials.m.kd: expected finite numbers, item 1 is nan"),
    ("-inf translate", OBJECT + "translate = [0, 0, -inf]\n",
     "objects[0].translate: expected finite numbers, item 2 is -inf"),
    ("nan light intensity", '[[lights]]\ntype = "point"\nintensity = nan\n',
     "lights[0].intensity: expected finite numbers, item 0 is nan"),
    ("nan scale", OBJECT + "scale = nan\n", "objects[0].scale: expected finite numbers, item 0 is nan"),
    ("nan primitive argument", '[[objects]]\nmesh = { primitive = "cube", size = nan }\n',
     "objects[0].mesh.size: expected a finite number, got nan"),
    # the camera
    ("zero up", "[camera]\nup = [0, 0, 0]\n",
     "camera.up: must not be zero length; up says which way is up in the image"),
    ("reversed_z as a string", '[camera]\nreversed_z = "yes"\n',
     "camera.reversed_z: expected true or false, got a string ('yes')"),
    ("eye equals look", "[camera]\neye = [1, 2, 3]\nlook = [1, 2, 3]\n",
     "camera.look: is the same point as camera.eye; the camera needs eye - look to be a direction"),
    ("zero near", "[camera]\nnear = 0\n",
     "camera.near: must be > 0 for a perspective camera, got 0"),
    ("negative near", "[camera]\nnear = -1.0\n",
     "camera.near: must be > 0 for a perspective camera, got -1"),
    ("far below near", "[camera]\nnear = 0.1\nfar = 0.05\n",
     "camera.far: must be greater than near (0.1), got 0.05"),
    ("far equal to near", "[camera]\nnear = 2.0\nfar = 2.0\n",
     "camera.far: must be greater than near (2), got 2"),
    ("parallel far below near", '[camera]\nprojection = "parallel"\nnear = -1.0\nfar = -2.0\n',
     "camera.far: must be greater than near (-1), got -2"),
    ("zero parallel height", '[camera]\nprojection = "parallel"\nheight = 0\n',
     "camera.height: must be > 0, got 0"),
    ("fov_y zero", "[camera]\nfov_y = 0\n",
     "camera.fov_y: must be between 0 and 180 degrees (both excluded), got 0"),
    ("fov_y 180", "[camera]\nfov_y = 180\n",
     "camera.fov_y: must be between 0 and 180 degrees (both excluded), got 180"),
    ("fov_y negative", "[camera]\nfov_y = -45.0\n",
     "camera.fov_y: must be between 0 and 180 degrees (both excluded), got -45"),
    ("unknown projection", '[camera]\nprojection = "orthographic"\n',
     "camera.projection: unknown projection 'orthographic'; expected one of: perspective, parallel"),
    # the thin lens (docs/scene-format.md, [camera])
    ("negative aperture", "[camera]\naperture = -0.1\n", "camera.aperture: must be >= 0, got -0.1"),
    ("nan aperture", "[camera]\naperture = nan\n", "camera.aperture: expected a finite number, got nan"),
    ("infinite aperture", "[camera]\naperture = inf\n", "camera.aperture: expected a finite number, got inf"),
    ("aperture as a string", '[camera]\naperture = "f/2"\n',
     "camera.aperture: expected a number, got a string ('f/2')"),
    ("parallel camera with a lens", '[camera]\nprojection = "parallel"\naperture = 0.2\n',
     "camera.aperture: must be 0 with a parallel camera, got 0.2: a lens focuses rays from one "
     "eye, and a parallel camera has none"),
    ("zero focus distance", "[camera]\nfocus_distance = 0\n", "camera.focus_distance: must be > 0, got 0"),
    ("negative focus distance", "[camera]\nfocus_distance = -3\n",
     "camera.focus_distance: must be > 0, got -3"),
    ("focus distance below float32's inverse", "[camera]\nfocus_distance = 1e-30\n",
     "camera.focus_distance: must be >= 1e-18 (its inverse must fit the GPU's float32 "
     "arithmetic), got 1e-30"),
    # transforms
    ("negative scale", OBJECT + "scale = [-1, 1, 1]\n",
     "objects[0].scale: must be >= 0 in every component, got [-1, 1, 1]: a negative scale turns "
     "the object inside out"),
    ("singular shear", OBJECT + "shear = { xy = 1.0, yx = 1.0 }\n",
     "objects[0].shear: makes the model matrix singular: its determinant is 0; it must stay > 0"),
    ("mirroring shear", OBJECT + "shear = { xy = 2.0, yx = 1.0 }\n",
     "objects[0].shear: makes the model matrix a mirror (inside out): its determinant is -1; "
     "it must stay > 0"),
    ("unknown cull", OBJECT + 'cull = "backface"\n',
     "objects[0].cull: unknown cull mode 'backface'; did you mean 'back'? expected one of: "
     "none, back, front"),
    # names and parents
    ("duplicate names", OBJECT + OBJECT,
     "objects[1].name: duplicate object name 'ball' (objects[0] has it too)"),
    ("duplicate default name", '[[objects]]\nname = "object1"\nmesh = { primitive = "cube" }\n'
     '[[objects]]\nmesh = { primitive = "cube" }\n',
     "objects[1]: duplicate object name 'object1' (objects[0] has it too)"),
    ("unknown parent", OBJECT + '[[objects]]\nname = "box"\nmesh = { primitive = "cube" }\n'
     'parent = "bal"\n',
     "objects[1].parent: no object named 'bal'; did you mean 'ball'? objects in this scene: ball, box"),
    ("parent cycle", '[[objects]]\nname = "a"\nparent = "b"\nmesh = { primitive = "cube" }\n'
     '[[objects]]\nname = "b"\nparent = "a"\nmesh = { primitive = "cube" }\n',
     "objects[0].parent: parent cycle: a -> b -> a"),
    ("longer parent cycle", '[[objects]]\nname = "root"\nmesh = { primitive = "cube" }\n'
     '[[objects]]\nname = "a"\nparent = "c"\nmesh = { primitive = "cube" }\n'
     '[[objects]]\nname = "b"\nparent = "a"\nmesh = { primitive = "cube" }\n'
     '[[objects]]\nname = "c"\nparent = "b"\nmesh = { primitive = "cube" }\n',
     "objects[1].parent: parent cycle: a -> c -> b -> a"),
    ("own parent", OBJECT + 'parent = "ball"\n', "objects[0].parent: parent cycle: ball -> ball"),
    # primitives
    ("unknown primitive", '[[objects]]\nmesh = { primitive = "sphere" }\n',
     "objects[0].mesh.primitive: unknown primitive 'sphere'; did you mean 'uv_sphere'? expected "
     "one of: uv_sphere, icosphere, plane, cube, cylinder, torus"),
    ("too few segments", '[[objects]]\nmesh = { primitive = "uv_sphere", segments = 2 }\n',
     "objects[0].mesh.segments: must be >= 3, got 2"),
    ("too few rings", '[[objects]]\nmesh = { primitive = "uv_sphere", rings = 1 }\n',
     "objects[0].mesh.rings: must be >= 2, got 1"),
    ("zero radius", '[[objects]]\nmesh = { primitive = "cylinder", radius = 0 }\n',
     "objects[0].mesh.radius: must be > 0, got 0"),
    ("negative torus radius", '[[objects]]\nmesh = { primitive = "torus", minor_radius = -0.2 }\n',
     "objects[0].mesh.minor_radius: must be > 0, got -0.2"),
    ("too many subdivisions", '[[objects]]\nmesh = { primitive = "icosphere", subdivisions = 9 }\n',
     "objects[0].mesh.subdivisions: must be <= 6, got 9"),
    ("plane with no cells", '[[objects]]\nmesh = { primitive = "plane", segments = 0 }\n',
     "objects[0].mesh.segments: must be >= 1, got 0"),
    ("argument of another primitive", '[[objects]]\nmesh = { primitive = "cube", radius = 1 }\n',
     "objects[0].mesh.radius: unknown key; known keys here: primitive, size"),
    ("misspelt argument", '[[objects]]\nmesh = { primitive = "uv_sphere", radious = 1 }\n',
     "objects[0].mesh.radious: unknown key; did you mean 'radius'?"),
    ("primitive and file", '[[objects]]\nmesh = { primitive = "cube", file = "a.obj" }\n',
     "objects[0].mesh: give either primitive or file, not both"),
    ("mesh with neither", "[[objects]]\nmesh = {}\n", "objects[0].mesh: needs a primitive or a file key"),
    # the crease angle of a mesh file
    ("zero crease angle", '[[objects]]\nmesh = { file = "meshes/tetrahedron.stl", crease_angle = 0 }\n',
     "objects[0].mesh.crease_angle: must be between 0 (excluded) and 180 degrees (180: smooth "
     "across every edge), got 0"),
    ("negative crease angle", '[[objects]]\nmesh = { file = "meshes/tetrahedron.stl", crease_angle = -30 }\n',
     "objects[0].mesh.crease_angle: must be between 0 (excluded) and 180 degrees (180: smooth "
     "across every edge), got -30"),
    ("crease angle above 180", '[[objects]]\nmesh = { file = "meshes/tetrahedron.stl", crease_angle = 180.5 }\n',
     "objects[0].mesh.crease_angle: must be between 0 (excluded) and 180 degrees (180: smooth "
     "across every edge), got 180.5"),
    ("crease angle as a string", '[[objects]]\nmesh = { file = "meshes/tetrahedron.stl", crease_angle = "30" }\n',
     "objects[0].mesh.crease_angle: expected a number, got a string ('30')"),
    ("nan crease angle", '[[objects]]\nmesh = { file = "meshes/tetrahedron.stl", crease_angle = nan }\n',
     "objects[0].mesh.crease_angle: expected a finite number, got nan"),
    ("misspelt crease angle", '[[objects]]\nmesh = { file = "meshes/tetrahedron.stl", crease = 30 }\n',
     "objects[0].mesh.crease: unknown key; did you mean 'crease_angle'?"),
    ("crease angle of a primitive", '[[objects]]\nmesh = { primitive = "cube", crease_angle = 30 }\n',
     "objects[0].mesh.crease_angle: is for mesh files (mesh = { file = ... }); a primitive has "
     "exact normals, its flat faces already separate"),
    ("no mesh", '[[objects]]\nname = "ghost"\n',
     'objects[0].mesh: missing; give mesh = {primitive = "..."}, mesh = {file = "..."} or '
     'shape = {type = "sphere"}'),
    # materials
    ("negative kd", "[materials.red]\nkd = [0.5, -0.2, 0.0]\n",
     "materials.red.kd: must be >= 0 in every component, item 1 is -0.2"),
    ("negative inline ka", OBJECT + "material = { ka = -0.1 }\n",
     "objects[0].material.ka: must be >= 0 in every component, item 0 is -0.1"),
    ("negative ks", "[materials.m]\nks = [-1, 0, 0]\n",
     "materials.m.ks: must be >= 0 in every component, item 0 is -1"),
    ("negative exponent", "[materials.m]\nn = -1\n", "materials.m.n: must be >= 0, got -1"),
    ("unknown shading", '[materials.red]\nshading = "smooth"\n',
     "materials.red.shading: unknown shading 'smooth'; expected one of: flat, gouraud, phong"),
    ("unknown inline shading", OBJECT + 'material = { shading = "phongg" }\n',
     "objects[0].material.shading: unknown shading 'phongg'; did you mean 'phong'? expected one "
     "of: flat, gouraud, phong"),
    ("unknown material name", "[materials.green]\n" + OBJECT + 'material = "gren"\n',
     "objects[0].material: no material named 'gren'; did you mean 'green'? [materials] defines: green"),
    ("material name without materials", OBJECT + 'material = "red"\n',
     "objects[0].material: no material named 'red': the file defines no [materials.NAME] tables"),
    ("negative background", "background = [0, 0, -1]\n",
     "background: must be >= 0 in every component, item 2 is -1"),
    # lights
    ("unknown light type", '[[lights]]\ntype = "directional"\n[[lights]]\ntype = "spot"\n',
     "lights[1].type: unknown light type 'spot'; did you mean 'point'? expected one of: "
     "directional, point"),
    ("light without type", "[[lights]]\nintensity = 1\n",
     "lights[0].type: missing; expected one of: directional, point"),
    ("zero light direction", '[[lights]]\ntype = "directional"\ndirection = [0, 0, 0]\n',
     "lights[0].direction: must not be zero length"),
    ("negative attenuation", '[[lights]]\ntype = "point"\nattenuation = [1, -0.1, 0]\n',
     "lights[0].attenuation: must be >= 0 in every component, item 1 is -0.1"),
    ("zero attenuation", '[[lights]]\ntype = "point"\nattenuation = [0, 0, 0]\n',
     "lights[0].attenuation: must not be all zero: the light is divided by c + l d + q d^2"),
    ("negative intensity", '[[lights]]\ntype = "point"\nintensity = [1, 1, -1]\n',
     "lights[0].intensity: must be >= 0 in every component, item 2 is -1"),
    # area lights
    ("unknown area shape", POINT + 'area = "square"\nsize = [1, 1]\n',
     "lights[0].area: unknown area shape 'square'; expected one of: rectangle, disc, sphere"),
    ("area as a number", POINT + "area = 1\n", "lights[0].area: expected a string, got an integer (1)"),
    ("rectangle without size", POINT + 'area = "rectangle"\n',
     "lights[0].size: missing; a rectangle light needs size = [w, h]"),
    ("disc without radius", POINT + 'area = "disc"\n',
     "lights[0].radius: missing; a disc light needs radius = r"),
    ("negative size", POINT + 'area = "rectangle"\nsize = [1, -0.5]\n',
     "lights[0].size: must be >= 0 in every component, item 1 is -0.5"),
    ("infinite size", POINT + 'area = "rectangle"\nsize = [inf, 1]\n',
     "lights[0].size: expected finite numbers, item 0 is inf"),
    ("size of three", POINT + 'area = "rectangle"\nsize = [1, 1, 1]\n',
     "lights[0].size: expected a list of 2 numbers, got a list of 3 items"),
    ("negative radius", POINT + 'area = "sphere"\nradius = -1\n', "lights[0].radius: must be >= 0, got -1"),
    ("nan radius", POINT + 'area = "disc"\nradius = nan\n', "lights[0].radius: expected a finite number, got nan"),
    ("size given for a disc", POINT + 'area = "disc"\nradius = 1\nsize = [1, 1]\n',
     "lights[0].size: is for rectangle lights, not a disc; a disc light takes radius and normal"),
    ("radius given for a rectangle", POINT + 'area = "rectangle"\nsize = [1, 1]\nradius = 1\n',
     "lights[0].radius: is for disc and sphere lights, not a rectangle; a rectangle light takes "
     "size and normal"),
    ("normal given for a sphere", POINT + 'area = "sphere"\nradius = 1\nnormal = [0, 1, 0]\n',
     "lights[0].normal: is for rectangle and disc lights, not a sphere; a sphere light takes radius"),
    ("zero area normal", POINT + 'area = "disc"\nradius = 1\nnormal = [0, 0, 0]\n',
     "lights[0].normal: must not be zero length: it says which way the disc faces"),
    ("size without area", POINT + "size = [1, 1]\n",
     "lights[0].size: is for area lights; add area = one of 'rectangle', 'disc', 'sphere'"),
    ("area on a directional light", '[[lights]]\ntype = "directional"\narea = "disc"\n',
     "lights[0].area: belongs to point lights, not directional ones; keys here: type, direction, "
     "intensity, shadows, shadow_resolution, shadow_filter, shadow_bias"),
    # shadows
    ("shadows as a string", LIGHT + 'shadows = "off"\n',
     "lights[0].shadows: expected true or false, got a string ('off')"),
    ("resolution not a power of two", LIGHT + "shadow_resolution = 1000\n",
     "lights[0].shadow_resolution: expected one of 64, 128, 256, 512, 1024, 2048, 4096 (texels on a side "
     "of the map) or \"auto\", got an integer (1000)"),
    ("resolution too large", '[[lights]]\ntype = "point"\nshadow_resolution = 8192\n',
     "lights[0].shadow_resolution: expected one of 64, 128, 256, 512, 1024, 2048, 4096 (texels on a side "
     "of the map) or \"auto\", got an integer (8192)"),
    ("resolution as a float", LIGHT + "shadow_resolution = 1024.0\n",
     "lights[0].shadow_resolution: expected one of 64, 128, 256, 512, 1024, 2048, 4096 (texels on a side "
     "of the map) or \"auto\", got a number (1024)"),
    ("resolution as another string", LIGHT + 'shadow_resolution = "high"\n',
     "lights[0].shadow_resolution: expected one of 64, 128, 256, 512, 1024, 2048, 4096 (texels on a side "
     "of the map) or \"auto\", got a string ('high')"),
    ("unknown shadow filter", LIGHT + 'shadow_filter = "pcf4x4"\n',
     "lights[0].shadow_filter: unknown shadow filter 'pcf4x4'; did you mean 'pcf5x5'? expected "
     "one of: hard, pcf2x2, pcf3x3, pcf5x5"),
    ("shadow filter as a number", LIGHT + "shadow_filter = 3\n",
     "lights[0].shadow_filter: expected a string, got an integer (3)"),
    ("shadow bias as a number", LIGHT + "shadow_bias = 0.5\n",
     "lights[0].shadow_bias: expected a table such as {normal = 1.0, constant = 0.25} (texels), "
     "got a number (0.5)"),
    ("unknown shadow bias term", LIGHT + "shadow_bias = { slope_scale = 1 }\n",
     "lights[0].shadow_bias.slope_scale: unknown key; did you mean 'slope'?"),
    ("negative shadow bias", LIGHT + "shadow_bias = { normal = -0.5 }\n",
     "lights[0].shadow_bias.normal: must be >= 0, got -0.5"),
    ("shadow bias too large", '[[lights]]\ntype = "point"\nshadow_bias = { constant = 8.5 }\n',
     "lights[0].shadow_bias.constant: must be <= 8 texels, got 8.5"),
    ("nan shadow bias", LIGHT + "shadow_bias = { slope = nan }\n",
     "lights[0].shadow_bias.slope: expected a finite number, got nan"),
    ("shadow bias term as a string", LIGHT + 'shadow_bias = { constant = "auto" }\n',
     "lights[0].shadow_bias.constant: expected a number, got a string ('auto')"),
    ("casts_shadows as a number", OBJECT + "casts_shadows = 0\n",
     "objects[0].casts_shadows: expected true or false, got an integer (0)"),
    ("receives_shadows as a string", OBJECT + 'receives_shadows = "no"\n',
     "objects[0].receives_shadows: expected true or false, got a string ('no')"),
    ("misspelt casts_shadows", OBJECT + "cast_shadows = false\n",
     "objects[0].cast_shadows: unknown key; did you mean 'casts_shadows'?"),
    # motion blur (the ray tracer's)
    ("negative shutter interval", "[camera]\nshutter = [1.0, 0.5]\n",
     "camera.shutter: negative shutter interval: close 0.5 is before open 1; the shutter is "
     "[open, close] with open <= close"),
    ("shutter as a number", "[camera]\nshutter = 1.0\n",
     "camera.shutter: expected a list of 2 numbers [open, close], got a number (1)"),
    ("shutter of three", "[camera]\nshutter = [0, 1, 2]\n",
     "camera.shutter: expected a list of 2 numbers [open, close], got a list of 3 items"),
    ("nan shutter", "[camera]\nshutter = [0, nan]\n",
     "camera.shutter[1]: expected a finite number, got nan"),
    ("infinite shutter", "[camera]\nshutter = [-inf, 0]\n",
     "camera.shutter[0]: expected a finite number, got -inf"),
    ("velocity with a string", OBJECT + 'velocity = [1, "fast", 0]\n',
     "objects[0].velocity: expected a list of 3 numbers, item 1 is a string ('fast')"),
    ("infinite velocity", OBJECT + "velocity = [inf, 0, 0]\n",
     "objects[0].velocity: expected finite numbers, item 0 is inf"),
    ("nan angular velocity", OBJECT + "angular_velocity = [0, nan, 0]\n",
     "objects[0].angular_velocity: expected finite numbers, item 1 is nan"),
    ("misspelt angular velocity", OBJECT + "angular_speed = [0, 1, 0]\n",
     "objects[0].angular_speed: unknown key; did you mean 'angular_velocity'?"),
    ("shadow key on a material", OBJECT + "material = { receives_shadows = false }\n",
     "objects[0].material.receives_shadows: unknown key; known keys here: ka, kd, ks, n, "
     "two_sided, shading, kr, kt, ior, gloss, texture, emission, fresnel"),
    # textures (docs/scene-format.md, "Textures")
    ("texture without a source", OBJECT + "material = { texture = { wrap = \"clamp\" } }\n",
     'objects[0].material.texture: needs image = "FILE" or checker = { ... }'),
    ("unknown wrap", OBJECT + 'material = { texture = { checker = {}, wrap = "repet" } }\n',
     "objects[0].material.texture.wrap: unknown wrap mode 'repet'; did you mean 'repeat'? "
     "expected one of: repeat, clamp, mirror"),
    ("unknown filter", OBJECT + 'material = { texture = { checker = {}, filter = "linear" } }\n',
     "objects[0].material.texture.filter: unknown filter 'linear'; did you mean 'bilinear'? "
     "expected one of: nearest, bilinear, mip-nearest, trilinear, anisotropic"),
    ("unknown colorspace", OBJECT + 'material = { texture = { image = "textures/globe.png", '
                                    'colorspace = "rgb" } }\n',
     "objects[0].material.texture.colorspace: unknown colorspace 'rgb'; did you mean 'srgb'? "
     "expected one of: srgb, linear"),
    ("unknown modulate", OBJECT + 'material = { texture = { checker = {}, modulate = ["kt"] } }\n',
     "objects[0].material.texture.modulate[0]: unknown coefficient 'kt'; expected one of: ka, kd, "
     "ks"),
    ("anisotropy 17", OBJECT + 'material = { texture = { checker = {}, filter = "anisotropic", '
                               'anisotropy = 17 } }\n',
     "objects[0].material.texture.anisotropy: must be <= 16, got 17"),
    ("anisotropy 1", OBJECT + 'material = { texture = { checker = {}, filter = "anisotropic", '
                              'anisotropy = 1 } }\n',
     "objects[0].material.texture.anisotropy: must be >= 2, got 1"),
    ("anisotropy without its filter", OBJECT + "material = { texture = { checker = {}, "
                                               "anisotropy = 4 } }\n",
     "objects[0].material.texture.anisotropy: needs filter = \"anisotropic\" (the filter here "
     "is 'trilinear')"),
    ("checker colour over 1", OBJECT + "material = { texture = { checker = { colors = [1, 2] } } }\n",
     "objects[0].material.texture.checker.colors[1]: must be <= 1 in every component (a texel "
     "holds 0..1), got [2.0, 2.0, 2.0]"),
    ("named texture", "[materials.m]\ntexture = { checker = { squares = 0 } }\n" + OBJECT,
     "materials.m.texture.checker.squares: must be >= 1, got 0"),
]


@pytest.mark.parametrize("text, expected", [case[1:] for case in BAD_SCENES],
                         ids=[case[0] for case in BAD_SCENES])
def test_bad_scene_message(tmp_path, text, expected):
    path, line = load_error(tmp_path, text)
    assert line == f"{path}: {expected}"


def test_key_paths_count_objects_from_zero(tmp_path):
    text = (OBJECT.replace("ball", "a") + OBJECT.replace("ball", "b") + OBJECT.replace("ball", "c")
            + 'material = { kd = [1, 1, "x"] }\n')
    path, line = load_error(tmp_path, text)
    assert line == f"{path}: objects[2].material.kd: expected a number or a list of 3 numbers, " \
                   f"item 2 is a string ('x')"


@pytest.mark.parametrize("text, where", [
    ("[camera]\neye = [0, 0, 5\n", r"at (end of file|line 3, column \d+)"),
    ("name = \n", r"at line 1, column \d+"),
    ("[camera]\nfov_y = 45 45\n", r"at line 2, column \d+"),
    ("[camera]\nnear = 1\nnear = 2\n", r"at line 3, column \d+"),
])
def test_toml_syntax_error_names_the_line(tmp_path, text, where):
    path, line = load_error(tmp_path, text)
    assert re.match(re.escape(f"{path}: TOML syntax error ") + where + ": ", line), line


def test_scene_file_not_found(tmp_path):
    missing = tmp_path / "missing.toml"
    with pytest.raises(SceneError) as info:
        load_scene(missing)
    assert info.value.line() == f"{missing}: scene file not found"


def test_scene_file_not_utf8(tmp_path):
    path = tmp_path / "latin1.toml"
    path.write_bytes('name = "café"\n'.encode("latin-1"))
    with pytest.raises(SceneError) as info:
        load_scene(path)
    assert info.value.line().startswith(f"{path}: not UTF-8 text")


def test_missing_mesh_file(tmp_path):
    text = '[[objects]]\nmesh = { file = "meshes/missing.obj" }\n'
    path, line = load_error(tmp_path, text)
    assert line.startswith(f"{path}: objects[0].mesh.file: mesh file not found: "
                           f"'meshes/missing.obj' (looked in {(tmp_path / 'meshes').resolve()}")


@pytest.mark.parametrize("mesh_text, reason", [
    ("", "mesh has no triangles"),
    ("v 0 0 0\nv 1 0 0\nv 0 1 0\n", "mesh has no triangles"),
    (OBJ_TRIANGLE.replace("v 1 0 0", "v 1 nan 0"),
     "vertex 1 is not finite (1, nan, 0); 1 of 3 vertices are NaN or Inf"),
    (OBJ_TRIANGLE.replace("v 1 0 0", "v inf 0 0"),
     "vertex 1 is not finite (inf, 0, 0); 1 of 3 vertices are NaN or Inf"),
    (OBJ_TRIANGLE.replace("f 1 2 3", "f 1 2 9"),
     "line 4: face index 9 out of range (the file has 3 vertices; OBJ indices run from 1 to 3, "
     "or -1 to -3 counting back)"),
])
def test_bad_mesh_file_names_scene_key_and_mesh(tmp_path, mesh_text, reason):
    mesh = write(tmp_path, "bad.obj", mesh_text)
    text = OBJECT + '[[objects]]\nname = "thing"\nmesh = { file = "bad.obj" }\n'
    path, line = load_error(tmp_path, text)
    assert line == f"{path}: objects[1].mesh.file: {mesh}: {reason}"


def test_bad_ply_face_index_through_a_scene(tmp_path):
    mesh = write(tmp_path, "bad.ply", "ply\nformat ascii 1.0\nelement vertex 3\nproperty float x\n"
                 "property float y\nproperty float z\nelement face 1\n"
                 "property list uchar int vertex_indices\nend_header\n0 0 0\n1 0 0\n0 1 0\n"
                 "3 0 1 3\n")
    path, line = load_error(tmp_path, '[[objects]]\nmesh = { file = "bad.ply" }\n')
    assert line == (f"{path}: objects[0].mesh.file: {mesh}: face 0 has vertex index 3 out of "
                    f"range (the mesh has 3 vertices, indices 0 to 2)")


# --------------------------------------------------------------------------- the command line

CLI_CASES = [
    ("syntax", "[camera\n", "TOML syntax error at line 1"),
    ("unknown key", "[camera]\nfovy = 40\n", "camera.fovy: unknown key; did you mean 'fov_y'?"),
    ("nan", "[camera]\neye = [0, nan, 5]\n", "camera.eye: expected finite numbers, item 1 is nan"),
    ("eye is look", "[camera]\neye = [0, 0, 0]\n", "camera.look: is the same point as camera.eye"),
    ("missing mesh", '[[objects]]\nmesh = { file = "nope.obj" }\n',
     "objects[0].mesh.file: mesh file not found: 'nope.obj'"),
    ("nan vertex", '[[objects]]\nmesh = { file = "nan.obj" }\n',
     "objects[0].mesh.file: NANMESH: vertex 0 is not finite (nan, 0, 0)"),
    ("parent cycle", '[[objects]]\nname = "a"\nparent = "a"\nmesh = { primitive = "cube" }\n',
     "objects[0].parent: parent cycle: a -> a"),
]


RENDER_SMALL = ("--backend", "reference", "--size", "32x24")      # `renderer render` options


# The first case in a process of its own is the full run's (--all): in the default run a
# refusal in a real process is held by tests/test_refusals.py (a corrupt mesh file), and a
# TOML syntax error's line by test_toml_syntax_error_names_the_line above.
@pytest.mark.parametrize("text, expected", [
    pytest.param(*case[1:], id=case[0], marks=[pytest.mark.slow] if index == 0 else [])
    for index, case in enumerate(CLI_CASES)])
def test_cli_bad_scene_exits_2_with_one_line(tmp_path, text, expected, request):
    """The first case as a user types it, in a process of its own; the others through
    renderer.cli.main in this process (cli_here: the same code, a second less each)."""
    nan_mesh = write(tmp_path, "nan.obj", OBJ_TRIANGLE.replace("v 0 0 0", "v nan 0 0"))
    bad_scene = write(tmp_path, "bad.toml", text)
    out_png = tmp_path / "out.png"
    cli = request.getfixturevalue("cli" if text == CLI_CASES[0][1] else "cli_here")
    result = cli("render", bad_scene, "-o", out_png, *RENDER_SMALL, cwd=REPO)
    assert result.returncode == 2, result.stderr
    assert "Traceback" not in result.stderr
    lines = result.stderr.strip().splitlines()
    assert len(lines) == 1, result.stderr
    assert str(bad_scene) in lines[0]
    assert expected.replace("NANMESH", str(nan_mesh)) in lines[0]
    assert not out_png.exists()


@pytest.mark.parametrize("image, reason", [
    (None, "image file not found: 'art.png'"),
    (b"", "ART: image is empty (0 bytes)"),
    (b"\x89PNG\r\n\x1a\n not really", "ART: could not be read as an image"),
])
def test_cli_bad_image_exits_2_with_one_line(tmp_path, cli_here, image, reason):
    """Missing, zero-size and corrupt images: one line naming the scene file, the key and
    the image, status 2, nothing written."""
    if image is not None:
        (tmp_path / "art.png").write_bytes(image)
    scene = write(tmp_path, "s.toml", OBJECT + 'material = { texture = { image = "art.png" } }\n')
    result = cli_here("render", scene, "-o", tmp_path / "out.png", *RENDER_SMALL)
    assert result.returncode == 2 and "Traceback" not in result.stderr
    assert result.stderr.splitlines() == [result.stderr.strip()]
    expected = reason.replace("ART", str(tmp_path / "art.png"))
    assert result.stderr.startswith(f"renderer: {scene}: objects[0].material.texture.image: "
                                    f"{expected}"), result.stderr
    assert not (tmp_path / "out.png").exists()


def test_a_textured_material_on_a_mesh_without_uvs_is_refused(tmp_path, cli_here):
    mesh = write(tmp_path, "tri.obj", OBJ_TRIANGLE)
    scene = write(tmp_path, "s.toml", "[materials.checked]\ntexture = { checker = {} }\n"
                  '[[objects]]\nmesh = { file = "tri.obj" }\nmaterial = "checked"\n')
    result = cli_here("render", scene, "-o", tmp_path / "out.png", *RENDER_SMALL)
    assert result.returncode == 2 and not (tmp_path / "out.png").exists()
    assert result.stderr == (f"renderer: {scene}: objects[0].material: has a texture, but the "
                             f"mesh ({mesh}) has no texture coordinates; give the file UVs (OBJ "
                             f"vt, PLY u v, glTF TEXCOORD_0) or use a primitive or a shape\n")


def test_texture_tables_make_shared_textures(tmp_path):
    """An image path is relative to the scene file; each image and checker is one Texture
    however many materials use it; a glTF's base-colour texture is the object's where its
    material sets none; the defaults are the design's."""
    (tmp_path / "art").mkdir()
    (tmp_path / "art" / "a.png").write_bytes((REPO / "assets" / "textures" / "crate.png").read_bytes())
    scene = load_scene(write(tmp_path, "s.toml", """
[materials.one]
texture = { image = "art/a.png" }
[materials.two]
kd = 0.5
[materials.two.texture]
image = "art/a.png"
wrap = "mirror"
filter = "anisotropic"
uv_scale = [2, 3]
uv_offset = [0.5, 0]
modulate = ["ka", "kd", "ks"]
[[objects]]
mesh = { primitive = "cube" }
material = "one"
[[objects]]
shape = { type = "sphere" }
material = "two"
[[objects]]
mesh = { primitive = "plane" }
material = { texture = { checker = {} } }
[[objects]]
mesh = { file = "meshes/textured_box.glb" }
[[objects]]
mesh = { file = "meshes/textured_box.glb" }
material = "one"
"""))
    one, two, checker, box, box_one = (obj.material.texture for obj in scene.objects)
    assert one.texture is two.texture and one.texture.source == str(tmp_path / "art" / "a.png")
    assert (one.sampler.wrap, one.sampler.filter, one.uv_scale, one.uv_offset, one.modulate) == \
        ("repeat", "trilinear", (1.0, 1.0), (0.0, 0.0), ("kd",))
    assert (two.sampler.wrap, two.sampler.filter, two.sampler.anisotropy) == ("mirror", "anisotropic", 16)
    assert (two.uv_scale, two.uv_offset, two.modulate) == ((2.0, 3.0), (0.5, 0.0), ("ka", "kd", "ks"))
    assert checker.texture.source == "checker 8x8 at 256" and checker.texture.colorspace == "linear"
    assert box.texture.source.endswith("textured_box.glb (base colour)")
    assert box_one is one and scene.objects[1].material.kd == (0.5, 0.5, 0.5)


# The full run's (--all), about 1.2 s: the default run holds the same refusal through
# renderer.cli.main (test_load_scene_unknown_name_is_the_command_lines_line: exactly that one
# line, status 2, the built-in names listed) and a refusal in a process of its own
# (tests/test_refusals.py, a corrupt mesh file: one line, status 2, no traceback).
@pytest.mark.slow
def test_cli_unknown_scene_name_exits_2_and_lists_builtins(tmp_path, cli):
    out_png = tmp_path / "out.png"
    result = cli("render", "no_such_scene", "-o", out_png, *RENDER_SMALL, cwd=REPO)
    assert result.returncode == 2, result.stderr
    assert "Traceback" not in result.stderr
    lines = result.stderr.strip().splitlines()
    assert len(lines) == 1, result.stderr
    assert "no_such_scene" in lines[0] and "sphere" in lines[0] and "hierarchy" in lines[0]
    assert not out_png.exists()


def test_cli_nan_is_not_rendered_even_when_unused(tmp_path, cli_here):
    """A NaN in a light's intensity must stop the render, not produce a black picture."""
    bad_scene = write(tmp_path, "bad.toml", '[[lights]]\ntype = "point"\nintensity = [1, nan, 1]\n'
                      + OBJECT)
    out_png = tmp_path / "out.png"
    result = cli_here("render", bad_scene, "-o", out_png, *RENDER_SMALL, cwd=REPO)
    assert result.returncode == 2 and "Traceback" not in result.stderr
    assert "lights[0].intensity: expected finite numbers, item 1 is nan" in result.stderr
    assert not out_png.exists()



# The full run's (--all): in the default run test_bad_scene_message holds each case's line
# and test_cli_bad_scene_exits_2_with_one_line how the command line turns a SceneError into
# it (one line, status 2, nothing written), the same code for every case.
@pytest.mark.slow
@pytest.mark.parametrize("text, expected", [case[1:] for case in BAD_SCENES],
                         ids=[case[0] for case in BAD_SCENES])
def test_every_bad_scene_through_the_command_line(tmp_path, capsys, text, expected):
    """Every case above, through `renderer render` in-process (the subprocess tests above
    show that `python -m renderer` exits with what main() returns)."""
    from renderer.cli import main
    bad_scene = write(tmp_path, "bad.toml", text)
    out_png = tmp_path / "out.png"
    status = main(["render", str(bad_scene), "-o", str(out_png), "--backend", "reference",
                   "--size", "32x24"])
    stderr = capsys.readouterr().err
    assert status == 2
    assert stderr.splitlines() == [f"renderer: {bad_scene}: {expected}"]
    assert list(tmp_path.iterdir()) == [bad_scene]           # nothing written, not even a temporary
