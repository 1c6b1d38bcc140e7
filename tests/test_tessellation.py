"""Re-tessellation of curved primitives (renderer/study/tessellation.py) from Mesh.recipe."""

from renderer.core.builtin import builtin_scenes
from renderer.core.primitives import icosphere
from renderer.core.scene import Scene, SceneObject
from renderer.core.scene_file import MAX_SEGMENTS, load_scene, scene_from_dict
from renderer.study.tessellation import FINEST, LEVELS, retessellate, scene_at_level


def mesh_of(primitive: dict):
    scene = scene_from_dict({"objects": [{"name": "a", "mesh": primitive}]})
    return scene.objects[0].mesh


def test_a_scene_file_primitive_records_its_recipe_and_a_mesh_file_none():
    assert mesh_of({"primitive": "torus", "major_segments": 12}).recipe == ("torus", {"major_segments": 12})
    scene = load_scene(builtin_scenes()["mesh_file"])
    assert any(obj.mesh.recipe is None for obj in scene.objects)


def test_segment_counts_scale_with_the_level():
    sphere = mesh_of({"primitive": "uv_sphere", "segments": 16, "rings": 8})
    assert retessellate(sphere, 2.0).recipe == ("uv_sphere", {"segments": 32, "rings": 16})
    assert retessellate(sphere, 0.25).recipe == ("uv_sphere", {"segments": 4, "rings": 2})
    # Defaults count too: a cylinder without `segments` has 32.
    assert retessellate(mesh_of({"primitive": "cylinder"}), 0.5).recipe == ("cylinder", {"segments": 16})


def test_an_icosphere_gains_a_subdivision_per_doubling():
    ico = mesh_of({"primitive": "icosphere", "subdivisions": 1})
    assert retessellate(ico, 4.0).recipe == ("icosphere", {"subdivisions": 3})
    assert retessellate(ico, 4.0).triangle_count == icosphere(subdivisions=3).triangle_count
    assert retessellate(ico, 0.25).recipe == ("icosphere", {"subdivisions": 0})     # clamped at 0


def test_counts_are_clamped_to_the_scene_formats_limits():
    cylinder = mesh_of({"primitive": "cylinder", "segments": 600})
    assert retessellate(cylinder, 4.0).recipe[1]["segments"] == MAX_SEGMENTS
    assert retessellate(mesh_of({"primitive": "cylinder", "segments": 3}), 0.25).recipe[1]["segments"] == 3


def test_flat_primitives_and_the_authored_level_are_left_alone():
    cube = mesh_of({"primitive": "cube"})
    assert retessellate(cube, 4.0) is cube
    sphere = mesh_of({"primitive": "uv_sphere"})
    assert retessellate(sphere, 1.0) is sphere


def test_scene_at_level_keeps_shared_meshes_shared():
    sphere = mesh_of({"primitive": "uv_sphere", "segments": 8, "rings": 4})
    scene = Scene(objects=[SceneObject("a", sphere), SceneObject("b", sphere),
                           SceneObject("c", mesh_of({"primitive": "cube"}))])
    finer = scene_at_level(scene, FINEST)
    assert finer.objects[0].mesh is finer.objects[1].mesh
    assert finer.objects[0].mesh.recipe == ("uv_sphere", {"segments": 32, "rings": 16})
    assert finer.objects[2].mesh is scene.objects[2].mesh
    assert scene.objects[0].mesh is sphere                       # the original is untouched
    assert LEVELS[-1] == FINEST and 1.0 in LEVELS
