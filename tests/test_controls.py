"""renderer/viewer/controls.py: the viewer's keys and mouse, fed events directly (no GL, no window).

The scene below has two objects (one authored two-sided, one not) and three lights: one
directional and two point lights, so keys 1, 2, 3 are "directional light 1",
"point light 1", "point light 2".
"""

from dataclasses import fields, replace

import glfw
import numpy as np
import pytest

from renderer.viewer.controls import (KEY_BINDINGS, MOUSE_BINDINGS, ORBIT_DEGREES_PER_PIXEL,
                               Controls, ViewState, apply_view, help_lines, light_names_of,
                               shown_light, working_copy)
from renderer.viewer.orbit import OrbitCamera
from renderer.core.scene import (Camera, DirectionalLight, Material, Mesh, PointLight, Scene,
                            SceneObject)

WIDTH, HEIGHT = 640, 480


def triangle() -> Mesh:
    return Mesh(positions=np.array([[0.0, 0, 0], [1, 0, 0], [0, 1, 0]]),
                normals=np.array([[0.0, 0, 1]] * 3), faces=np.array([[0, 1, 2]]))


def make_scene(two_sided=(True, False)) -> Scene:
    mesh = triangle()
    return Scene(
        camera=Camera(eye=(0.0, 0.0, 5.0)),
        objects=[SceneObject(f"object {i}", mesh,
                             Material(kd=(0.1 * i, 0.5, 0.5), shading="gouraud", two_sided=t))
                 for i, t in enumerate(two_sided)],
        directional_lights=[DirectionalLight(direction=(0.0, -1.0, 0.0))],
        point_lights=[PointLight(position=(1.0, 1.0, 1.0)), PointLight(position=(2.0, 2.0, 2.0))],
    )


class Viewer:
    """What a viewer holds: the state, the orbit camera, the controls and the messages."""

    def __init__(self, scene=None, state=None):
        self.scene = make_scene() if scene is None else scene
        self.state = ViewState() if state is None else state
        self.orbit = OrbitCamera(self.scene.camera)
        self.messages: list[str] = []
        self.controls = Controls(self.state, self.orbit, light_names_of(self.scene),
                                 self.messages.append, scene=self.scene)
        self.controls.resize(WIDTH, HEIGHT)

    def press(self, key, mods=0):
        self.controls.key(key, 0, glfw.PRESS, mods)

    def drag(self, button, path, mods=0):
        """Cursor to path[0], press, move along the rest, release."""
        self.controls.cursor(*path[0])
        self.controls.mouse_button(button, glfw.PRESS, mods)
        for point in path[1:]:
            self.controls.cursor(*point)
        self.controls.mouse_button(button, glfw.RELEASE, mods)


def expected(camera, *moves) -> Camera:
    """The camera an OrbitCamera ends with after the given (method, args) moves."""
    orbit = OrbitCamera(camera)
    for method, args in moves:
        getattr(orbit, method)(*args)
    return orbit.camera


# --------------------------------------------------------------------------- state and lights

def test_lights_on_starts_with_every_light_on():
    viewer = Viewer()
    assert light_names_of(viewer.scene) == ["directional light 1", "point light 1", "point light 2"]
    assert viewer.state.lights_on == [True, True, True]


def test_a_light_list_of_the_wrong_length_is_refused():
    with pytest.raises(ValueError, match="2 light flags for 3 lights"):
        Viewer(state=ViewState(lights_on=[True, False]))


# --------------------------------------------------------------------------- keys

@pytest.mark.parametrize("key, mode, message", [
    (glfw.KEY_F, "flat", "shading: flat"),
    (glfw.KEY_G, "gouraud", "shading: Gouraud"),
    (glfw.KEY_P, "phong", "shading: Phong"),
])
def test_shading_keys(key, mode, message):
    viewer = Viewer()
    viewer.press(key)
    assert viewer.state.shading == mode
    assert viewer.messages == [message]
    assert viewer.state.scene_changed and not viewer.state.camera_changed


def test_a_gives_shading_back_to_the_scene_file():
    viewer = Viewer()
    viewer.press(glfw.KEY_F)
    viewer.press(glfw.KEY_A)
    assert viewer.state.shading is None
    assert viewer.messages == ["shading: flat", "shading: as authored"]


def test_a_key_that_changes_nothing_says_so_but_flags_no_change():
    viewer = Viewer()
    viewer.press(glfw.KEY_F)
    viewer.state.scene_changed = False                 # the viewer has drawn it
    viewer.press(glfw.KEY_F)
    assert viewer.messages == ["shading: flat", "shading: flat"]
    assert not viewer.state.scene_changed


def test_w_toggles_wireframe():
    viewer = Viewer()
    viewer.press(glfw.KEY_W)
    assert viewer.state.wireframe and viewer.state.scene_changed
    viewer.press(glfw.KEY_W)
    assert not viewer.state.wireframe
    assert viewer.messages == ["wireframe: on", "wireframe: off"]


@pytest.mark.parametrize("authored, first", [
    ((True, False), True),         # not all two-sided: the first T makes every object two-sided
    ((True, True), False),         # all two-sided: the first T makes every object one-sided
    ((False, False), True),
])
def test_t_toggles_two_sided_lighting_from_the_authored_materials(authored, first):
    viewer = Viewer(scene=make_scene(two_sided=authored))
    viewer.press(glfw.KEY_T)
    assert viewer.state.two_sided is first and viewer.state.scene_changed
    viewer.press(glfw.KEY_T)
    assert viewer.state.two_sided is (not first)
    on_off = {True: "on", False: "off"}
    assert viewer.messages == [f"two-sided lighting: {on_off[first]}",
                               f"two-sided lighting: {on_off[not first]}"]


def test_t_without_the_scene_turns_two_sided_lighting_on():
    messages = []
    state = ViewState()
    controls = Controls(state, OrbitCamera(Camera()), [], messages.append)
    controls.key(glfw.KEY_T, 0, glfw.PRESS, 0)
    assert state.two_sided is True and messages == ["two-sided lighting: on"]


def test_number_keys_toggle_lights_directional_first():
    viewer = Viewer()
    viewer.press(glfw.KEY_2)
    assert viewer.state.lights_on == [True, False, True] and viewer.state.scene_changed
    viewer.press(glfw.KEY_1)
    viewer.press(glfw.KEY_KP_2)                        # the keypad's digits work too
    assert viewer.state.lights_on == [False, True, True]
    assert viewer.messages == ["light 2 (point light 1): off",
                               "light 1 (directional light 1): off",
                               "light 2 (point light 1): on"]


def test_a_number_past_the_lights_only_says_so():
    viewer = Viewer()
    viewer.press(glfw.KEY_4)
    viewer.press(glfw.KEY_9)
    assert viewer.state.lights_on == [True, True, True]
    assert not viewer.state.scene_changed
    assert viewer.messages == ["light 4: no such light (the scene has 3 lights)",
                               "light 9: no such light (the scene has 3 lights)"]
    one = Viewer(scene=replace(make_scene(), point_lights=[]))
    one.press(glfw.KEY_2)
    none = Viewer(scene=replace(make_scene(), directional_lights=[], point_lights=[]))
    none.press(glfw.KEY_1)
    assert one.messages == ["light 2: no such light (the scene has 1 light)"]
    assert none.messages == ["light 1: no such light (the scene has no lights)"]


def test_c_cycles_the_reference_view():
    viewer = Viewer()
    seen = []
    for _ in range(3):
        viewer.press(glfw.KEY_C)
        seen.append(viewer.state.reference)
    assert seen == ["side-by-side", "difference", "off"]
    assert viewer.messages == ["reference view: side-by-side", "reference view: difference",
                               "reference view: off"]
    assert viewer.state.scene_changed


def test_m_toggles_the_ray_tracer_and_changes_the_picture():
    """M steps between the methods in registration order: the rasteriser, the ray tracer,
    radiosity (which converges a step a frame), the path tracer."""
    viewer = Viewer()
    viewer.press(glfw.KEY_M)
    assert viewer.state.method == "raytrace" and viewer.state.scene_changed
    assert viewer.messages == ["method: ray tracer; it refines while the view is still (the "
                               "title counts the samples per pixel)"]
    viewer.state.scene_changed = False
    viewer.press(glfw.KEY_M)
    assert viewer.state.method == "radiosity" and viewer.state.scene_changed
    assert viewer.messages[-1] == "method: radiosity; it converges a step a frame (the title says where)"
    viewer.press(glfw.KEY_M)
    assert viewer.state.method == "pathtrace" and viewer.state.scene_changed
    assert viewer.messages[-1].startswith("method: path tracer; it refines while the view is still")
    viewer.press(glfw.KEY_M)
    assert viewer.state.method == "raster"
    assert viewer.messages[-1] == "method: rasteriser"
    assert ("  M     rasteriser / ray tracer / radiosity / path tracer (the tracers refine while the "
            "view is still, radiosity converges)") in help_lines()


def test_m_from_radiosity_steps_on_in_registration_order():
    viewer = Viewer()
    viewer.state.method = "radiosity"
    viewer.press(glfw.KEY_M)
    assert viewer.state.method == "pathtrace"


def test_o_toggles_shadows():
    viewer = Viewer()
    viewer.press(glfw.KEY_O)
    assert not viewer.state.shadows and viewer.state.scene_changed
    viewer.press(glfw.KEY_O)
    assert viewer.state.shadows
    assert viewer.messages == ["shadows: off", "shadows: on"]


def test_d_cycles_through_the_lights_with_maps_then_off():
    """Directional light 1 (key 1) first, then the point lights; a light that is off or has
    shadows off is skipped; after the last, off."""
    scene = make_scene()
    scene.point_lights[0] = replace(scene.point_lights[0],
                                    shadow=replace(scene.point_lights[0].shadow, enabled=False))
    viewer = Viewer(scene)
    shown = []
    for _ in range(3):
        viewer.press(glfw.KEY_D)
        shown.append(viewer.state.shadow_map)
    assert shown == [0, 2, None] and viewer.state.scene_changed
    assert viewer.messages == ["shadow map view: directional light 1",
                               "shadow map view: point light 2", "shadow map view: off"]
    viewer.press(glfw.KEY_1)                       # light 1 off: D starts at point light 2
    viewer.press(glfw.KEY_D)
    assert viewer.state.shadow_map == 2


def test_turning_off_the_light_whose_map_is_shown_turns_the_map_view_off():
    viewer = Viewer()
    viewer.press(glfw.KEY_D)
    viewer.press(glfw.KEY_1)
    assert viewer.state.shadow_map is None and viewer.messages[-1] == "shadow map view: off"


@pytest.mark.parametrize("change", ["nothing casts", "lights off"])
def test_d_without_a_map_only_says_so(change):
    scene = make_scene()
    if change == "nothing casts":
        for obj in scene.objects:
            obj.casts_shadows = False
    viewer = Viewer(scene)
    if change == "lights off":
        for key in (glfw.KEY_1, glfw.KEY_2, glfw.KEY_3):
            viewer.press(key)
    viewer.state.scene_changed = False
    viewer.press(glfw.KEY_D)
    assert viewer.state.shadow_map is None and not viewer.state.scene_changed
    assert viewer.messages[-1] == "shadow map view: no light that is on has a shadow map"


def test_shown_light_counts_only_the_lights_that_are_on():
    scene = make_scene()                           # keys: directional 1, point 1, point 2
    assert [shown_light(ViewState(lights_on=[True] * 3), scene, i) for i in range(3)] == [
        ("directional", 0), ("point", 0), ("point", 1)]
    assert shown_light(ViewState(lights_on=[False, False, True]), scene, 2) == ("point", 0)


def test_v_and_b_switch_vsync_and_buffering_without_a_change_flag():
    viewer = Viewer()
    viewer.press(glfw.KEY_V)
    viewer.press(glfw.KEY_B)
    assert (viewer.state.vsync, viewer.state.buffering) == (False, 3)
    viewer.press(glfw.KEY_V)
    viewer.press(glfw.KEY_B)
    assert (viewer.state.vsync, viewer.state.buffering) == (True, 2)
    assert viewer.messages == ["v-sync: off", "buffering: triple",
                               "v-sync: on", "buffering: double"]
    assert not viewer.state.scene_changed and not viewer.state.camera_changed


def test_s_and_esc_request_a_screenshot_and_quitting():
    viewer = Viewer()
    viewer.press(glfw.KEY_S)
    assert viewer.state.screenshot and not viewer.state.quit
    viewer.press(glfw.KEY_ESCAPE)
    assert viewer.state.quit
    assert viewer.messages == []                       # the viewer reports the file it saves


def test_r_resets_the_view():
    viewer = Viewer()
    viewer.drag(glfw.MOUSE_BUTTON_LEFT, [(100, 100), (150, 120)])
    viewer.controls.scroll(0, 2)
    assert viewer.orbit.camera != viewer.scene.camera
    viewer.state.camera_changed = False
    viewer.press(glfw.KEY_R)
    assert viewer.orbit.camera == viewer.scene.camera
    assert viewer.state.camera_changed
    assert viewer.messages == ["view reset"]


def test_h_shows_the_help_and_hides_it():
    viewer = Viewer()
    viewer.press(glfw.KEY_H)
    assert viewer.state.help and viewer.state.scene_changed
    assert viewer.messages == ["\n".join(help_lines(viewer.state, light_names_of(viewer.scene)))]
    viewer.press(glfw.KEY_H)
    assert not viewer.state.help
    assert viewer.messages[-1] == "help: hidden"


def test_modifiers_do_not_change_what_a_key_does():
    viewer = Viewer()
    viewer.press(glfw.KEY_F, mods=glfw.MOD_SHIFT)
    assert viewer.state.shading == "flat"


def test_every_bound_key_does_something():
    for binding in KEY_BINDINGS:
        viewer = Viewer()
        viewer.press(binding.key)
        assert viewer.messages or viewer.state != ViewState(lights_on=[True] * 3), binding.label


@pytest.mark.parametrize("action", [glfw.REPEAT, glfw.RELEASE])
def test_only_presses_act(action):
    """A held key repeats: toggles would flicker. Neither repeats nor releases do anything."""
    keys = [b.key for b in KEY_BINDINGS] + [glfw.KEY_KP_1]
    viewer = Viewer()
    for key in keys:
        viewer.controls.key(key, 0, action, 0)
    assert viewer.state == ViewState(lights_on=[True] * 3)
    assert viewer.orbit.camera == viewer.scene.camera
    assert viewer.messages == []


def test_an_unbound_key_does_nothing():
    viewer = Viewer()
    viewer.press(glfw.KEY_Z)
    viewer.press(glfw.KEY_0)
    assert viewer.state == ViewState(lights_on=[True] * 3) and viewer.messages == []


# --------------------------------------------------------------------------- mouse

def test_left_drag_orbits_like_grabbing_the_scene():
    """Dragging 225 px right is -90° azimuth (0.4°/px): the camera goes to its left, from
    (0,0,5) to (-5,0,0), so the side facing the viewer moves right with the cursor."""
    assert ORBIT_DEGREES_PER_PIXEL == 0.4
    viewer = Viewer()
    viewer.drag(glfw.MOUSE_BUTTON_LEFT, [(100, 100), (200, 100), (325, 100)])
    np.testing.assert_allclose(viewer.orbit.camera.eye, (-5.0, 0.0, 0.0), atol=1e-12)
    assert viewer.state.camera_changed
    assert viewer.messages == []                       # mouse moves print nothing


def test_dragging_down_raises_the_camera():
    """75 px down is +30° elevation: the eye rises to (0, 2.5, 5 cos 30°)."""
    viewer = Viewer()
    viewer.drag(glfw.MOUSE_BUTTON_LEFT, [(100, 100), (100, 175)])
    np.testing.assert_allclose(viewer.orbit.camera.eye, (0.0, 2.5, 5 * np.cos(np.radians(30))),
                               atol=1e-12)


def test_a_drag_is_the_sum_of_its_moves():
    viewer = Viewer()
    viewer.drag(glfw.MOUSE_BUTTON_LEFT, [(100, 100), (110, 95), (90, 130)])
    want = expected(viewer.scene.camera, ("orbit", (-4.0, -2.0)), ("orbit", (8.0, 14.0)))
    np.testing.assert_allclose(viewer.orbit.camera.eye, want.eye, atol=1e-12)


def test_moves_without_a_button_or_after_release_do_nothing():
    viewer = Viewer()
    for point in [(0, 0), (50, 60), (300, 10)]:
        viewer.controls.cursor(*point)
    viewer.drag(glfw.MOUSE_BUTTON_LEFT, [(10, 10)])
    viewer.controls.cursor(400, 400)
    assert viewer.orbit.camera == viewer.scene.camera
    assert not viewer.state.camera_changed


def test_the_first_move_after_a_press_without_a_known_cursor_only_sets_the_anchor():
    viewer = Viewer()
    viewer.controls.mouse_button(glfw.MOUSE_BUTTON_LEFT, glfw.PRESS, 0)
    viewer.controls.cursor(100, 100)
    assert viewer.orbit.camera == viewer.scene.camera
    viewer.controls.cursor(110, 100)
    want = expected(viewer.scene.camera, ("orbit", (-4.0, 0.0)))
    np.testing.assert_allclose(viewer.orbit.camera.eye, want.eye, atol=1e-12)


@pytest.mark.parametrize("button, mods", [(glfw.MOUSE_BUTTON_MIDDLE, 0),
                                          (glfw.MOUSE_BUTTON_LEFT, glfw.MOD_SHIFT)])
def test_middle_drag_and_shift_left_drag_pan(button, mods):
    """30 px right, 20 px up: the same as pan(30, -20, 480), which keeps the old look point
    under the cursor (tests/test_orbit.py)."""
    viewer = Viewer()
    viewer.drag(button, [(100, 100), (130, 80)], mods=mods)
    want = expected(viewer.scene.camera, ("pan", (30.0, -20.0, HEIGHT)))
    np.testing.assert_allclose(viewer.orbit.camera.eye, want.eye, atol=1e-15)
    np.testing.assert_allclose(viewer.orbit.camera.look, want.look, atol=1e-15)
    assert viewer.state.camera_changed and viewer.messages == []


def test_shift_counts_at_the_press_only():
    """Shift held at the press pans for the whole drag; a press without it orbits (cursor
    events carry no modifiers)."""
    viewer = Viewer()
    viewer.drag(glfw.MOUSE_BUTTON_LEFT, [(100, 100), (130, 100)], mods=0)
    assert viewer.orbit.camera.look == (0.0, 0.0, 0.0)          # orbited: look kept
    viewer = Viewer()
    viewer.controls.cursor(100, 100)
    viewer.controls.mouse_button(glfw.MOUSE_BUTTON_LEFT, glfw.PRESS, glfw.MOD_SHIFT)
    viewer.controls.cursor(130, 100)
    assert viewer.orbit.camera.look != (0.0, 0.0, 0.0)          # panned


def test_another_buttons_release_does_not_end_the_drag():
    viewer = Viewer()
    viewer.controls.cursor(100, 100)
    viewer.controls.mouse_button(glfw.MOUSE_BUTTON_LEFT, glfw.PRESS, 0)
    viewer.controls.mouse_button(glfw.MOUSE_BUTTON_MIDDLE, glfw.PRESS, 0)   # ignored
    viewer.controls.mouse_button(glfw.MOUSE_BUTTON_MIDDLE, glfw.RELEASE, 0)
    viewer.controls.cursor(110, 100)
    want = expected(viewer.scene.camera, ("orbit", (-4.0, 0.0)))
    np.testing.assert_allclose(viewer.orbit.camera.eye, want.eye, atol=1e-12)


def test_right_button_does_nothing():
    viewer = Viewer()
    viewer.drag(glfw.MOUSE_BUTTON_RIGHT, [(100, 100), (200, 150)])
    assert viewer.orbit.camera == viewer.scene.camera


def test_pan_waits_for_the_framebuffer_size():
    messages = []
    state = ViewState()
    orbit = OrbitCamera(Camera())
    controls = Controls(state, orbit, [], messages.append)       # no resize yet
    controls.cursor(0, 0)
    controls.mouse_button(glfw.MOUSE_BUTTON_MIDDLE, glfw.PRESS, 0)
    controls.cursor(10, 10)
    assert orbit.camera == Camera() and not state.camera_changed


def test_wheel_zooms():
    """One step up (dy = +1) is closer: distance 5 -> 4.5; horizontal scrolling does nothing."""
    viewer = Viewer()
    viewer.controls.scroll(1.0, 0.0)
    assert viewer.orbit.camera == viewer.scene.camera and not viewer.state.camera_changed
    viewer.controls.scroll(0.0, 1.0)
    np.testing.assert_allclose(viewer.orbit.camera.eye, (0.0, 0.0, 4.5), atol=1e-15)
    assert viewer.state.camera_changed and viewer.messages == []


# --------------------------------------------------------------------------- the shown scene

def test_working_copy_has_new_objects_and_lists_sharing_meshes():
    authored = make_scene()
    shown = working_copy(authored)
    for a, s in zip(authored.objects, shown.objects):
        assert s is not a and s.mesh is a.mesh and s == a
    assert shown.objects is not authored.objects
    assert shown.directional_lights is not authored.directional_lights
    assert shown.point_lights is not authored.point_lights
    assert shown.point_lights == authored.point_lights


def test_apply_view_keeps_objects_and_writes_materials_lights_and_camera():
    authored = make_scene()
    before = [replace(obj.material) for obj in authored.objects]
    shown = working_copy(authored)
    objects = list(shown.objects)
    camera = Camera(eye=(1.0, 2.0, 3.0))
    state = ViewState(shading="flat", two_sided=False, lights_on=[True, False, True])
    apply_view(state, authored, shown, camera)
    assert all(s is o for s, o in zip(shown.objects, objects))
    for obj, source in zip(shown.objects, before):
        assert obj.material == replace(source, shading="flat", two_sided=False)
    assert [m.material for m in authored.objects] == before          # authored untouched
    assert shown.directional_lights == [authored.directional_lights[0]]
    assert len(shown.point_lights) == 1 and shown.point_lights[0] is authored.point_lights[1]
    assert shown.camera is camera


def test_apply_view_as_authored_gives_the_authored_materials_back():
    authored = make_scene()
    shown = working_copy(authored)
    apply_view(ViewState(shading="phong", two_sided=True), authored, shown, authored.camera)
    apply_view(ViewState(), authored, shown, authored.camera)
    assert [o.material for o in shown.objects] == [o.material for o in authored.objects]
    # no flags at all: every light is shown
    assert shown.directional_lights == authored.directional_lights
    assert shown.point_lights == authored.point_lights


def test_apply_view_turns_off_the_directional_light_only():
    authored = make_scene()
    shown = working_copy(authored)
    apply_view(ViewState(lights_on=[False, True, True]), authored, shown, authored.camera)
    assert shown.directional_lights == [] and shown.point_lights == authored.point_lights


def test_apply_view_refuses_a_shown_scene_that_is_not_a_copy():
    authored = make_scene()
    with pytest.raises(ValueError, match="working_copy"):
        apply_view(ViewState(), authored, Scene(), authored.camera)


def test_keys_then_apply_view():
    """The viewer's loop in small: key presses, then the shown scene follows them."""
    viewer = Viewer()
    shown = working_copy(viewer.scene)
    viewer.press(glfw.KEY_F)
    viewer.press(glfw.KEY_T)
    viewer.press(glfw.KEY_3)
    apply_view(viewer.state, viewer.scene, shown, viewer.orbit.camera)
    assert [(o.material.shading, o.material.two_sided) for o in shown.objects] == \
        [("flat", True), ("flat", True)]
    assert shown.point_lights == [viewer.scene.point_lights[0]]


# --------------------------------------------------------------------------- help

def test_help_lists_every_binding():
    text = "\n".join(help_lines())
    for binding in KEY_BINDINGS:
        assert any(line.split() and line.split()[0] == binding.label and binding.what in line
                   for line in help_lines()), binding.label
    for label, what in MOUSE_BINDINGS:
        assert f"{label}   " in text and what in text


def test_help_lines_read_as_a_table():
    """Key labels are padded to the widest (3: "1-9", "Esc"), then three spaces."""
    lines = help_lines()
    assert lines[0] == "Keys"
    assert lines[1] == "  F     flat shading for every object"
    assert "  1-9   light 1 to 9 on / off (directional lights first, then point lights)" in lines
    assert "  Esc   quit" in lines
    assert "  wheel                             zoom: closer / further (parallel: a smaller / " \
           "larger view)" in lines


def test_help_with_state_and_lights_shows_them():
    state = ViewState(shading="gouraud", lights_on=[True, False], buffering=3)
    lines = help_lines(state, ["directional light 1", "point light 1"])
    assert lines[lines.index("Lights") + 1:lines.index("Lights") + 3] == [
        "  1   directional light 1: on", "  2   point light 1: off"]
    assert "  shading: Gouraud, wireframe: off, two-sided lighting: as authored" in lines
    assert "  reference view: off, v-sync: on, buffering: triple, method: rasteriser" in lines
    assert "method: ray tracer" in help_lines(ViewState(method="raytrace"))[-2]
    assert help_lines(ViewState(shadows=False, shadow_map=1), ["directional light 1", "point light 1"])[-1] \
        == "  shadows: off, shadow map view: point light 1"


def test_view_state_defaults():
    state = ViewState()
    assert {f.name: getattr(state, f.name) for f in fields(state)} == {
        "shading": None, "wireframe": False, "two_sided": None, "lights_on": [],
        "reference": "off", "vsync": True, "buffering": 2, "help": False, "method": "raster",
        "shadows": True, "shadow_map": None,
        "screenshot": False, "quit": False, "camera_changed": False, "scene_changed": False}
