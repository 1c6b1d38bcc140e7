"""What can shadow what (renderer/core/convexity.py, renderer/core/shadow_casting.py): a
hand-checked case per rule, then what the built-in scenes draw because of it, and the default
scene, which nothing can shadow, drawn exactly as with its shadows off."""

import re
from dataclasses import replace
from pathlib import Path

import numpy as np
import pytest

from renderer.core import primitives
from renderer.core.convexity import convex_body
from renderer.core.scene import (Camera, DirectionalLight, Material, Mesh, PointLight, Scene,
                                 SceneObject, Transform)
from renderer.core.scene_file import load_scene
from renderer.core.shadow_casting import Occluders, world_geometry
from renderer.core.shadow_settings import CONSTANT_BIAS_TEXELS, FILTERS, RESOLUTIONS, Shadow, auto_resolution
from renderer.core.shadows import LayerStack, plan_shadows, shadow_layout, shadow_lights
from renderer.gpu import GpuRenderer

REPO = Path(__file__).resolve().parents[1]
DOWN = (0.0, -1.0, 0.0)


# --- convex solids ---------------------------------------------------------------------------

@pytest.mark.parametrize("mesh", [primitives.cube(1.0), primitives.uv_sphere(1.0, 24, 12),
                                  primitives.icosphere(1.0, 2), primitives.cylinder(0.3, 1.0, 16)],
                         ids=["cube", "uv_sphere", "icosphere", "cylinder"])
def test_closed_convex_primitives_are_convex_solids_with_outward_normals(mesh):
    """Welded at their seams (a cube's 24 corners are 8 points; a uv sphere's poles one each),
    they are watertight and every vertex lies inside every face's plane."""
    body = convex_body(mesh)
    assert body is not None and body.normals_outward is True
    assert body.contains(np.zeros((1, 3)))[0] and not body.contains(np.array([[0.0, 5.0, 0.0]]))[0]


@pytest.mark.parametrize("mesh", [primitives.plane(2.0), primitives.torus(1.0, 0.3, 16, 8)],
                         ids=["open-plane", "torus"])
def test_open_or_concave_meshes_are_not(mesh):
    assert convex_body(mesh) is None


def test_a_cube_with_a_face_missing_is_open():
    cube = primitives.cube(1.0)
    open_box = Mesh(cube.positions, cube.normals, cube.faces[2:])
    assert convex_body(open_box) is None


def test_inward_winding_is_found_and_containment_goes_through_the_model():
    """A room: the cube wound inward with inward normals; its solid is still the box, and a
    model matrix (scale 2, moved by 10) moves it."""
    cube = primitives.cube(1.0)
    room = Mesh(cube.positions, -cube.normals, cube.faces[:, ::-1].copy())
    body = convex_body(room)
    assert body is not None and body.normals_outward is False
    model = Transform(scale=(2.0, 2.0, 2.0), translate=(10.0, 0.0, 0.0)).matrix()
    assert body.contains(np.array([[10.9, 0.9, -0.9], [9.1, 0.0, 0.0]]), model).all()
    assert not body.contains(np.array([[11.1, 0.0, 0.0]]), model).any()


# --- the pair rule ---------------------------------------------------------------------------

def scene_of(*objects, directional=(), point=()):
    return Scene(camera=Camera(eye=(0.0, 3.0, 6.0)), objects=list(objects),
                 directional_lights=[DirectionalLight(direction=d) for d in directional],
                 point_lights=[PointLight(position=p) for p in point])


def occluders(scene):
    return Occluders(scene, *world_geometry(scene))


def obj(name, mesh, translate=(0.0, 0.0, 0.0), two_sided=False, scale=(1.0, 1.0, 1.0)):
    return SceneObject(name, mesh, material=Material(two_sided=two_sided),
                       transform=Transform(scale=scale, translate=translate))


def test_a_convex_solid_lit_from_outside_cannot_shadow_itself_unless_its_inside_is_seen():
    ball = obj("ball", primitives.icosphere(1.0, 2))
    for lights in ({"directional": [DOWN]}, {"point": [(0.0, 5.0, 0.0)]}):
        assert not occluders(scene_of(ball, **lights)).can_shadow(0, 0, **_light(lights))
    two_sided = obj("ball", primitives.icosphere(1.0, 2), two_sided=True)
    assert occluders(scene_of(two_sided, directional=[DOWN])).can_shadow(0, 0, light_direction=DOWN)


def _light(lights):
    if "directional" in lights:
        return {"light_direction": lights["directional"][0]}
    return {"light_position": lights["point"][0]}


def test_a_convex_room_around_its_lamp_shadows_neither_itself_nor_what_is_in_it():
    """The lamp inside: every point of the room's inside sees it; a ball in the room is lit
    through nothing of the room; a ball outside the room is shadowed by it."""
    room = obj("room", primitives.cube(2.0), two_sided=True, scale=(2.0, 1.5, 2.0))
    inside = obj("in", primitives.icosphere(0.3, 1), translate=(0.5, -0.5, 0.5))
    outside = obj("out", primitives.icosphere(0.3, 1), translate=(9.0, 0.0, 0.0))
    rule = occluders(scene_of(room, inside, outside, point=[(0.0, 1.0, 0.0)]))
    lamp = (0.0, 1.0, 0.0)
    assert not rule.can_shadow(0, 0, light_position=lamp)
    assert not rule.can_shadow(0, 1, light_position=lamp)
    assert rule.can_shadow(0, 2, light_position=lamp)
    assert rule.can_shadow(0, 0, light_position=(0.0, 9.0, 0.0))      # lamp outside, inside seen


def test_a_floor_shadows_only_what_lies_below_it():
    floor = obj("floor", primitives.plane(10.0))
    above = obj("above", primitives.cube(1.0), translate=(0.0, 1.0, 0.0))
    dipping = obj("dipping", primitives.cube(1.0), translate=(0.0, 0.2, 0.0))
    rule = occluders(scene_of(floor, above, dipping, directional=[DOWN]))
    assert [rule.can_shadow(0, r, light_direction=DOWN) for r in (0, 1, 2)] == [False, False, True]
    assert not rule.can_shadow(0, 2, light_direction=(1.0, 0.0, 0.0))     # grazing: no area


def test_a_directional_light_shadows_only_within_the_casters_box_across_it_and_behind_it():
    """Light straight down: a cube over the floor at x = 0 can shadow a cube below it, not one
    beside it (x = 5), nor one above it."""
    caster = obj("caster", primitives.cube(1.0), translate=(0.0, 2.0, 0.0))
    below = obj("below", primitives.cube(1.0), translate=(0.3, 0.0, 0.0))
    beside = obj("beside", primitives.cube(1.0), translate=(5.0, 0.0, 0.0))
    above = obj("above", primitives.cube(1.0), translate=(0.0, 4.0, 0.0))
    rule = occluders(scene_of(caster, below, beside, above, directional=[DOWN]))
    assert rule.pairs([0], [1, 2, 3], light_direction=DOWN) == {0: [1]}


# --- what the planning draws -----------------------------------------------------------------

def test_the_default_scene_has_no_maps_and_draws_its_shadows_off_image(gl_contexts):
    """One convex ball under two lights: nothing can shadow anything, so no light gets a map,
    no program compiles shadow code, and the frame is the one with every light's shadows off,
    pixel for pixel (benchmarks/bench_shadows.py times the two: the same cost)."""
    scene = load_scene("sphere")
    assert shadow_lights(scene) == [] and not shadow_layout(scene, 64, 48).any
    off = replace(scene, directional_lights=[replace(light, shadow=Shadow(enabled=False))
                                             for light in scene.directional_lights],
                  point_lights=[replace(light, shadow=Shadow(enabled=False)) for light in scene.point_lights])
    ctx = gl_contexts["egl"]
    with GpuRenderer(scene, 64, 48, context=ctx) as gpu:
        on_image = gpu.render().rgba8
        assert gpu.shadow_maps is None and not any(v.shadows for v in gpu.programs)
    with GpuRenderer(off, 64, 48, context=ctx) as gpu:
        assert (gpu.render().rgba8 == on_image).all()


def test_a_room_around_its_lamp_is_in_no_map_and_a_face_with_no_pair_is_not_drawn():
    """shadow_room: the room (a convex box around the lamp) is drawn into no face; the faces
    drawn are those whose frustum holds the ball, the box or the post and a receiver."""
    scene = load_scene("shadow_room")
    plan = plan_shadows(scene, scene.matrices(64, 48), shadow_layout(scene, 64, 48))
    names = [o.name for o in scene.objects]
    drawn = {p.face: [names[c] for c in p.casters] for p in plan.passes}
    assert all("room" not in casters for casters in drawn.values())
    assert len(drawn) < 6


def test_a_caster_dipping_below_the_floor_does_not_stretch_the_map():
    """mesh_shadow: the knot dips into the floor plane, so the floor can shadow it and is
    drawn; the map is fitted to the knot (its box across the light), not to the floor's
    extent: texels within twice those of the knot alone."""
    scene = load_scene("mesh_shadow")
    plan = plan_shadows(scene, scene.matrices(320, 240), shadow_layout(scene, 320, 240))
    alone = replace(scene, objects=[replace(scene.objects[0], casts_shadows=False), scene.objects[1]])
    alone_plan = plan_shadows(alone, alone.matrices(320, 240), shadow_layout(alone, 320, 240))
    key = ("directional", 0)
    assert plan.texel_size[key] <= 2.0 * alone_plan.texel_size[key]


def test_the_documents_give_the_automatic_constant_bias_the_code_uses():
    """docs/scene-format.md and docs/conventions.md state the automatic rule's constant term."""
    half = {0.5: "½", 0.25: "¼"}[CONSTANT_BIAS_TEXELS]
    for document in ("docs/scene-format.md", "docs/conventions.md"):
        text = (REPO / document).read_text()
        stated = re.findall(r"constant`? = (\S+?), `?slope`? = 0", text)
        assert stated and set(stated) == {half}, (document, stated)


def test_each_kind_of_light_has_a_stack_of_its_own_size():
    """classic at 640x480: its directional map (2048, twice the longer side) is the one layer of
    the directional stack; its point light's six faces (512, half the longer side) are six
    layers of 512, not of 2048 (a quarter of the memory each: 6 MiB, not 96)."""
    layout = shadow_layout(load_scene("classic"), 640, 480)
    assert layout.stack("directional") == LayerStack(2048, 1)
    assert layout.stack("point") == LayerStack(512, 6)
    assert [tile.layer for tile in layout.get("point", 0).tiles] == [0, 1, 2, 3, 4, 5]


def test_an_image_far_longer_than_wide_gets_maps_for_its_pixels_not_its_long_side():
    """Automatic maps hold at most 128 texels per image pixel: at 1 x 16384 (16,384 pixels,
    2 M texels a map) the directional map's 2 x 16384 -> 4096 halves to 1024 (1 M texels; 2048
    is 4 M) and a cube face's 8192 -> 4096 to 512 (six faces 1.5 M; 1024 is 6 M), either way
    round. Usual shapes keep the long side's rule, whatever the filter: 640 x 480 gets 2048 and
    512 (13.7 and 5.1 texels a pixel), pcf5x5 at 206 x 206 (the worst rounding up: 1030 ->
    2048) keeps 2048, 98.8 a pixel; the smallest map stays even where it is more."""
    assert auto_resolution(1, 16384, point=False) == auto_resolution(16384, 1, point=False) == 1024
    assert auto_resolution(1, 16384, point=True) == auto_resolution(16384, 1, point=True) == 512
    assert (auto_resolution(640, 480, point=False), auto_resolution(640, 480, point=True)) == (2048, 512)
    assert auto_resolution(206, 206, point=False, kernel=FILTERS["pcf5x5"]) == 2048
    assert auto_resolution(1, 1, point=True) == RESOLUTIONS[0]
