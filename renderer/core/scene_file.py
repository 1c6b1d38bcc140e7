"""Scene files: TOML in, a checked `Scene` out, every mistake one `SceneError` line.

    load_scene("sphere") or load_scene("my_scene.toml") -> Scene   (a built-in name or a path)
    read_scene(...) -> (parsed dict, path); with_overrides(data, {"camera.aperture": 0.1}, source)
    read_toml(path, "job file", UserError) -> dict     (any TOML file, its failures one line)
    scene_from_dict({"camera": {...}, "objects": [...]}, source="<dict>", base_dir=".")

docs/scene-format.md documents every key with its unit and default. The reader is strict:
an unknown key is an error (with the closest known key suggested), numbers must be finite,
and the camera, transforms and meshes are checked before anything is rendered, so that a
bad file fails here with "FILE: KEY.PATH: reason" instead of drawing nothing. Key paths
count list entries from 0: `objects[2].material.kd` is the third [[objects]] table.
"""

from __future__ import annotations

import copy
import dataclasses
import difflib
import inspect
import math
import numbers
import re
import tomllib
from pathlib import Path
from typing import Any, NoReturn

import numpy as np

from renderer.core import transforms
from renderer.core.gl_rules import scene_light_problem, scene_varying_problem
from renderer.core.builtin import assets_dir, is_scene_name, resolve_scene
from renderer.errors import SceneError, UserError, show_number
from renderer.core import memory
from renderer.core.meshio import DEFAULT_CREASE_ANGLE, MAX_COORDINATE, load_mesh
from renderer.core.paths import checked_path
from renderer.core.physical import MODELS
from renderer.core.user_files import SCENE_FILE, USER_FILE_CAPS, FileRefused, read_user_file
from renderer.core.primitives import PRIMITIVES
from renderer.core.primitives import TRIANGLES as PRIMITIVE_TRIANGLES
from renderer.core import shapes
from renderer.core import tessellation
from renderer.core.gltf_texture import base_colour_texture
from renderer.core.texture_keys import read_image, read_texture
from renderer.core.shadow_settings import (FILTERS, MAX_BIAS_TEXELS, RESOLUTIONS, BiasRule, Shadow,
                                           auto_bias)
from renderer.core.textures import MaterialTexture
from renderer.core.scene import (AREA_SHAPES, FRESNEL_MODES, SHADING_MODES, Camera, DirectionalLight, LightArea,
                            Material, Mesh, Plane, PointLight, Scene, SceneObject, Sphere,
                            Transform, energy_excess, world_shape)

PROJECTIONS = ("perspective", "parallel")
CULL_MODES = ("none", "back", "front")
LIGHT_TYPES = ("directional", "point")

TOP_KEYS = ("name", "description", "model", "background", "ambient", "camera", "materials", "lights",
            "objects")
LENS_KEYS = ("aperture", "focus_distance")
CAMERA_KEYS = ("eye", "look", "up", "projection", "fov_y", "height", "near", "far", "reversed_z",
               *LENS_KEYS, "shutter")
MATERIAL_KEYS = ("ka", "kd", "ks", "n", "two_sided", "shading", "kr", "kt", "ior", "gloss",
                 "texture", "emission", "fresnel")
SHADOW_KEYS = ("shadows", "shadow_resolution", "shadow_filter", "shadow_bias")
AREA_KEYS = ("area", "size", "radius", "normal")   # a point light's area (LightArea), `area` first
AREA_SHAPE_KEYS = {"rectangle": ("size", "normal"), "disc": ("radius", "normal"),
                   "sphere": ("radius",)}
LIGHT_KEYS = {
    "directional": ("type", "direction", "intensity", *SHADOW_KEYS),
    "point": ("type", "position", "intensity", "attenuation", *SHADOW_KEYS, *AREA_KEYS),
}
BIAS_KEYS = tuple(f.name for f in dataclasses.fields(BiasRule))   # normal, constant, slope
OBJECT_KEYS = ("name", "mesh", "shape", "material", "scale", "shear", "rotate", "translate", "parent",
               "cull", "casts_shadows", "receives_shadows", "velocity", "angular_velocity", "tessellation")
TESSELLATION_KEYS = ("spacing", "error", "level", "displacement")
DISPLACEMENT_KEYS = ("image", "scale", "uv_scale", "uv_offset")
MESH_FILE_KEYS = ("file", "crease_angle")
SHAPE_TYPES = ("sphere", "plane")
SHAPE_KEYS = {
    "sphere": ("type", "centre", "radius", "subdivisions"),
    "plane": ("type", "normal", "offset", "size", "segments"),
}

# Limits on primitive arguments: (integer?, smallest, largest). Lengths must be > 0; counts
# are capped so that a typo cannot ask for a hundred million triangles.
MAX_SEGMENTS = 1024
_LENGTH = (False, 0.0, None)          # a float > 0
PRIMITIVE_LIMITS = {
    "uv_sphere": {"radius": _LENGTH, "segments": (True, 3, MAX_SEGMENTS),
                  "rings": (True, 2, MAX_SEGMENTS)},
    "icosphere": {"radius": _LENGTH, "subdivisions": (True, 0, 6)},
    "plane": {"size": _LENGTH, "segments": (True, 1, MAX_SEGMENTS)},
    "cube": {"size": _LENGTH},
    "cylinder": {"radius": _LENGTH, "height": _LENGTH, "segments": (True, 3, MAX_SEGMENTS)},
    "torus": {"major_radius": _LENGTH, "minor_radius": _LENGTH,
              "major_segments": (True, 3, MAX_SEGMENTS), "minor_segments": (True, 3, MAX_SEGMENTS)},
}

# Arrays and tables nest at most this many levels (the top-level table is level 1; a
# scene's deepest value, objects[i].mesh.file or a shear factor, is at level 4 or 5).
MAX_NESTING = 32

# A parent cycle longer than this shows its first and last names only.
MAX_CYCLE_SHOWN = 8

# A model matrix whose linear part has a determinant at or below this is refused.
MIN_DETERMINANT = 1e-9

# The GPU computes in float32 (largest value 3.4e38): every number in a scene file, and every
# mesh coordinate (meshio.MAX_COORDINATE), must have |x| <= MAX_NUMBER, so that products of
# two such numbers stay finite. The matrices they compose (camera-relative model matrix,
# normal matrix, projection) and each object's bounding box through them, in clip space,
# must stay within MAX_COMPOSED, which leaves 8 orders of magnitude for the image's aspect
# ratio and the GPU's own arithmetic.
MAX_NUMBER = MAX_COORDINATE
MAX_COMPOSED = 1e30
# The reason a number over MAX_NUMBER is refused, the same wherever it stands.
TOO_LARGE = f"too large for the GPU's float32 arithmetic; numbers must satisfy |x| <= {MAX_NUMBER:g}"


# --------------------------------------------------------------------------- entry points

def load_scene(scene) -> Scene:
    """Read a TOML scene file, given by its path or, from any folder, a built-in scene by its
    name ("sphere", "hierarchy", ...: what `renderer scenes` lists). Mesh files it names are
    found relative to its folder. `read_scene` then `scene_from_dict`, for callers that
    change the parsed data in between (`with_overrides`).
    """
    data, path = read_scene(scene)
    return scene_from_dict(data, source=str(path), base_dir=path.parent)


def read_scene(scene) -> tuple[dict, Path]:
    """A scene file's parsed TOML and its path; "name" defaults to the file's stem.

    An existing file wins over a built-in name spelt the same. A bare name (no folder, no
    `.toml` suffix) that is neither gives the command line's one-line error
    ("spher: no such scene file or built-in scene; did you mean 'sphere'? ..."); any other
    path that does not exist gives "FILE: scene file not found".
    """
    path = checked_path(scene, error=SceneError)
    if not path.is_file() and is_scene_name(str(scene)):
        path = resolve_scene(str(scene))
    data = read_toml(path)
    data.setdefault("name", path.stem)
    return data, path


def read_toml(path: Path, what: str = "scene file", error: type[UserError] = SceneError) -> dict:
    """A TOML file's parsed tables; each way of failing is one `error` line naming the file
    (not found, not a regular file, over its size cap, not UTF-8, unreadable, a syntax error,
    nested too deeply: renderer/core/user_files.py reads it). `what` names the kind of file
    in the reasons ("scene file", "job file"), and is its kind for the size cap."""
    kind = what if what in USER_FILE_CAPS else SCENE_FILE
    source = str(path)
    try:
        return tomllib.loads(read_user_file(path, kind).decode("utf-8-sig"))
    except FileRefused as refused:
        raise error(refused.reason, file=source) from None
    except UnicodeDecodeError as exc:
        raise error(f"not UTF-8 text (byte {exc.start}); a {what} is TOML", file=source) from None
    except tomllib.TOMLDecodeError as exc:
        raise error(_toml_syntax_reason(exc), file=source) from None
    except RecursionError:               # tomllib recurses once per level of nesting
        raise error(f"arrays or tables nested too deeply for the TOML parser; a {what} "
                    f"nests at most {MAX_NESTING} levels", file=source) from None


# One step of a key path: a table key (letters, digits, _) or a list index `[i]`.
_KEY_STEP = re.compile(r"(?:^|\.)([A-Za-z_][A-Za-z0-9_]*)|\[(\d+)\]")


def with_overrides(data: dict, overrides: dict, source: str) -> dict:
    """A deep copy of parsed scene data with each key path in `overrides` set to its value:
    {"objects[0].material.kd": [1, 0, 0], "camera.aperture": 0.1}. Missing tables on the
    way are made (the reader then refuses a key it does not know, with its suggestion); a
    list index past the end, a step into a value that is not a table or list, or a path
    that is not a key path is a SceneError naming `source` and the path. The values are
    checked later, by `scene_from_dict`, exactly as a file's are."""
    data = copy.deepcopy(data)
    for path, value in overrides.items():
        steps = _key_steps(path, source)
        node, where = data, ""
        for i, (key, index) in enumerate(steps):
            last = i == len(steps) - 1
            if key is not None:
                if not isinstance(node, dict):
                    raise SceneError(f"cannot set {key!r} in {describe_value(node)}",
                                     file=source, key=where)
                where = _join(where, key)
                if last:
                    node[key] = value
                else:
                    node = node.setdefault(key, {})
            else:
                if not isinstance(node, list) or index >= len(node):
                    got = (f"the list has {len(node)} item{'' if len(node) == 1 else 's'}"
                           if isinstance(node, list) else f"got {describe_value(node)}")
                    raise SceneError(f"no entry [{index}]: {got}", file=source, key=where)
                where = f"{where}[{index}]"
                if last:
                    node[index] = value
                else:
                    node = node[index]
    return data


def _key_steps(path: str, source: str) -> list[tuple[str | None, int | None]]:
    """'objects[0].material.kd' -> [("objects", None), (None, 0), ("material", None), ...]."""
    steps, end = [], 0
    for match in _KEY_STEP.finditer(path):
        if match.start() != end:
            break
        steps.append((match[1], None) if match[1] else (None, int(match[2])))
        end = match.end()
    if not steps or end != len(path) or steps[0][0] is None or path.startswith("."):
        raise SceneError("not a key path like objects[0].material.kd", file=source, key=path)
    return steps


def scene_from_dict(data: dict, source: str = "<dict>", base_dir=None) -> Scene:
    """Build a Scene from the same structure a TOML file parses to (lists may be tuples).

    source names the data in error messages; base_dir is where relative mesh paths start
    (default: the current directory).
    """
    reader = _Reader(source, Path.cwd() if base_dir is None else Path(base_dir))
    _check_nesting(data, reader)
    return reader.scene(data)


def with_lens(camera: Camera, values: dict, source: str) -> Camera:
    """A copy of `camera` with the thin-lens keys in `values` ("aperture", "focus_distance")
    set and checked as a scene file's [camera] keys are (a SceneError naming the key): the
    command line's --aperture and --focus-distance."""
    camera = dataclasses.replace(camera)
    _Reader(source, Path.cwd()).lens(values, camera, "")
    return camera


def _check_nesting(data: Any, reader: "_Reader") -> None:
    """Refuse arrays and tables nested more than MAX_NESTING levels (the top-level table is
    level 1), naming the key path where it happens. Walked with a stack, not recursion, so
    that data nested thousands deep is refused rather than overflowing Python's stack."""
    stack = [(data, "", 1)]
    while stack:
        value, path, depth = stack.pop()
        if isinstance(value, dict):
            children = [(v, _join(path, str(k))) for k, v in value.items()]
        elif isinstance(value, (list, tuple)):
            children = [(v, f"{path}[{i}]") for i, v in enumerate(value)]
        else:
            continue
        if depth > MAX_NESTING:
            shown = path if len(path) <= 60 else path[:57] + "..."
            reader.fail(shown, f"arrays or tables nested more than {MAX_NESTING} levels deep")
        stack.extend((v, p, depth + 1) for v, p in children)


def _toml_syntax_reason(exc: tomllib.TOMLDecodeError) -> str:
    """tomllib says "Invalid value (at line 3, column 7)"; we say where first."""
    message = str(exc)
    match = re.search(r"\s*\(at line (\d+), column (\d+)\)$", message)
    if match:
        what = message[:match.start()]
        return f"TOML syntax error at line {match[1]}, column {match[2]}: {what}"
    match = re.search(r"\s*\(at end of document\)$", message)
    if match:
        return f"TOML syntax error at end of file: {message[:match.start()]}"
    return f"TOML syntax error: {message}"


# --------------------------------------------------------------------------- value checks

def describe_value(value: Any) -> str:
    """What a value is, for "expected X, got Y" messages."""
    if isinstance(value, bool):
        return f"a boolean ({str(value).lower()})"
    if isinstance(value, numbers.Integral):
        return f"an integer ({value})"
    if isinstance(value, numbers.Real):
        return f"a number ({show_number(float(value))})"
    if isinstance(value, str):
        shown = value if len(value) <= 30 else value[:27] + "..."
        return f"a string ({shown!r})"
    if isinstance(value, (list, tuple)):
        return f"a list of {len(value)} item{'' if len(value) == 1 else 's'}"
    if isinstance(value, dict):
        return "a table"
    return f"a {type(value).__name__} ({value})"




def _show_vec(v) -> str:
    return "[" + ", ".join(show_number(float(x)) for x in v) + "]"


def _is_number(value: Any) -> bool:
    return isinstance(value, numbers.Real) and not isinstance(value, bool)


def unknown_choice(what: str, value: str, known) -> str:
    """'unknown shading 'smooth'; expected one of: flat, gouraud, phong' (+ a suggestion)."""
    known = list(known)
    close = difflib.get_close_matches(value, known, n=1, cutoff=0.6)
    hint = f"did you mean {close[0]!r}? " if close else ""
    return f"unknown {what} {value!r}; {hint}expected one of: {', '.join(known)}"


def unknown_key(key: str, known) -> str:
    known = list(known)
    close = difflib.get_close_matches(key, known, n=1, cutoff=0.6)
    if close:
        return f"unknown key; did you mean {close[0]!r}?"
    return f"unknown key; known keys here: {', '.join(known)}"


def _no_such(what: str, value: str, known, listing: str) -> str:
    """'no material named 'rd'; did you mean 'red'? [materials] defines: red, blue'."""
    known = list(known)
    close = difflib.get_close_matches(value, known, n=1, cutoff=0.6)
    hint = f"did you mean {close[0]!r}? " if close else ""
    return f"no {what} named {value!r}; {hint}{listing}: {', '.join(known)}"


def _join(path: str, key: str) -> str:
    return f"{path}.{key}" if path else key


# --------------------------------------------------------------------------- the reader

class TableReader:
    """Checks of parsed TOML's tables and values, each failing as one line: `error(reason,
    file=source, key=KEY.PATH)` (SceneError for scenes; renderer/batch/job_file.py reads job
    files with it too)."""

    def __init__(self, source: str, error: type[UserError] = SceneError):
        self.source = source
        self.error = error

    def fail(self, key: str | None, reason: str) -> NoReturn:
        raise self.error(reason, file=self.source, key=key or None)

    # ---- tables and scalars

    def table(self, value: Any, path: str, known) -> dict:
        """A table whose keys must all be in `known`."""
        if not isinstance(value, dict):
            self.fail(path, f"expected a table, got {describe_value(value)}")
        for key in value:
            if key not in known:
                self.fail(_join(path, str(key)), unknown_key(str(key), known))
        return value

    def list_of_tables(self, value: Any, path: str, toml_name: str) -> list:
        if not isinstance(value, (list, tuple)) or not all(isinstance(v, dict) for v in value):
            self.fail(path, f"expected a list of tables ([[{toml_name}]]), "
                            f"got {describe_value(value)}")
        return list(value)

    def to_float(self, value, path: str) -> float:
        try:
            return float(value)
        except OverflowError:          # TOML integers are unbounded
            self.fail(path, f"number too large: {str(value)[:20]}...")

    def float32_number(self, value, path: str, item: int | None = None) -> float:
        """A number (or list item `item`) as a float that is finite and within MAX_NUMBER."""
        x = self.to_float(value, path)
        if not math.isfinite(x):
            self.fail(path, f"expected a finite number, got {show_number(x)}" if item is None else
                      f"expected finite numbers, item {item} is {show_number(x)}")
        if abs(x) > MAX_NUMBER:
            self.fail(path, f"{show_number(x)} is {TOO_LARGE}" if item is None else
                      f"item {item} is {show_number(x)}, {TOO_LARGE}")
        return x

    def number(self, value: Any, path: str, *, minimum: float | None = None,
               above: float | None = None) -> float:
        if not _is_number(value):
            self.fail(path, f"expected a number, got {describe_value(value)}")
        x = self.float32_number(value, path)
        if minimum is not None and x < minimum:
            self.fail(path, f"must be >= {minimum:g}, got {x:g}")
        if above is not None and x <= above:
            self.fail(path, f"must be > {above:g}, got {x:g}")
        return x

    def integer(self, value: Any, path: str, minimum: int, maximum: int | None) -> int:
        if isinstance(value, bool) or not isinstance(value, numbers.Integral):
            self.fail(path, f"expected an integer, got {describe_value(value)}")
        if value < minimum:
            self.fail(path, f"must be >= {minimum}, got {value}")
        if maximum is not None and value > maximum:
            self.fail(path, f"must be <= {maximum}, got {value}")
        return int(value)

    def vec3(self, value: Any, path: str, *, minimum: float | None = None,
             scalar_ok: bool = False) -> tuple[float, float, float]:
        """A list of 3 finite numbers (or, where scalar_ok, one number meaning all three)."""
        return self.numbers(value, path, 3, minimum=minimum, scalar_ok=scalar_ok)

    def numbers(self, value: Any, path: str, count: int, *, minimum: float | None = None,
                scalar_ok: bool = False) -> tuple[float, ...]:
        """A list of `count` finite numbers (or, where scalar_ok, one number meaning all)."""
        expected = f"a number or a list of {count} numbers" if scalar_ok else f"a list of {count} numbers"
        if scalar_ok and _is_number(value):
            value = [value] * count
        if not isinstance(value, (list, tuple)) or len(value) != count:
            self.fail(path, f"expected {expected}, got {describe_value(value)}")
        components = []
        for i, item in enumerate(value):
            if not _is_number(item):
                self.fail(path, f"expected {expected}, item {i} is {describe_value(item)}")
            x = self.float32_number(item, path, i)
            if minimum is not None and x < minimum:
                self.fail(path, f"must be >= {minimum:g} in every component, "
                                f"item {i} is {show_number(x)}")
            components.append(x)
        return tuple(components)

    def colour(self, value: Any, path: str) -> tuple[float, float, float]:
        """Linear RGB, each component >= 0; one number means a grey."""
        return self.vec3(value, path, minimum=0.0, scalar_ok=True)

    def string(self, value: Any, path: str) -> str:
        if not isinstance(value, str):
            self.fail(path, f"expected a string, got {describe_value(value)}")
        return value

    def describe(self, value: Any) -> str:
        return describe_value(value)

    def choice(self, value: Any, path: str, what: str, known) -> str:
        text = self.string(value, path)
        if text not in known:
            self.fail(path, unknown_choice(what, text, known))
        return text

    def boolean(self, value: Any, path: str) -> bool:
        if not isinstance(value, bool):
            self.fail(path, f"expected true or false, got {describe_value(value)}")
        return value


class _Reader(TableReader):
    """Turns parsed TOML into scene dataclasses; every check raises through `fail`."""

    def __init__(self, source: str, base_dir: Path):
        super().__init__(source)
        self.base_dir = base_dir
        self.primitive_triangles = 0      # so far, for the memory check before building more
        self.tally = memory.TriangleTally()    # every mesh's, against the command's plan
        self.textures: dict = {}          # each image, checker and mesh file's texture, made once
        self.physical = False             # model = "physical": its materials' and lights' rules

    # ---- the scene

    def scene(self, data: Any) -> Scene:
        data = self.table(data, "", TOP_KEYS)
        scene = Scene()
        if "name" in data:
            scene.name = self.string(data["name"], "name")
        if "description" in data:
            self.string(data["description"], "description")
        if "model" in data:
            scene.model = self.choice(data["model"], "model", "model", MODELS)
        self.physical = scene.model == "physical"
        if "background" in data:
            scene.background = self.colour(data["background"], "background")
        if "ambient" in data:
            scene.ambient = self.colour(data["ambient"], "ambient")
        scene.camera = self.camera(data.get("camera", {}), "camera")
        materials = self.materials(data.get("materials", {}), "materials")
        for i, raw in enumerate(self.list_of_tables(data.get("lights", []), "lights", "lights")):
            light = self.light(raw, f"lights[{i}]")
            if isinstance(light, DirectionalLight):
                scene.directional_lights.append(light)
            else:
                scene.point_lights.append(light)
        raw_objects = self.list_of_tables(data.get("objects", []), "objects", "objects")
        scene.objects = [self.scene_object(raw, f"objects[{i}]", i, materials)
                         for i, raw in enumerate(raw_objects)]
        problem = scene_light_problem(scene)     # after the objects: do they cast and receive?
        if problem:
            self.fail("lights", problem)
        varyings = scene_varying_problem(scene)
        if varyings:
            self.fail(f"objects[{varyings[0]}]", varyings[1])
        self.check_names_and_parents(scene.objects, raw_objects)
        self.check_shapes(scene)
        self.check_float32_range(scene)
        scene.source = self.source
        return scene

    def check_float32_range(self, scene: Scene) -> None:
        """Refuse a scene whose composed matrices, or objects through them, leave float32's
        safe range (MAX_COMPOSED), though every number in it is within MAX_NUMBER."""
        with np.errstate(all="ignore"):
            frame = scene.matrices(1, 1)
            clip_from_eye = frame.projection @ frame.view
            if not _within(clip_from_eye):
                self.fail("camera", f"its projection matrix has entries beyond "
                                    f"{MAX_COMPOSED:g}, more than the GPU's float32 arithmetic "
                                    f"holds safely; widen fov_y or height, or bring near and far "
                                    f"closer to 1")
            for i, (obj, matrices) in enumerate(zip(scene.objects, frame.objects)):
                corners = _box_corners(obj.mesh.positions)
                clip = (clip_from_eye @ matrices.model @ corners.T).T
                if not (_within(matrices.model) and _within(matrices.normal) and _within(clip)):
                    self.fail(f"objects[{i}]", f"its transform (with its parents') takes it "
                                               f"beyond {MAX_COMPOSED:g} in the GPU's float32 "
                                               f"coordinates; scale, translate or the camera "
                                               f"put it too far away or make it too large")

    def camera(self, raw: Any, path: str) -> Camera:
        raw = self.table(raw, path, CAMERA_KEYS)
        cam = Camera()
        key = lambda k: _join(path, k)   # noqa: E731 - one-line path helper
        if "eye" in raw:
            cam.eye = self.vec3(raw["eye"], key("eye"))
        if "look" in raw:
            cam.look = self.vec3(raw["look"], key("look"))
        if "up" in raw:
            cam.up = self.vec3(raw["up"], key("up"))
        if "projection" in raw:
            cam.projection = self.choice(raw["projection"], key("projection"), "projection",
                                         PROJECTIONS)
        if "fov_y" in raw:
            cam.fov_y = self.number(raw["fov_y"], key("fov_y"))
            if not 0.0 < cam.fov_y < 180.0:
                self.fail(key("fov_y"), f"must be between 0 and 180 degrees (both excluded), "
                                        f"got {cam.fov_y:g}")
        if "height" in raw:
            cam.height = self.number(raw["height"], key("height"), above=0.0)
        if "near" in raw:
            cam.near = self.number(raw["near"], key("near"))
        if "far" in raw:
            cam.far = self.number(raw["far"], key("far"))
        if "reversed_z" in raw:
            cam.reversed_z = self.boolean(raw["reversed_z"], key("reversed_z"))
        if "shutter" in raw:
            cam.shutter = self.shutter(raw["shutter"], key("shutter"))

        view = np.subtract(cam.eye, cam.look)
        if not np.any(view):
            self.fail(key("look"), f"is the same point as {key('eye')}; the camera needs "
                                   f"eye - look to be a direction")
        # Up parallel to the view is allowed: transforms.look_at falls back to another axis.
        if not np.any(cam.up):
            self.fail(key("up"), "must not be zero length; up says which way is up in the image")
        if cam.projection == "perspective" and cam.near <= 0:
            self.fail(key("near"), f"must be > 0 for a perspective camera, got {cam.near:g}")
        if cam.far <= cam.near:
            self.fail(key("far"), f"must be greater than near ({cam.near:g}), got {cam.far:g}")
        self.lens(raw, cam, path)
        return cam

    def lens(self, raw: dict, cam: Camera, path: str) -> None:
        """The thin lens's keys (docs/scene-format.md, "Depth of field") onto `cam`. The
        focus distance's inverse is a float32 uniform: it must be at least 1 / MAX_NUMBER."""
        key = lambda k: _join(path, k)   # noqa: E731
        if "aperture" in raw:
            cam.aperture = self.number(raw["aperture"], key("aperture"), minimum=0.0)
            if cam.projection == "parallel" and cam.aperture > 0.0:
                self.fail(key("aperture"), f"must be 0 with a parallel camera, got "
                                           f"{cam.aperture:g}: a lens focuses rays from one "
                                           f"eye, and a parallel camera has none")
        if "focus_distance" in raw:
            cam.focus_distance = self.number(raw["focus_distance"], key("focus_distance"),
                                             above=0.0)
            if cam.focus_distance < 1.0 / MAX_NUMBER:
                self.fail(key("focus_distance"), f"must be >= {1.0 / MAX_NUMBER:g} (its inverse "
                                                 f"must fit the GPU's float32 arithmetic), got "
                                                 f"{cam.focus_distance:g}")
    def shutter(self, value: Any, path: str) -> tuple[float, float]:
        """The ray tracer's shutter [open, close] (motion blur): two finite numbers, open <= close."""
        if not isinstance(value, (list, tuple)) or len(value) != 2:
            self.fail(path, f"expected a list of 2 numbers [open, close], got {describe_value(value)}")
        open_, close = (self.number(x, f"{path}[{i}]") for i, x in enumerate(value))
        if close < open_:
            self.fail(path, f"negative shutter interval: close {show_number(close)} is before open "
                            f"{show_number(open_)}; the shutter is [open, close] with open <= close")
        return open_, close

    def materials(self, raw: Any, path: str) -> dict[str, Material]:
        if not isinstance(raw, dict):
            self.fail(path, f"expected a table of named materials ([materials.NAME]), "
                            f"got {describe_value(raw)}")
        return {name: self.material(value, _join(path, name)) for name, value in raw.items()}

    def material(self, raw: Any, path: str) -> Material:
        raw = self.table(raw, path, MATERIAL_KEYS)
        mat = Material()
        for coefficient in ("ka", "kd", "ks"):
            if coefficient in raw:
                setattr(mat, coefficient, self.colour(raw[coefficient], _join(path, coefficient)))
        if "n" in raw:
            mat.n = self.number(raw["n"], _join(path, "n"), minimum=0.0)
        if "two_sided" in raw:
            mat.two_sided = self.boolean(raw["two_sided"], _join(path, "two_sided"))
        if "shading" in raw:
            mat.shading = self.choice(raw["shading"], _join(path, "shading"), "shading",
                                      SHADING_MODES)
        for coefficient in ("kr", "kt", "emission"):
            if coefficient in raw:
                setattr(mat, coefficient, self.colour(raw[coefficient], _join(path, coefficient)))
        if "ior" in raw:
            mat.ior = self.number(raw["ior"], _join(path, "ior"), above=0.0)
        if "fresnel" in raw:
            mat.fresnel = self.choice(raw["fresnel"], _join(path, "fresnel"), "Fresnel mode", FRESNEL_MODES)
        elif self.physical:
            mat.fresnel = "exact"                        # the physical model's default
        if self.physical and max(mat.kd) > 1.0:
            self.fail(_join(path, "kd"), f"is a reflectance in the physical model (model = \"physical\"): "
                                         f"at most 1 in each channel, got {max(mat.kd):g}")
        if "gloss" in raw:
            mat.gloss = self.gloss(raw["gloss"], _join(path, "gloss"))
        if "texture" in raw:
            mat.texture = read_texture(self, raw["texture"], _join(path, "texture"), self.textures)
        channel = energy_excess(mat.kr, mat.kt)
        if channel is not None:
            where = _join(path, "kt" if "kt" in raw else "kr")
            self.fail(where, f"kr + kt is {mat.kr[channel] + mat.kt[channel]:g} in channel "
                             f"{'rgb'[channel]}; the energy rule is kr + kt <= 1 in each channel "
                             f"(the reflected and refracted rays together carry at most the "
                             f"light that arrives)")
        return mat

    def gloss(self, value: Any, path: str) -> float:
        """A Phong-lobe exponent: a number >= 0, or inf (TOML's `inf`), the mirror."""
        x = self.to_float(value, path) if _is_number(value) else 0.0
        if x == math.inf:
            return x
        if math.isnan(x) or x < 0:
            self.fail(path, f"must be a number >= 0 or inf (a mirror), got {show_number(x)}")
        return self.number(value, path)

    def light(self, raw: dict, path: str) -> DirectionalLight | PointLight:
        if "type" not in raw:
            self.fail(_join(path, "type"), f"missing; expected one of: {', '.join(LIGHT_TYPES)}")
        kind = self.choice(raw["type"], _join(path, "type"), "light type", LIGHT_TYPES)
        for k in raw:
            owners = [t for t in LIGHT_TYPES if t != kind and k in LIGHT_KEYS[t]]
            if k not in LIGHT_KEYS[kind] and owners:
                self.fail(_join(path, k), f"belongs to {owners[0]} lights, not {kind} ones; "
                                          f"keys here: {', '.join(LIGHT_KEYS[kind])}")
        raw = self.table(raw, path, LIGHT_KEYS[kind])
        key = lambda k: _join(path, k)   # noqa: E731
        if kind == "directional":
            light = DirectionalLight()
            if "direction" in raw:
                light.direction = self.vec3(raw["direction"], key("direction"))
                if not any(light.direction):
                    self.fail(key("direction"), "must not be zero length")
        else:
            light = PointLight()
            if "position" in raw:
                light.position = self.vec3(raw["position"], key("position"))
            if "attenuation" in raw and self.physical:
                self.fail(key("attenuation"), "the physical model's point lights fall off as the inverse "
                                              "square (model = \"physical\"); leave attenuation out")
            if "attenuation" in raw:
                light.attenuation = self.vec3(raw["attenuation"], key("attenuation"), minimum=0.0)
                if not any(light.attenuation):
                    self.fail(key("attenuation"), "must not be all zero: the light is divided "
                                                  "by c + l d + q d^2")
            light.area = self.light_area(raw, path)
        if "intensity" in raw:
            light.intensity = self.colour(raw["intensity"], key("intensity"))
        light.shadow = self.shadow(raw, path)
        return light

    def light_area(self, raw: dict, path: str) -> LightArea | None:
        """A point light's area (scene.LightArea) from its area keys: `area` names the shape,
        which then needs its extent (`size` for a rectangle, `radius` for a disc or a sphere)
        and takes nothing of another shape's; `normal` (rectangle, disc) defaults to [0, -1, 0]."""
        key = lambda k: _join(path, k)   # noqa: E731
        if "area" not in raw:
            given = next((k for k in AREA_KEYS if k in raw), None)
            if given:
                self.fail(key(given), f"is for area lights; add area = one of "
                                      f"{', '.join(map(repr, AREA_SHAPES))}")
            return None
        shape = self.choice(raw["area"], key("area"), "area shape", AREA_SHAPES)
        extent = "size" if shape == "rectangle" else "radius"
        for k in AREA_KEYS[1:]:
            if k in raw and k not in AREA_SHAPE_KEYS[shape]:
                owners = " and ".join(s for s in AREA_SHAPES if k in AREA_SHAPE_KEYS[s])
                self.fail(key(k), f"is for {owners} lights, not a {shape}; a {shape} light "
                                  f"takes {' and '.join(AREA_SHAPE_KEYS[shape])}")
        if extent not in raw:
            self.fail(key(extent), f"missing; a {shape} light needs "
                                   f"{'size = [w, h]' if shape == 'rectangle' else 'radius = r'}")
        area = LightArea(shape)
        if shape == "rectangle":
            area = dataclasses.replace(area, size=self.numbers(raw["size"], key("size"), 2, minimum=0.0))
        else:
            area = dataclasses.replace(area, radius=self.number(raw["radius"], key("radius"), minimum=0.0))
        if "normal" in raw:
            normal = self.vec3(raw["normal"], key("normal"))
            if not any(normal):
                self.fail(key("normal"), "must not be zero length: it says which way the "
                                         f"{shape} faces")
            area = dataclasses.replace(area, normal=normal)
        return area

    def shadow(self, raw: dict, path: str) -> Shadow:
        """A light's shadow-map settings (shadow_settings.Shadow) from its shadow keys. A
        `shadow_bias` table sets the terms it names; the others keep the automatic rule's
        value for the light's filter (auto_bias), so that one term can be changed alone."""
        key = lambda k: _join(path, k)   # noqa: E731
        shadow = Shadow()
        if "shadows" in raw:
            shadow = Shadow(enabled=self.boolean(raw["shadows"], key("shadows")))
        if "shadow_resolution" in raw:
            shadow = dataclasses.replace(shadow, resolution=self.shadow_resolution(
                raw["shadow_resolution"], key("shadow_resolution")))
        if "shadow_filter" in raw:
            shadow = dataclasses.replace(shadow, filter=self.choice(
                raw["shadow_filter"], key("shadow_filter"), "shadow filter", FILTERS))
        if "shadow_bias" in raw:
            where = key("shadow_bias")
            if not isinstance(raw["shadow_bias"], dict):
                self.fail(where, f"expected a table such as {{normal = 1.0, constant = 0.25}} "
                                 f"(texels), got {describe_value(raw['shadow_bias'])}")
            given = self.table(raw["shadow_bias"], where, BIAS_KEYS)
            terms = {name: self.number(value, _join(where, name), minimum=0.0)
                     for name, value in given.items()}
            for name, value in terms.items():
                if value > MAX_BIAS_TEXELS:
                    self.fail(_join(where, name), f"must be <= {MAX_BIAS_TEXELS:g} texels, got "
                                                  f"{value:g}")
            shadow = dataclasses.replace(
                shadow, bias=dataclasses.replace(auto_bias(shadow.filter), **terms))
        return shadow

    def shadow_resolution(self, value: Any, path: str) -> int | None:
        """A tile side from shadow_settings.RESOLUTIONS, or "auto" (None: auto_resolution)."""
        if value == "auto" and isinstance(value, str):
            return None
        if isinstance(value, bool) or not isinstance(value, numbers.Integral) \
                or value not in RESOLUTIONS:
            self.fail(path, f"expected one of {', '.join(map(str, RESOLUTIONS))} (texels on a "
                            f"side of the map) or \"auto\", got {describe_value(value)}")
        return int(value)

    def scene_object(self, raw: dict, path: str, index: int,
                     materials: dict[str, Material]) -> SceneObject:
        raw = self.table(raw, path, OBJECT_KEYS)
        key = lambda k: _join(path, k)   # noqa: E731
        name = self.string(raw["name"], key("name")) if "name" in raw else f"object{index}"
        if "mesh" in raw and "shape" in raw:
            self.fail(key("shape"), "give either mesh or shape, not both: a shape's mesh is "
                                    "its own tessellation")
        if "mesh" not in raw and "shape" not in raw:
            self.fail(key("mesh"), "missing; give mesh = {primitive = \"...\"}, "
                                   "mesh = {file = \"...\"} or shape = {type = \"sphere\"}")
        shape = None
        if "shape" in raw:
            shape, mesh = self.shape(raw["shape"], key("shape"))
        else:
            mesh = self.mesh(raw["mesh"], key("mesh"))
        material = Material()
        if "material" in raw:
            material = self.object_material(raw["material"], key("material"), materials)
        if not material.textured and "file" in raw.get("mesh", {}):
            texture = self.mesh_file_texture(raw["mesh"]["file"], key("mesh.file"))
            if texture is not None:
                material = dataclasses.replace(material, texture=texture)
        if material.textured and mesh.uvs is None:
            self.fail(key("material"), f"has a texture, but the mesh ({mesh.source}) has no "
                                       f"texture coordinates; give the file UVs (OBJ vt, PLY "
                                       f"u v, glTF TEXCOORD_0) or use a primitive or a shape")
        obj = SceneObject(name=name, mesh=mesh, material=material,
                          transform=self.transform(raw, path), shape=shape)
        if "parent" in raw:
            obj.parent = self.string(raw["parent"], key("parent"))
        if "cull" in raw:
            obj.cull = self.choice(raw["cull"], key("cull"), "cull mode", CULL_MODES)
        for flag in ("casts_shadows", "receives_shadows"):
            if flag in raw:
                setattr(obj, flag, self.boolean(raw[flag], key(flag)))
        for motion in ("velocity", "angular_velocity"):          # motion blur, the ray tracer's
            if motion in raw:
                setattr(obj, motion, self.vec3(raw[motion], key(motion)))
        if "tessellation" in raw:
            obj.tessellation = self.tessellation(raw["tessellation"], key("tessellation"), obj)
        return obj

    def tessellation(self, raw: Any, path: str, obj: SceneObject):
        """An object's tessellation stages (renderer/core/tessellation.py): `spacing` ("equal",
        "fractional_even", "fractional_odd"), `error` in pixels or a fixed `level` (1 to 64).
        An analytic sphere's points go on the sphere, a mesh's on its PN triangles; not with a
        texture or shadow maps yet."""
        if not isinstance(raw, dict):
            self.fail(path, f"expected a table such as {{error = 0.25}} or {{level = 8}}, got {describe_value(raw)}")
        raw = self.table(raw, path, TESSELLATION_KEYS)
        if obj.shape is not None and not isinstance(obj.shape, Sphere):
            self.fail(path, "a plane is flat: only an analytic sphere or a mesh is tessellated")
        if obj.material.textured:
            self.fail(path, "a tessellated object cannot be textured yet (a sphere's seam, a mesh's "
                            "UVs across its patches)")
        if obj.receives_shadows and obj.shape is None:
            self.fail(path, "a tessellated mesh does not look shadow maps up yet (they hold its flat "
                            "triangles): give the object receives_shadows = false")
        settings = tessellation.Tessellation(surface="sphere" if isinstance(obj.shape, Sphere) else "pn_triangles")
        if "displacement" in raw:
            settings = dataclasses.replace(settings, surface="displaced",
                                           displacement=self.displacement(raw["displacement"],
                                                                          _join(path, "displacement"), obj))
        if "spacing" in raw:
            word = self.choice(raw["spacing"], _join(path, "spacing"), "spacing", tuple(tessellation.SPACING_WORDS))
            settings = dataclasses.replace(settings, spacing=tessellation.SPACING_WORDS[word])
        if "error" in raw and "level" in raw:
            self.fail(path, "give either error (pixels, levels by need) or level (fixed), not both")
        if "error" in raw:
            settings = dataclasses.replace(settings, error=self.number(raw["error"], _join(path, "error"), above=0.0))
        if "level" in raw:
            level = self.number(raw["level"], _join(path, "level"), minimum=1.0)
            if level > tessellation.MAX_LEVEL:
                self.fail(_join(path, "level"), f"must be at most {tessellation.MAX_LEVEL:g} "
                                                f"(GL_MAX_TESS_GEN_LEVEL), got {level:g}")
            settings = dataclasses.replace(settings, level=level)
        return settings

    def displacement(self, raw: Any, path: str, obj: SceneObject) -> "tessellation.Displacement":
        """A mesh's displacement: `image` (a height image, its red channel read as linear 0 to 1),
        `scale` (object units for a height of 1), and where it is read: st = uv * `uv_scale` +
        `uv_offset` (as a material texture's)."""
        if not isinstance(raw, dict):
            self.fail(path, f"expected a table such as {{image = \"textures/heights.png\", scale = 0.2}}, "
                            f"got {describe_value(raw)}")
        raw = self.table(raw, path, DISPLACEMENT_KEYS)
        if obj.shape is not None:
            self.fail(path, "displaces a mesh (its points along its normals); an analytic shape has none to move")
        if obj.mesh.uvs is None:
            self.fail(path, f"the mesh ({obj.mesh.source or 'made in code'}) has no texture coordinates "
                            f"to read the height image at")
        for key in ("image", "scale"):
            if key not in raw:
                self.fail(_join(path, key), "is required")
        texture = read_image(self, raw["image"], _join(path, "image"), "linear", self.textures)
        return tessellation.Displacement(
            texture, self.number(raw["scale"], _join(path, "scale")),
            tuple(self.numbers(raw.get("uv_scale", (1.0, 1.0)), _join(path, "uv_scale"), 2)),
            tuple(self.numbers(raw.get("uv_offset", (0.0, 0.0)), _join(path, "uv_offset"), 2)))

    def object_material(self, raw: Any, path: str, materials: dict[str, Material]) -> Material:
        if isinstance(raw, str):
            if raw not in materials:
                if not materials:
                    self.fail(path, f"no material named {raw!r}: the file defines no "
                                    f"[materials.NAME] tables")
                self.fail(path, _no_such("material", raw, materials, "[materials] defines"))
            return materials[raw]
        if isinstance(raw, dict):
            return self.material(raw, path)
        self.fail(path, f"expected a material name (string) or an inline table, "
                        f"got {describe_value(raw)}")

    def transform(self, raw: dict, path: str) -> Transform:
        key = lambda k: _join(path, k)   # noqa: E731
        t = Transform()
        if "scale" in raw:
            t.scale = self.vec3(raw["scale"], key("scale"), scalar_ok=True)
            if min(t.scale) < 0:
                self.fail(key("scale"), f"must be >= 0 in every component, got "
                                        f"{_show_vec(t.scale)}: a negative scale turns the "
                                        f"object inside out")
        if "shear" in raw:
            shear = self.table(raw["shear"], key("shear"), transforms.SHEAR_FACTORS)
            t.shear = {name: self.number(v, _join(key("shear"), name)) for name, v in shear.items()}
            det = float(np.linalg.det(transforms.shear(**t.shear)[:3, :3]))
            if det <= MIN_DETERMINANT:
                effect = "singular" if abs(det) <= MIN_DETERMINANT else "a mirror (inside out)"
                self.fail(key("shear"), f"makes the model matrix {effect}: its determinant is "
                                        f"{det:.3g}; it must stay > 0")
        if "rotate" in raw:
            t.rotate = self.vec3(raw["rotate"], key("rotate"))
        if "translate" in raw:
            t.translate = self.vec3(raw["translate"], key("translate"))
        return t

    # ---- analytic shapes

    def shape(self, raw: Any, path: str) -> tuple[Sphere | Plane, Mesh]:
        """An analytic shape and the mesh the rasteriser draws for it (renderer/core/shapes.py),
        counted with the primitives before it is built."""
        if not isinstance(raw, dict):
            self.fail(path, f"expected a table such as {{type = \"sphere\", radius = 1.0}}, "
                            f"got {describe_value(raw)}")
        if "type" not in raw:
            self.fail(_join(path, "type"), f"missing; expected one of: {', '.join(SHAPE_TYPES)}")
        kind = self.choice(raw["type"], _join(path, "type"), "shape type", SHAPE_TYPES)
        raw = self.table(raw, path, SHAPE_KEYS[kind])
        key = lambda k: _join(path, k)   # noqa: E731
        if kind == "sphere":
            shape = Sphere()
            if "centre" in raw:
                shape = Sphere(self.vec3(raw["centre"], key("centre")), shape.radius)
            if "radius" in raw:
                shape = Sphere(shape.centre, self.number(raw["radius"], key("radius"), above=0.0))
            subdivisions = shapes.SPHERE_SUBDIVISIONS
            if "subdivisions" in raw:
                subdivisions = self.integer(raw["subdivisions"], key("subdivisions"),
                                            *PRIMITIVE_LIMITS["icosphere"]["subdivisions"][1:])
            args = {"subdivisions": subdivisions}
        else:
            shape = Plane()
            if "normal" in raw:
                normal = self.vec3(raw["normal"], key("normal"))
                if not any(normal):
                    self.fail(key("normal"), "must not be zero length: the plane is P·N + d = 0")
                shape = Plane(normal, shape.offset)
            if "offset" in raw:
                shape = Plane(shape.normal, self.number(raw["offset"], key("offset")))
            args = {"size": shapes.PLANE_SIZE, "segments": shapes.PLANE_SEGMENTS}
            if "size" in raw:
                args["size"] = self.number(raw["size"], key("size"), above=0.0)
            if "segments" in raw:
                args["segments"] = self.integer(raw["segments"], key("segments"),
                                                *PRIMITIVE_LIMITS["plane"]["segments"][1:])
            n = np.asarray(shape.normal, dtype=np.float64)
            foot = abs(shape.offset) / float(np.linalg.norm(n))
            if foot + args["size"] > MAX_NUMBER:
                self.fail(path, f"the plane's square reaches {show_number(foot + args['size'])} "
                                f"from the origin, beyond |x| <= {MAX_NUMBER:g} (float32)")
        self.primitive_triangles += shapes.TRIANGLES[kind](**args)
        too_much = memory.over_limit(self.primitive_triangles * memory.SCENE_BYTES_PER_TRIANGLE,
                                     loading=True)
        if too_much:
            self.fail(path, f"the scene's primitives up to here make up to "
                            f"{self.primitive_triangles:,} triangles: building them {too_much}")
        too_much = self.tally.add(shapes.TRIANGLES[kind](**args), shape=True,
                                  build_bytes_per_triangle=memory.SCENE_BYTES_PER_TRIANGLE)
        if too_much:
            self.fail(path, too_much)
        if kind == "sphere":
            mesh = shapes.sphere_mesh(shape, **args)
        else:
            mesh = shapes.plane_mesh(shape, **args)
        return shape, mesh

    def check_shapes(self, scene: Scene) -> None:
        """Each analytic shape must survive its world transform (scene.world_shape): a sphere
        only a similarity, a plane anything that does not flatten it."""
        for i, (obj, model) in enumerate(zip(scene.objects, scene.world_matrices())):
            if obj.shape is not None:
                try:
                    world_shape(obj.shape, model)
                except ValueError as exc:
                    self.fail(f"objects[{i}].shape", str(exc))

    # ---- meshes

    def mesh(self, raw: Any, path: str) -> Mesh:
        if not isinstance(raw, dict):
            self.fail(path, f"expected a table such as {{primitive = \"uv_sphere\"}} or "
                            f"{{file = \"meshes/knot.obj\"}}, got {describe_value(raw)}")
        if "primitive" in raw and "file" in raw:
            self.fail(path, "give either primitive or file, not both")
        if "file" in raw:
            self.table(raw, path, MESH_FILE_KEYS)
            crease_angle = DEFAULT_CREASE_ANGLE
            if "crease_angle" in raw:
                crease_angle = self.crease_angle(raw["crease_angle"], _join(path, "crease_angle"))
            return self.mesh_file(raw["file"], _join(path, "file"), crease_angle)
        if "primitive" in raw:
            if "crease_angle" in raw:
                self.fail(_join(path, "crease_angle"),
                          "is for mesh files (mesh = { file = ... }); a primitive has exact "
                          "normals, its flat faces already separate")
            return self.primitive(raw, path)
        self.fail(path, "needs a primitive or a file key")

    def primitive(self, raw: dict, path: str) -> Mesh:
        name = self.choice(raw["primitive"], _join(path, "primitive"), "primitive", PRIMITIVES)
        build = PRIMITIVES[name]
        parameters = list(inspect.signature(build).parameters)
        args = self.table(raw, path, ["primitive", *parameters])
        limits = PRIMITIVE_LIMITS.get(name, {})
        kwargs = {}
        for arg, value in args.items():
            if arg == "primitive":
                continue
            arg_path = _join(path, arg)
            is_int, low, high = limits.get(arg, (False, None, None))
            if is_int:
                kwargs[arg] = self.integer(value, arg_path, low, high)
            elif low is not None:
                kwargs[arg] = self.number(value, arg_path, above=low)
            else:
                kwargs[arg] = self.number(value, arg_path)
        # Refused before it is built: a few segment counts at their maxima make tens of
        # millions of triangles (renderer/core/memory.py).
        self.primitive_triangles += PRIMITIVE_TRIANGLES[name](**kwargs)
        too_much = memory.over_limit(self.primitive_triangles * memory.SCENE_BYTES_PER_TRIANGLE,
                                     loading=True)
        if too_much:
            self.fail(path, f"the scene's primitives up to here make up to "
                            f"{self.primitive_triangles:,} triangles: building them {too_much}")
        too_much = self.tally.add(PRIMITIVE_TRIANGLES[name](**kwargs),
                                  build_bytes_per_triangle=memory.SCENE_BYTES_PER_TRIANGLE)
        if too_much:
            self.fail(path, too_much)
        mesh = build(**kwargs)
        if mesh.triangle_count == 0:
            self.fail(path, "the primitive has no triangles with these arguments")
        mesh.recipe = (name, kwargs)
        return mesh

    def crease_angle(self, value: Any, path: str) -> float:
        angle = self.number(value, path)
        if not 0.0 < angle <= 180.0:
            self.fail(path, f"must be between 0 (excluded) and 180 degrees (180: smooth across "
                            f"every edge), got {angle:g}")
        return angle

    def mesh_file(self, value: Any, path: str, crease_angle: float = DEFAULT_CREASE_ANGLE) -> Mesh:
        return load_mesh(self.find_file(value, path, "mesh"), source=self.source, key=path,
                         crease_angle=crease_angle, tally=self.tally)

    def mesh_file_texture(self, value: Any, path: str) -> MaterialTexture | None:
        """A glTF/GLB mesh file's base-colour texture (renderer/core/gltf_texture.py), made
        once per file; None for other files and for a glTF without one."""
        file = self.find_file(value, path, "mesh")
        if file.suffix.lower() not in (".glb", ".gltf"):
            return None
        cache_key = ("mesh file", str(file.resolve()))
        if cache_key not in self.textures:
            self.textures[cache_key] = base_colour_texture(file, source=self.source, key=path)
        return self.textures[cache_key]

    def find_file(self, value: Any, path: str, what: str) -> Path:
        """A file a scene names (a mesh, an image): relative paths start at the scene file's
        folder, then at the built-in assets folder (so any scene can use the built-in meshes
        and textures as "meshes/NAME", "textures/NAME")."""
        text = self.string(value, path)
        if not text:
            self.fail(path, f"is empty; expected {'an' if what[0] in 'aeiou' else 'a'} {what} "
                            f"file path")
        checked_path(text, file=self.source, key=path, error=SceneError)
        candidates = [Path(text)] if Path(text).is_absolute() else [self.base_dir / text]
        assets = _builtin_assets_dir()
        if assets is not None and not Path(text).is_absolute():
            candidates.append(assets / text)
        for candidate in candidates:
            checked_path(candidate, file=self.source, key=path, error=SceneError)
            if candidate.exists():
                return candidate
        looked = " and ".join(str(c.parent.resolve()) for c in candidates)
        self.fail(path, f"{what} file not found: {text!r} (looked in {looked})")

    # ---- names and parents

    def check_names_and_parents(self, objects: list[SceneObject], raw_objects: list[dict]) -> None:
        first_index: dict[str, int] = {}
        for i, obj in enumerate(objects):
            if obj.name in first_index:
                where = f"objects[{i}].name" if "name" in raw_objects[i] else f"objects[{i}]"
                self.fail(where, f"duplicate object name {obj.name!r} "
                                 f"(objects[{first_index[obj.name]}] has it too)")
            first_index[obj.name] = i
        for i, obj in enumerate(objects):
            if obj.parent is not None and obj.parent not in first_index:
                self.fail(f"objects[{i}].parent",
                          _no_such("object", obj.parent, first_index, "objects in this scene"))
        # A parent cycle is reported at the first object on it, as the chain from that object
        # back to itself. Each object is visited once (a chain of any length, no recursion):
        # walk up from each object not yet visited until a root, an object visited before,
        # or an object on this walk (a cycle).
        parent_index = [None if obj.parent is None else first_index[obj.parent] for obj in objects]
        walk_of = [-1] * len(objects)                    # which walk first visited an object
        cycles: list[list[int]] = []
        for start in range(len(objects)):
            walk, at = [], start
            while at is not None and walk_of[at] < 0:
                walk_of[at] = start
                walk.append(at)
                at = parent_index[at]
            if at is not None and walk_of[at] == start:  # came back onto this walk: a cycle
                cycles.append(walk[walk.index(at):])
        if cycles:
            first = min(min(cycle) for cycle in cycles)
            cycle = next(c for c in cycles if first in c)
            k = cycle.index(first)
            names = [objects[j].name for j in cycle[k:] + cycle[:k]] + [objects[first].name]
            if len(names) > MAX_CYCLE_SHOWN + 1:         # one line of reasonable length
                names = [*names[:MAX_CYCLE_SHOWN // 2], f"... ({len(names) - 1} objects) ...",
                         *names[-(MAX_CYCLE_SHOWN // 2):]]
            self.fail(f"objects[{first}].parent", f"parent cycle: {' -> '.join(names)}")


def _within(values) -> bool:
    values = np.asarray(values, dtype=np.float64)
    return bool(np.isfinite(values).all() and (np.abs(values) <= MAX_COMPOSED).all())


def _box_corners(positions) -> np.ndarray:
    """The 8 corners (8, 4) of the axis-aligned box around `positions`, homogeneous."""
    positions = np.asarray(positions, dtype=np.float64).reshape(-1, 3)
    if len(positions) == 0:
        return np.zeros((0, 4))
    low, high = positions.min(axis=0), positions.max(axis=0)
    corners = np.array([[(low, high)[(k >> axis) & 1][axis] for axis in range(3)]
                        for k in range(8)])
    return np.hstack([corners, np.ones((8, 1))])


def _builtin_assets_dir() -> Path | None:
    try:
        return assets_dir()
    except SceneError:
        return None
