"""Analytic shapes (sphere, plane) and the ray tracer's material terms (kr, kt, ior) in the
scene model and scene files: parsing, refusals, world-space parameters, tessellation meshes.
Every expected value is worked out by hand in the comments."""

import math

import numpy as np
import pytest

from renderer.core import memory, shapes
from renderer.core.builtin import builtin_scenes, scene_descriptions
from renderer.core.scene import (Material, Plane, Scene, SceneObject, Sphere, Transform,
                                 WorldPlane, WorldSphere, world_shape)
from renderer.core.scene_file import load_scene, scene_from_dict
from renderer.errors import SceneError

from conftest import RAYTRACE_SCENES, SHADOW_CASE_SCENES, SHADOW_SCENES, TESSELLATION_SCENES


def one_object(**obj) -> dict:
    return {"objects": [obj]}


def load(data: dict) -> Scene:
    return scene_from_dict(data, source="s.toml")


def refusal(data: dict) -> str:
    with pytest.raises(SceneError) as info:
        load(data)
    return info.value.line()


# --------------------------------------------------------------------------- parsing

def test_sphere_keys_and_defaults():
    scene = load(one_object(shape={"type": "sphere"}))
    obj = scene.objects[0]
    assert obj.shape == Sphere((0.0, 0.0, 0.0), 1.0)
    assert obj.mesh.triangle_count == 20 * 4 ** shapes.SPHERE_SUBDIVISIONS == 1280
    scene = load(one_object(shape={"type": "sphere", "centre": [1, 2, 3], "radius": 0.5,
                                   "subdivisions": 1}))
    obj = scene.objects[0]
    assert obj.shape == Sphere((1.0, 2.0, 3.0), 0.5)
    assert obj.mesh.triangle_count == 80


def test_plane_keys_and_defaults():
    obj = load(one_object(shape={"type": "plane"})).objects[0]
    assert obj.shape == Plane((0.0, 1.0, 0.0), 0.0)
    assert obj.mesh.triangle_count == 2
    assert np.ptp(obj.mesh.positions, axis=0).tolist() == [1000.0, 0.0, 1000.0]
    obj = load(one_object(shape={"type": "plane", "normal": [0, 0, 2], "offset": -4,
                                 "size": 10, "segments": 3})).objects[0]
    assert obj.shape == Plane((0.0, 0.0, 2.0), -4.0)
    assert obj.mesh.triangle_count == 18
    # 2z - 4 = 0: the square lies in z = 2, centred on (0, 0, 2), 10 on a side
    assert np.allclose(obj.mesh.positions[:, 2], 2.0)
    assert obj.mesh.positions[:, :2].min() == -5.0 and obj.mesh.positions[:, :2].max() == 5.0


def test_material_ray_tracer_keys():
    mat = load(one_object(shape={"type": "sphere"},
                          material={"kr": 0.25, "kt": [0.5, 0.75, 0.0], "ior": 1.33}))
    mat = mat.objects[0].material
    assert (mat.kr, mat.kt, mat.ior) == ((0.25,) * 3, (0.5, 0.75, 0.0), 1.33)
    default = Material()
    assert (default.kr, default.kt, default.ior) == ((0.0,) * 3, (0.0,) * 3, 1.5)
    # exactly at the energy rule's limit, in decimal: 0.7 + 0.3
    load(one_object(mesh={"primitive": "cube"}, material={"kr": 0.7, "kt": 0.3}))


def test_gloss_is_a_lobe_exponent_from_0_to_inf_and_unset_is_the_mirror():
    """gloss 0 (the cosine lobe) and TOML's inf (the mirror) are both taken; an unset gloss
    is None, which the ray tracer reads as inf (Material.gloss_exponent)."""
    for gloss in (0, 10, 1e6, math.inf):
        mat = load(one_object(shape=SPHERE, material={"kr": 0.5, "gloss": gloss})).objects[0].material
        assert mat.gloss == gloss and mat.gloss_exponent == gloss
    assert Material().gloss is None and Material().gloss_exponent == math.inf


def test_only_the_ray_tracing_and_shadow_builtin_scenes_use_shapes_and_ray_tracer_terms():
    """conftest.RAYTRACE_SCENES is the set of built-in scenes made for the ray tracer: each uses
    an analytic shape or k_r, k_t, ior and says `--method raytrace` in its description. The
    shadow scenes (conftest.SHADOW_SCENES, made for the rasteriser) use shapes, for the ray
    tracer's exact shadows, but no k_r, k_t, ior; every other built-in scene uses none of them
    (the rasteriser's scenes stay as they were). The shadow case scenes
    (conftest.SHADOW_CASE_SCENES) use shapes where their case wants them (a floor plane), meshes
    where it does not (a 200-unit mesh floor, a low-poly sphere), and no ray-tracer terms; the
    tessellation scenes (conftest.TESSELLATION_SCENES) analytic spheres or meshes for the
    tessellation stages, and no ray-tracer terms."""
    descriptions = scene_descriptions()
    for name, path in builtin_scenes().items():
        scene = load_scene(path)
        terms = {(m.kr, m.kt, m.ior) for m in (obj.material for obj in scene.objects)}
        uses_shapes = any(obj.shape is not None for obj in scene.objects)
        uses_ray_terms = terms != {((0.0,) * 3, (0.0,) * 3, 1.5)}
        made_for_it = name in RAYTRACE_SCENES
        if name in SHADOW_CASE_SCENES:        # shapes where the case wants them, no ray terms
            assert not uses_ray_terms, name
            continue
        if name in TESSELLATION_SCENES:       # tessellated spheres or meshes, no ray terms
            assert not uses_ray_terms and any(o.tessellation for o in scene.objects), name
            continue
        assert (uses_shapes or uses_ray_terms) == (made_for_it or name in SHADOW_SCENES), name
        assert not (uses_ray_terms and name in SHADOW_SCENES), name
        assert ("--method raytrace" in descriptions[name]) == made_for_it, name
    assert RAYTRACE_SCENES | SHADOW_SCENES <= set(builtin_scenes())
    assert not RAYTRACE_SCENES & SHADOW_SCENES


# --------------------------------------------------------------------------- refusals

SPHERE = {"type": "sphere"}
BAD = [
    ("negative radius", one_object(shape={"type": "sphere", "radius": -1}),
     "objects[0].shape.radius: must be > 0, got -1"),
    ("zero radius", one_object(shape={"type": "sphere", "radius": 0}),
     "objects[0].shape.radius: must be > 0, got 0"),
    ("nan centre", one_object(shape={"type": "sphere", "centre": [0, math.nan, 0]}),
     "objects[0].shape.centre: expected finite numbers, item 1 is nan"),
    ("huge radius", one_object(shape={"type": "sphere", "radius": 1e19}),
     "objects[0].shape.radius: 1e+19 is too large for the GPU's float32 arithmetic"),
    ("subdivisions", one_object(shape={"type": "sphere", "subdivisions": 7}),
     "objects[0].shape.subdivisions: must be <= 6, got 7"),
    ("zero normal", one_object(shape={"type": "plane", "normal": [0, 0, 0]}),
     "objects[0].shape.normal: must not be zero length: the plane is P·N + d = 0"),
    ("inf offset", one_object(shape={"type": "plane", "offset": math.inf}),
     "objects[0].shape.offset: expected a finite number, got inf"),
    ("plane size", one_object(shape={"type": "plane", "size": 0}),
     "objects[0].shape.size: must be > 0, got 0"),
    ("plane too far", one_object(shape={"type": "plane", "offset": 1e18}),
     "objects[0].shape: the plane's square reaches"),
    ("no type", one_object(shape={"radius": 1}),
     "objects[0].shape.type: missing; expected one of: sphere, plane"),
    ("unknown type", one_object(shape={"type": "spher"}),
     "objects[0].shape.type: unknown shape type 'spher'; did you mean 'sphere'?"),
    ("plane key on sphere", one_object(shape={"type": "sphere", "normal": [0, 1, 0]}),
     "objects[0].shape.normal: unknown key"),
    ("mesh and shape", one_object(shape=SPHERE, mesh={"primitive": "cube"}),
     "objects[0].shape: give either mesh or shape, not both"),
    ("not a table", one_object(shape="sphere"),
     "objects[0].shape: expected a table such as {type = \"sphere\", radius = 1.0}"),
    ("non-uniform scale", one_object(shape=SPHERE, scale=[1, 2, 1]),
     "objects[0].shape: a sphere's transform (with its parents') must be a uniform scale"),
    ("shear", one_object(shape=SPHERE, shear={"xy": 0.5}),
     "objects[0].shape: a sphere's transform"),
    ("zero scale", one_object(shape=SPHERE, scale=0),
     "objects[0].shape: a sphere's transform"),
    ("flattened plane", one_object(shape={"type": "plane", "normal": [1, 0, 0]},
                                   scale=[1, 0, 1]),
     "objects[0].shape: the transform (with its parents') flattens the plane"),
    ("ior zero", one_object(shape=SPHERE, material={"ior": 0}),
     "objects[0].material.ior: must be > 0, got 0"),
    ("ior negative", one_object(shape=SPHERE, material={"ior": -1.5}),
     "objects[0].material.ior: must be > 0, got -1.5"),
    ("kr negative", one_object(shape=SPHERE, material={"kr": [0, -0.1, 0]}),
     "objects[0].material.kr: must be >= 0 in every component, item 1 is -0.1"),
    ("energy", one_object(shape=SPHERE, material={"kr": 0.5, "kt": [0.2, 0.6, 0.1]}),
     "objects[0].material.kt: kr + kt is 1.1 in channel g; the energy rule is kr + kt <= 1 "
     "in each channel"),
    ("energy kr only", {"materials": {"m": {"kr": 1.5}}, "objects": []},
     "materials.m.kr: kr + kt is 1.5 in channel r"),
    ("gloss negative", one_object(shape=SPHERE, material={"kr": 0.5, "gloss": -1}),
     "objects[0].material.gloss: must be a number >= 0 or inf (a mirror), got -1"),
    ("gloss -inf", one_object(shape=SPHERE, material={"gloss": -math.inf}),
     "objects[0].material.gloss: must be a number >= 0 or inf (a mirror), got -inf"),
    ("gloss nan", one_object(shape=SPHERE, material={"gloss": math.nan}),
     "objects[0].material.gloss: must be a number >= 0 or inf (a mirror), got nan"),
    ("gloss string", one_object(shape=SPHERE, material={"gloss": "inf"}),
     "objects[0].material.gloss: expected a number, got a string ('inf')"),
]


@pytest.mark.parametrize("data, expected", [case[1:] for case in BAD],
                         ids=[case[0] for case in BAD])
def test_refusal_is_one_line_naming_file_and_key(data, expected):
    line = refusal(data)
    assert "\n" not in line
    assert line.startswith("s.toml: " + expected), line


def test_a_parent_scale_breaks_a_child_sphere():
    data = {"objects": [{"name": "p", "mesh": {"primitive": "cube"}, "scale": [1, 1, 3]},
                        {"name": "c", "parent": "p", "shape": SPHERE}]}
    assert refusal(data).startswith("s.toml: objects[1].shape: a sphere's transform")


def test_shape_refusal_through_the_command_line(tmp_path, cli_here):
    bad = tmp_path / "bad.toml"
    bad.write_text('[[objects]]\nshape = { type = "sphere", radius = -2.0 }\n')
    out = tmp_path / "out.png"
    result = cli_here("render", bad, "-o", out, "--backend", "reference", "--size", "32x24")
    assert result.returncode == 2, result.stderr
    assert result.stderr.strip().splitlines() == [
        f"renderer: {bad}: objects[0].shape.radius: must be > 0, got -2"]
    assert not out.exists()


def test_shape_tessellation_counts_against_memory():
    # SCENE_BYTES_PER_TRIANGLE 256: 768,000 bytes (beside the process's own) hold 3000
    # triangles; 1280 + 1280 fit, a third sphere's 3840 does not; nor does one of 5120
    sphere = {"type": "sphere"}
    with memory.limit_set(memory.PROCESS_BYTES + 3000 * memory.SCENE_BYTES_PER_TRIANGLE):
        load({"objects": [{"shape": sphere}, {"shape": sphere}]})
        line = refusal({"objects": [{"shape": sphere}, {"shape": sphere}, {"shape": sphere}]})
        assert line.startswith("s.toml: objects[2].shape: the scene's primitives up to here "
                               "make up to 3,840 triangles")
        line = refusal(one_object(shape={"type": "sphere", "subdivisions": 4}))
        assert "5,120 triangles" in line
        line = refusal({"objects": [{"shape": sphere}, {"shape": sphere},
                                    {"mesh": {"primitive": "icosphere", "subdivisions": 3}}]})
        assert line.startswith("s.toml: objects[2].mesh: the scene's primitives up to here "
                               "make up to 3,840 triangles")


# --------------------------------------------------------------------------- world space

def test_sphere_world_parameters_translate_scale_rotate():
    # centre (1, 0, 0), r 0.5; scale 2: (2, 0, 0), r 1; rotate 90 about z: (0, 2, 0);
    # translate (0, 0, -3): (0, 2, -3); relative to the eye (0, 0, 5): (0, 2, -8)
    scene = load({"camera": {"eye": [0, 0, 5]},
                  "objects": [{"shape": {"type": "sphere", "centre": [1, 0, 0], "radius": 0.5},
                               "scale": 2, "rotate": [0, 0, 90], "translate": [0, 0, -3]}]})
    (world,) = scene.world_shapes()
    assert isinstance(world, WorldSphere)
    assert np.allclose(world.centre, [0, 2, -8], atol=1e-12)
    assert world.radius == pytest.approx(1.0, abs=1e-12)


def test_sphere_under_a_parent_chain():
    # parent: scale 3, translate (10, 0, 0); child: translate (1, 0, 0), unit sphere:
    # world centre 3·(1, 0, 0) + (10, 0, 0) = (13, 0, 0), radius 3
    scene = load({"camera": {"eye": [0, 0, 5]},
                  "objects": [{"name": "p", "mesh": {"primitive": "cube"}, "scale": 3,
                               "translate": [10, 0, 0]},
                              {"name": "c", "parent": "p", "shape": SPHERE,
                               "translate": [1, 0, 0], "rotate": [30, 40, 50]}]})
    world = scene.world_shapes()[1]
    assert np.allclose(world.centre, [13, 0, -5], atol=1e-12)
    assert world.radius == pytest.approx(3.0, rel=1e-12)


def test_plane_world_parameters_translate_scale_rotate():
    # y = 1 (N = (0, 1, 0), d = -1); scale y 2: y = 2; rotate 90 about x takes +y to +z:
    # z = 2; translate z 1: z = 3, i.e. N = (0, 0, 1), d = -3; relative to the eye (0, 0, 5):
    # z_rel + 5 - 3 = 0, d = 2
    scene = load({"camera": {"eye": [0, 0, 5]},
                  "objects": [{"shape": {"type": "plane", "normal": [0, 1, 0], "offset": -1},
                               "scale": [1, 2, 1], "rotate": [90, 0, 0],
                               "translate": [0, 0, 1]}]})
    (world,) = scene.world_shapes()
    assert isinstance(world, WorldPlane)
    assert np.allclose(world.normal, [0, 0, 1], atol=1e-12)
    assert world.offset == pytest.approx(2.0, abs=1e-12)


def test_plane_under_shear_holds_its_mapped_points():
    # Any invertible affine map: points of the object's plane land on the world plane.
    shape = Plane((1.0, 2.0, -1.0), 0.7)
    model = Transform(scale=(1, 2, 3), shear={"xy": 0.3, "zx": -0.2}, rotate=(10, 20, 30),
                      translate=(1, 2, 3)).matrix()
    origin = np.array([0.5, -4.0, 2.0])
    world = world_shape(shape, model, origin)
    n = np.array(shape.normal)
    points = np.random.default_rng(0).normal(size=(8, 3))
    points -= ((points @ n + shape.offset) / (n @ n))[:, None] * n       # onto the plane
    mapped = points @ model[:3, :3].T + model[:3, 3] - origin
    assert np.abs(mapped @ world.normal + world.offset).max() < 1e-12
    assert np.linalg.norm(world.normal) == pytest.approx(1.0)


def test_plane_flattened_along_its_normal_keeps_a_plane():
    # y = 1 under scale y 0 collapses onto y = 0: cof(diag(1, 0, 1)) (0, 1, 0) = (0, 1, 0), d 0
    world = world_shape(Plane((0, 1, 0), -1.0), Transform(scale=(1, 0, 1)).matrix())
    assert np.allclose(world.normal, [0, 1, 0]) and world.offset == 0.0


def test_world_shape_refusals_in_python():
    with pytest.raises(ValueError, match="uniform scale"):
        world_shape(Sphere(), Transform(scale=(1, 1, 1.01)).matrix())
    with pytest.raises(ValueError, match="flattens"):
        world_shape(Plane((1, 0, 0), 0.0), Transform(scale=(1, 1, 0)).matrix())


# --------------------------------------------------------------------------- tessellation

def test_sphere_mesh_lies_on_the_sphere_with_outward_normals():
    mesh = shapes.sphere_mesh(Sphere((1.0, -2.0, 3.0), 2.5), subdivisions=2)
    assert mesh.triangle_count == 320
    offsets = mesh.positions - [1.0, -2.0, 3.0]
    assert np.allclose(np.linalg.norm(offsets, axis=1), 2.5)
    assert np.allclose(mesh.normals, offsets / 2.5)
    p = mesh.positions[mesh.faces]                           # counter-clockwise from outside
    face_normals = np.cross(p[:, 1] - p[:, 0], p[:, 2] - p[:, 0])
    assert (np.einsum("ij,ij->i", face_normals, p.mean(axis=1) - [1.0, -2.0, 3.0]) > 0).all()


@pytest.mark.parametrize("normal", [(0, 1, 0), (0, 0, -3), (1, 2, 3), (0.01, 0, 1), (-1, 0, 0)])
def test_plane_mesh_is_a_square_on_the_plane_facing_its_normal(normal):
    shape = Plane(normal, 2.0)
    mesh = shapes.plane_mesh(shape, size=4.0, segments=2)
    n = np.asarray(normal, dtype=float)
    unit = n / np.linalg.norm(n)
    assert mesh.triangle_count == 8 and len(mesh.positions) == 9
    assert np.abs(mesh.positions @ n + 2.0).max() < 1e-12    # on P·N + d = 0
    assert np.allclose(mesh.normals, unit)
    centre = mesh.positions.mean(axis=0)                     # the foot of the origin
    assert np.allclose(centre, -2.0 * n / (n @ n))
    corners = mesh.positions - centre
    assert np.allclose(sorted(np.linalg.norm(corners, axis=1))[-1], 2 * math.sqrt(2))
    p = mesh.positions[mesh.faces]
    face_normals = np.cross(p[:, 1] - p[:, 0], p[:, 2] - p[:, 0])
    assert np.allclose(face_normals / np.linalg.norm(face_normals, axis=1)[:, None], unit)


def test_plane_mesh_along_y_is_the_plane_primitive():
    from renderer.core.primitives import plane
    mesh, primitive = shapes.plane_mesh(Plane(), 6.0, 3), plane(6.0, 3)
    assert np.array_equal(mesh.positions, primitive.positions)
    assert np.array_equal(mesh.faces, primitive.faces)


def test_shape_object_built_in_python_and_from_a_file_agree():
    data = one_object(name="ball", shape={"type": "sphere", "centre": [0, 1, 0], "radius": 2,
                                          "subdivisions": 1})
    from_file = load(data).objects[0]
    by_hand = SceneObject("ball", shapes.sphere_mesh(Sphere((0, 1, 0), 2.0), 1),
                          shape=Sphere((0.0, 1.0, 0.0), 2.0))
    assert from_file.shape == by_hand.shape
    assert np.array_equal(from_file.mesh.positions, by_hand.mesh.positions)
    assert np.array_equal(from_file.mesh.faces, by_hand.mesh.faces)
