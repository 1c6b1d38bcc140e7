"""The interactive viewer's keys and mouse, with no GL and no window.

The viewer's glfw callbacks forward their arguments unchanged to `Controls.key`,
`mouse_button`, `cursor` and `scroll`, and the framebuffer size to `resize`; tests feed the
same events directly. Controls changes a `ViewState` and an `OrbitCamera` and says what it
did through `on_message`, one short line a key. Each frame the viewer:
- takes `orbit.camera` and clears `camera_changed` (set by drags, the wheel and R);
- calls `apply_view` and clears `scene_changed` (set by every key that changes what the
  picture shows: F G P A T 1-9, and W C H M O D, which the viewer reads from the state itself);
- acts on and clears the requests `screenshot` (S) and `quit` (Esc);
- applies `vsync` and `buffering` when they differ from what it last applied (V and B set
  no change flag: the picture stays the same).

`apply_view` and `working_copy` turn the state into the scene the renderer draws, keeping
the object identities the GPU renderer was made with.
"""

from __future__ import annotations

from dataclasses import dataclass, field, replace
from typing import Callable

import glfw

from renderer.viewer.orbit import OrbitCamera
from renderer.core.scene import Camera, Scene
from renderer.core.shadow_settings import scene_has_shadows
from renderer.methods import METHODS

REFERENCE_MODES = ("off", "side-by-side", "difference")     # C cycles in this order
ORBIT_DEGREES_PER_PIXEL = 0.4
SHADING_NAMES = {None: "as authored", "flat": "flat", "gouraud": "Gouraud", "phong": "Phong"}
LIGHT_KEYS = 9                                              # keys 1 to 9


@dataclass
class ViewState:
    """What the viewer shows, as the keys left it; None means as the scene file has it."""
    shading: str | None = None          # "flat" / "gouraud" / "phong" for every object
    wireframe: bool = False
    two_sided: bool | None = None       # two-sided lighting for every object
    lights_on: list[bool] = field(default_factory=list)   # directional lights, then point
    reference: str = "off"              # one of REFERENCE_MODES
    vsync: bool = True
    buffering: int = 2                  # 2 (double) or 3 (triple)
    help: bool = False
    method: str = "raster"              # one of METHODS: what draws the picture
    shadows: bool = True                # shadow maps drawn and looked up (GpuRenderer.shadows)
    shadow_map: int | None = None       # the light (index in key order) whose map is shown
    # Requests: the viewer acts on them and clears them.
    screenshot: bool = False
    quit: bool = False
    # Changes since the viewer last looked: it redraws and clears them.
    camera_changed: bool = False
    scene_changed: bool = False


# --------------------------------------------------------------------------- state to scene

def working_copy(authored: Scene) -> Scene:
    """The scene the viewer draws: new SceneObjects (meshes shared) and new light lists, so
    that apply_view can change it in place without touching the authored scene."""
    return replace(authored,
                   objects=[replace(obj) for obj in authored.objects],
                   directional_lights=list(authored.directional_lights),
                   point_lights=list(authored.point_lights))


def apply_view(state: ViewState, authored: Scene, shown: Scene, camera: Camera) -> None:
    """Write the state's choices into `shown` (a working_copy of `authored`) in place.

    Every `shown.objects[i]` stays the same object (the GPU renderer checks identity); only
    its material is replaced, by the authored one with the state's shading and two_sided.
    Lights are the authored ones whose `lights_on` flag is True (a light without a flag, past
    the end of the list, is on). `shown.camera` becomes `camera` itself.
    """
    if len(shown.objects) != len(authored.objects):
        raise ValueError(f"shown has {len(shown.objects)} objects, the authored scene "
                         f"{len(authored.objects)}: make shown with working_copy(authored)")
    changes = {}
    if state.shading is not None:
        changes["shading"] = state.shading
    if state.two_sided is not None:
        changes["two_sided"] = state.two_sided
    for obj, source in zip(shown.objects, authored.objects):
        obj.material = replace(source.material, **changes)
    flags = list(state.lights_on)
    n_directional = len(authored.directional_lights)

    def on(i: int) -> bool:
        return flags[i] if i < len(flags) else True

    shown.directional_lights = [light for i, light in enumerate(authored.directional_lights)
                                if on(i)]
    shown.point_lights = [light for i, light in enumerate(authored.point_lights)
                          if on(n_directional + i)]
    shown.camera = camera


def light_names_of(scene: Scene) -> list[str]:
    """The names Controls and help_lines give the lights, in key order:
    ["directional light 1", ..., "point light 1", ...]."""
    return ([f"directional light {i + 1}" for i in range(len(scene.directional_lights))]
            + [f"point light {i + 1}" for i in range(len(scene.point_lights))])


def lights_with_maps(scene: Scene | None) -> list[int]:
    """The lights (indices in key order) that have a shadow map when on: those with shadows
    on, in a scene where something casts and something receives."""
    if scene is None or not scene_has_shadows(scene):
        return []
    lights = [*scene.directional_lights, *scene.point_lights]
    return [i for i, light in enumerate(lights) if light.shadow.enabled]


def shown_light(state: ViewState, authored: Scene, index: int) -> tuple[str, int]:
    """(kind, index among the shown scene's lights of that kind) of light `index` in key
    order, which must be on: apply_view leaves the lights that are off out."""
    n_directional = len(authored.directional_lights)
    flags = list(state.lights_on) + [True] * (index + 1 - len(state.lights_on))
    if index < n_directional:
        return "directional", sum(flags[:index])
    return "point", sum(flags[n_directional:index])


# --------------------------------------------------------------------------- the bindings

@dataclass(frozen=True)
class Binding:
    key: int            # glfw key constant (for "1-9": KEY_1; keys 1 to 9 and keypad 1 to 9)
    label: str
    what: str


KEY_BINDINGS = (
    Binding(glfw.KEY_F, "F", "flat shading for every object"),
    Binding(glfw.KEY_G, "G", "Gouraud shading for every object"),
    Binding(glfw.KEY_P, "P", "Phong shading for every object"),
    Binding(glfw.KEY_A, "A", "shading as the scene file has it"),
    Binding(glfw.KEY_W, "W", "wireframe on / off"),
    Binding(glfw.KEY_T, "T", "two-sided lighting on / off for every object"),
    Binding(glfw.KEY_1, "1-9",
            "light 1 to 9 on / off (directional lights first, then point lights)"),
    Binding(glfw.KEY_C, "C", "reference view: off, side by side, difference"),
    Binding(glfw.KEY_M, "M", "rasteriser / ray tracer / radiosity / path tracer (the tracers refine while the "
                             "view is still, radiosity converges)"),
    Binding(glfw.KEY_O, "O", "shadows on / off"),
    Binding(glfw.KEY_D, "D", "shadow map view: each light's map in turn (depth as grey), then off"),
    Binding(glfw.KEY_V, "V", "v-sync on / off"),
    Binding(glfw.KEY_B, "B", "double / triple buffering"),
    Binding(glfw.KEY_S, "S", "save a screenshot"),
    Binding(glfw.KEY_R, "R", "reset the view to the scene's camera"),
    Binding(glfw.KEY_H, "H", "show / hide this help"),
    Binding(glfw.KEY_ESCAPE, "Esc", "quit"),
)

MOUSE_BINDINGS = (
    ("left drag", "orbit: turn the camera about the look point"),
    ("middle drag / shift + left drag", "pan: move the view with the cursor"),
    ("wheel", "zoom: closer / further (parallel: a smaller / larger view)"),
)


def _on_off(flag: bool) -> str:
    return "on" if flag else "off"


def _table(rows) -> list[str]:
    width = max(len(label) for label, _ in rows)
    return [f"  {label:<{width}}   {what}" for label, what in rows]


def help_lines(state: ViewState | None = None, light_names: list[str] | None = None) -> list[str]:
    """The help text: every key and mouse binding; with `light_names`, the lights by key
    (and whether each is on, with `state`); with `state`, the current settings."""
    lines = ["Keys"] + _table([(b.label, b.what) for b in KEY_BINDINGS])
    lines += ["Mouse"] + _table(MOUSE_BINDINGS)
    if light_names:
        flags = state.lights_on if state is not None else []
        rows = []
        for i, name in enumerate(light_names):
            label = str(i + 1) if i < LIGHT_KEYS else "-"
            what = name + (f": {_on_off(flags[i])}" if i < len(flags) else "")
            rows.append((label, what))
        lines += ["Lights"] + _table(rows)
    if state is not None:
        two_sided = "as authored" if state.two_sided is None else _on_off(state.two_sided)
        lines += ["Now",
                  f"  shading: {SHADING_NAMES[state.shading]}, wireframe: "
                  f"{_on_off(state.wireframe)}, two-sided lighting: {two_sided}",
                  f"  reference view: {state.reference}, v-sync: {_on_off(state.vsync)}, "
                  f"buffering: {_buffering(state.buffering)}, method: {METHODS[state.method].title}",
                  f"  shadows: {_on_off(state.shadows)}, shadow map view: "
                  + ("off" if state.shadow_map is None or not light_names
                     else light_names[state.shadow_map])]
    return lines


def _buffering(count: int) -> str:
    return {2: "double", 3: "triple"}.get(count, str(count))


# --------------------------------------------------------------------------- the handler

class Controls:
    """Keys and mouse to ViewState and OrbitCamera changes (module docstring: the protocol).

    `scene` (optional) is the authored scene; T needs it to know whether every material is
    authored two-sided (without it, the first T turns two-sided lighting on), D which lights
    have shadow maps (without it, none).
    Call `resize` with the framebuffer size before panning: cursor positions must be in the
    same units (pixels) for the scene to follow the cursor.
    """

    def __init__(self, state: ViewState, orbit: OrbitCamera, light_names: list[str],
                 on_message: Callable[[str], object] = print, *, scene: Scene | None = None):
        self.state = state
        self.orbit = orbit
        self.light_names = list(light_names)
        self.on_message = on_message
        if not state.lights_on:
            state.lights_on = [True] * len(self.light_names)
        elif len(state.lights_on) != len(self.light_names):
            raise ValueError(f"{len(state.lights_on)} light flags for "
                             f"{len(self.light_names)} lights")
        self._authored_all_two_sided = (scene is not None and
                                        all(o.material.two_sided for o in scene.objects))
        self._with_maps = lights_with_maps(scene)
        self._width = 0
        self._height = 0
        self._cursor: tuple[float, float] | None = None
        self._drag: str | None = None          # "orbit" or "pan" while a button is held
        self._drag_button: int | None = None
        self._keys = {
            glfw.KEY_F: lambda: self._shade("flat"),
            glfw.KEY_G: lambda: self._shade("gouraud"),
            glfw.KEY_P: lambda: self._shade("phong"),
            glfw.KEY_A: lambda: self._shade(None),
            glfw.KEY_W: self._wireframe,
            glfw.KEY_T: self._two_sided,
            glfw.KEY_C: self._reference,
            glfw.KEY_M: self._method,
            glfw.KEY_O: self._shadows,
            glfw.KEY_D: self._shadow_map,
            glfw.KEY_V: self._vsync,
            glfw.KEY_B: self._buffering,
            glfw.KEY_S: self._screenshot,
            glfw.KEY_R: self._reset,
            glfw.KEY_H: self._help,
            glfw.KEY_ESCAPE: self._quit,
        }
        for i in range(LIGHT_KEYS):
            self._keys[glfw.KEY_1 + i] = lambda i=i: self._light(i)
            self._keys[glfw.KEY_KP_1 + i] = lambda i=i: self._light(i)

    # ------------------------------------------------------------------------ glfw callbacks

    def key(self, key: int, scancode: int, action: int, mods: int) -> None:
        """A key event; only presses act (a held key's repeats would toggle back and forth)."""
        if action != glfw.PRESS:
            return
        handler = self._keys.get(key)
        if handler is not None:
            handler()

    def mouse_button(self, button: int, action: int, mods: int) -> None:
        """Left press starts an orbit drag, or a pan with shift held at the press; middle
        press starts a pan. Releasing that button ends the drag; others are ignored meanwhile."""
        if action == glfw.PRESS and self._drag is None:
            if button == glfw.MOUSE_BUTTON_LEFT:
                self._drag = "pan" if mods & glfw.MOD_SHIFT else "orbit"
            elif button == glfw.MOUSE_BUTTON_MIDDLE:
                self._drag = "pan"
            else:
                return
            self._drag_button = button
        elif action == glfw.RELEASE and button == self._drag_button:
            self._drag = self._drag_button = None

    def cursor(self, x: float, y: float) -> None:
        """The cursor at (x, y), window coordinates (y down). While dragging, the move since
        the last position orbits or pans. Orbit feels like grabbing the scene: dragging right
        turns the camera left (azimuth -0.4°/px), dragging down raises it (elevation +0.4°/px),
        so the side facing the viewer follows the cursor."""
        last, self._cursor = self._cursor, (x, y)
        if self._drag is None or last is None:
            return
        dx, dy = x - last[0], y - last[1]
        if dx == 0 and dy == 0:
            return
        if self._drag == "orbit":
            self.orbit.orbit(-dx * ORBIT_DEGREES_PER_PIXEL, dy * ORBIT_DEGREES_PER_PIXEL)
        elif self._height > 0:
            self.orbit.pan(dx, dy, self._height)
        else:
            return
        self.state.camera_changed = True

    def scroll(self, dx: float, dy: float) -> None:
        """Wheel: dy steps, + (away from the user) zooms in."""
        if dy != 0:
            self.orbit.zoom(dy)
            self.state.camera_changed = True

    def resize(self, width: int, height: int) -> None:
        """The framebuffer size in pixels (pan's scale)."""
        self._width, self._height = int(width), int(height)

    # ------------------------------------------------------------------------ the keys

    def _say(self, line: str) -> None:
        self.on_message(line)

    def _set(self, name: str, value) -> None:
        """Set a state field that changes the picture; flag it only when it really changed."""
        if getattr(self.state, name) != value:
            setattr(self.state, name, value)
            self.state.scene_changed = True

    def _shade(self, mode: str | None) -> None:
        self._set("shading", mode)
        self._say(f"shading: {SHADING_NAMES[mode]}")

    def _wireframe(self) -> None:
        self._set("wireframe", not self.state.wireframe)
        self._say(f"wireframe: {_on_off(self.state.wireframe)}")

    def _two_sided(self) -> None:
        current = self.state.two_sided
        self._set("two_sided", not self._authored_all_two_sided if current is None else not current)
        self._say(f"two-sided lighting: {_on_off(self.state.two_sided)}")

    def _light(self, index: int) -> None:
        count = len(self.state.lights_on)
        if index >= count:
            has = "no lights" if count == 0 else f"{count} light{'s' if count > 1 else ''}"
            self._say(f"light {index + 1}: no such light (the scene has {has})")
            return
        self.state.lights_on[index] = not self.state.lights_on[index]
        self.state.scene_changed = True
        name = self.light_names[index]
        self._say(f"light {index + 1} ({name}): {_on_off(self.state.lights_on[index])}")
        if self.state.shadow_map == index:          # its map went with it
            self.state.shadow_map = None
            self._say("shadow map view: off")

    def _reference(self) -> None:
        i = REFERENCE_MODES.index(self.state.reference)
        self._set("reference", REFERENCE_MODES[(i + 1) % len(REFERENCE_MODES)])
        self._say(f"reference view: {self.state.reference}")

    def _method(self) -> None:
        names = [n for n, m in METHODS.items() if m.stepped_to or n == self.state.method]
        # M steps through them in registration order
        self._set("method", names[(names.index(self.state.method) + 1) % len(names)])
        shown = METHODS[self.state.method]
        self._say(f"method: {shown.title}" + ("; it refines while the view is still (the title "
                                               "counts the samples per pixel)" if shown.progressive else
                                               "; it converges a step a frame (the title says where)"
                                               if shown.solved_in_steps else ""))

    def _shadows(self) -> None:
        self._set("shadows", not self.state.shadows)
        self._say(f"shadows: {_on_off(self.state.shadows)}")

    def _shadow_map(self) -> None:
        """The next light (key order) that is on and has a map, after the one shown; after
        the last, off."""
        with_maps = [i for i in self._with_maps if self.state.lights_on[i]]
        if not with_maps:
            self._say("shadow map view: no light that is on has a shadow map")
            return
        current = self.state.shadow_map
        later = [i for i in with_maps if current is None or i > current]
        self._set("shadow_map", later[0] if later else None)
        if self.state.shadow_map is None:
            self._say("shadow map view: off")
        else:
            self._say(f"shadow map view: {self.light_names[self.state.shadow_map]}")

    def _vsync(self) -> None:
        self.state.vsync = not self.state.vsync
        self._say(f"v-sync: {_on_off(self.state.vsync)}")

    def _buffering(self) -> None:
        self.state.buffering = 3 if self.state.buffering == 2 else 2
        self._say(f"buffering: {_buffering(self.state.buffering)}")

    def _screenshot(self) -> None:
        self.state.screenshot = True             # the viewer says where it saved it

    def _reset(self) -> None:
        self.orbit.reset()
        self.state.camera_changed = True
        self._say("view reset")

    def _help(self) -> None:
        self._set("help", not self.state.help)
        if self.state.help:
            self._say("\n".join(help_lines(self.state, self.light_names)))
        else:
            self._say("help: hidden")

    def _quit(self) -> None:
        self.state.quit = True
