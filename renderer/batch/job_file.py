"""Job files: TOML in, a checked `Job` out (renderer/batch/items.py), every mistake one line.

    job = read_job("job.toml")        # UserError "job.toml: scenes[1].cameras.orbit.views: ..."

docs/batch-format.md documents every key. The reader is as strict as the scene reader (it
uses its TableReader): an unknown key is an error with the closest known key suggested, and
values are checked where they stand. Every scene is read and every sweep point's overrides
applied and built here, on the driver, before anything is rendered: a bad scene, a bad
override value, an animation of a still scene or an output the output stage refuses fails
the job before its first frame, naming the job file and the key.

Bounded: the job's items and sweep points are counted from the job file alone, before any
scene is read, and a job over MAX_ITEMS items or MAX_SCENES scenes to build is refused
then, with its count (in well under a second). Each sweep point's scene is built, checked
and dropped (its SceneSource keeps the overrides and the digest), so a job holds no scenes.
"""

from __future__ import annotations

import hashlib
import itertools
import math
import re
from pathlib import Path
from typing import Any

from renderer.batch.items import (CameraSpec, Job, Output, SceneEntry, SceneSource, Setting,
                                  default_output_name)
from renderer.core import memory
from renderer.core import output_settings as stage
from renderer.core.builtin import is_scene_name
from renderer.core.jsonio import canonical_json
from renderer.core.motion import declares_motion
from renderer.core.paths import checked_path, output_stem
from renderer.core.scene import SHADING_MODES
from renderer.core.scene_file import (MAX_NUMBER, TableReader, describe_value, read_scene,
                                      read_toml, scene_from_dict, with_overrides)
from renderer.errors import OptionError, SceneError, UserError
from renderer.methods import METHODS, method_options

TOP_KEYS = ("name", "description", "seed", "size", "scenes", "settings")
SCENE_KEYS = ("scene", "name", "cameras", "sweep")
CAMERA_KINDS = ("orbit", "poses", "animation")
ORBIT_KEYS = ("views", "elevation")
POSE_KEYS = ("eye", "look", "up")
ANIMATION_KEYS = ("frames", "step", "exposure")
# The methods' options a [[settings]] table may give (their SETTING_FIELDS), in registration order.
OPTION_KEYS = tuple(dict.fromkeys(f for m in METHODS.values() for f in m.options.SETTING_FIELDS))
SETTING_KEYS = ("name", "method", "size", "background", *OPTION_KEYS, "outputs")
OUTPUT_KEYS = ("name", "format", "transfer", "bits", "dither", "halftone")
DEPTH_KEYS = ("name", "depth")
DEPTH_FORMATS = ("npy", "exr")
BACKGROUNDS = ("opaque", "transparent")

DEFAULT_SIZE = (640, 480)            # as `renderer render`
MAX_SIDE = 16384                     # pixels, as --size
MAX_COUNT = 100_000                  # orbit views, animation frames, sweep values per key
# Items in a job: each is planned on the driver (its key, files and output names checked, its
# record looked up), ~0.1 ms each: 100,000 items are planned in seconds; a typo should not
# plan a billion frames.
MAX_ITEMS = 100_000
# Scenes a job builds, one per [[scenes]] entry and sweep point: each is built and checked
# before the first frame (a few ms for a small scene), so a job is checked in bounded time.
MAX_SCENES = 10_000
SEED_LIMIT = 2 ** 64
MAX_ELEVATION = 89.0                 # degrees: camera_paths keeps the eye 1 degree off the poles
# A name that is one path component: scenes' and settings' names are parts of item keys.
NAME = re.compile(r"[A-Za-z0-9][A-Za-z0-9._-]{0,99}")


def read_job(path) -> Job:
    """The job file at `path`, read and checked (module docstring)."""
    path = checked_path(path, error=UserError)
    data = read_toml(path, "job file", UserError)
    return _JobReader(path).job(data)


def need(setting: Setting, backends) -> memory.Need:
    """What drawing a scene with `setting` on `backends` takes (renderer/core/memory.py)."""
    return METHODS[setting.method].need(setting.size, backends, setting.options)


def check_memory(scene, setting: Setting, backends) -> None:
    """A UserError when drawing `scene` with `setting` on `backends` would need more memory
    than the limit (renderer/core/memory.py)."""
    need(setting, backends).check(scene)


def _name(reader: TableReader, value: Any, key: str) -> str:
    text = reader.string(value, key)
    if not NAME.fullmatch(text):
        reader.fail(key, f"{text!r} cannot name a folder: use letters, digits, '.', '_' and '-' "
                         "(at most 100, starting with a letter or digit)")
    return text


def _unique(reader: TableReader, names: list[tuple[str, str]], what: str) -> None:
    """Each (name, key) once: a second use of a name is an error at its key."""
    seen = {}
    for name, key in names:
        if name in seen:
            reader.fail(key, f"{what} {name!r} is already {seen[name]}'s; give each its own name")
        seen[name] = key.rsplit(".", 1)[0]


class _JobReader(TableReader):
    def __init__(self, path: Path):
        super().__init__(str(path), error=UserError)
        self.path = path

    def job(self, data: dict) -> Job:
        data = self.table(data, "", TOP_KEYS)
        name = self.string(data.get("name", self.path.stem), "name")
        seed = self.integer(data.get("seed", 0), "seed", 0, SEED_LIMIT - 1)
        size = self.size(data["size"], "size") if "size" in data else DEFAULT_SIZE
        if "scenes" not in data:
            self.fail("scenes", "a job needs at least one [[scenes]] table (scene = NAME or FILE)")
        raw_settings = self.entries(data.get("settings", [{}]), "settings")
        settings = tuple(self.setting(raw, f"settings[{i}]", size) for i, raw in enumerate(raw_settings))
        _unique(self, [(s.name, f"settings[{i}].name") for i, s in enumerate(settings)], "the setting name")
        # First what each entry asks for, from the job file alone (no scene read), so that a
        # job over the limits is refused at once; then each entry's scene and sweep points.
        asked = [self.scene_request(raw, f"scenes[{i}]")
                 for i, raw in enumerate(self.entries(data["scenes"], "scenes"))]
        count = sum(len(cameras) * points for _, _, _, points, cameras in asked) * len(settings)
        if count > MAX_ITEMS:
            self.fail("scenes", f"the job has {count:,} items; at most {MAX_ITEMS:,}")
        built = sum(points for _, _, _, points, _ in asked)
        if built > MAX_SCENES:
            self.fail("scenes", f"the job has {built:,} scenes to build (one per entry and "
                                f"sweep point); at most {MAX_SCENES:,}, each built and checked "
                                f"before the first frame")
        scenes = tuple(self.scene_entry(*request, f"scenes[{i}]", settings)
                       for i, request in enumerate(asked))
        _unique(self, [(s.name, f"scenes[{i}].name") for i, s in enumerate(scenes)], "the scene name")
        return Job(str(self.path), name, seed, scenes, settings,
                   self.string(data.get("description", ""), "description"))

    def entries(self, value: Any, key: str) -> list:
        entries = self.list_of_tables(value, key, key)
        if not entries:
            self.fail(key, f"expected at least one [[{key}]] table")
        return entries

    def size(self, value: Any, key: str) -> tuple[int, int]:
        if not isinstance(value, list) or len(value) != 2:
            self.fail(key, f"expected [WIDTH, HEIGHT] in pixels, got {describe_value(value)}")
        return tuple(self.integer(v, f"{key}[{i}]", 1, MAX_SIDE) for i, v in enumerate(value))

    # ---- [[scenes]]

    def scene_request(self, raw: dict, key: str):
        """What a [[scenes]] entry asks for, checked without reading its scene: (the table,
        the scene's name or file, the sweep's axes, its point count, the cameras)."""
        raw = self.table(raw, key, SCENE_KEYS)
        if "scene" not in raw:
            self.fail(key, "needs scene = NAME (a built-in scene) or FILE (relative to the job file)")
        scene = self.string(raw["scene"], f"{key}.scene")
        axes = self.sweep_axes(raw.get("sweep"), f"{key}.sweep")
        points = math.prod(len(values) for _, values in axes)
        if points > MAX_SCENES:                # before building any of them
            self.fail(f"{key}.sweep", f"{points:,} sweep points; a job has at most "
                                      f"{MAX_SCENES:,} (each is a scene, built and checked "
                                      f"before the first frame)")
        return raw, scene, axes, points, self.cameras(raw.get("cameras"), f"{key}.cameras")

    def scene_entry(self, raw: dict, scene_name: str, axes: list, count: int, cameras,
                    key: str, settings: tuple[Setting, ...]) -> SceneEntry:
        """The entry's scene read and every sweep point built and checked (its memory for
        each setting too), one at a time: only the points' SceneSources are kept."""
        data, path = self.read_scene(scene_name, f"{key}.scene")
        points, first = [], None
        needs = [need(setting, ["gpu"]) for setting in settings]
        for overrides in self.sweep_points(axes):
            with memory.planned(*needs):       # a mesh too big for a setting: refused unbuilt
                source, scene = self.point(data, path, overrides, f"{key}.sweep")
            if first is None:                  # the entry's rules that need its scene
                first = scene
                if cameras[0].kind == "frame":
                    self.animated(f"{key}.cameras.animation", scene, settings)
            for setting in settings:
                self.memory(scene, setting, key)
            points.append(source)              # the scene itself is dropped: none is held
        name = _name(self, raw["name"], f"{key}.name") if "name" in raw else output_stem(first)
        return SceneEntry(name, tuple(points), cameras)

    def memory(self, scene, setting: Setting, key: str) -> None:
        """The GPU's memory for the scene and setting, under the limit (core/memory.py)."""
        try:
            check_memory(scene, setting, ["gpu"])
        except UserError as error:
            self.fail(key, f"setting {setting.name!r}: {error.reason}")

    def read_scene(self, text: str, key: str) -> tuple[dict, Path]:
        beside = self.path.parent / text           # a path is relative to the job file
        try:
            return read_scene(text if is_scene_name(text) and not beside.is_file() else beside)
        except SceneError as error:
            self.fail(key, error.line())

    def sweep_axes(self, raw: Any, key: str) -> list[tuple[str, list]]:
        """The sweep's axes, (key path, values) in file order; none without a sweep."""
        if raw is None:
            return []
        if not isinstance(raw, dict):
            self.fail(key, f"expected a table of key paths = [values], got {describe_value(raw)}")
        axes = list(self.flat_sweep(raw, key).items())
        if not axes:
            self.fail(key, "expected at least one key path = [values]")
        return axes

    @staticmethod
    def sweep_points(axes: list[tuple[str, list]]):
        """The sweep's points, one dict of overrides each, the first key varying slowest,
        made one at a time; one point without overrides when there is no sweep."""
        for values in itertools.product(*(values for _, values in axes)):
            yield dict(zip((path for path, _ in axes), values))

    def flat_sweep(self, raw: dict, key: str, prefix: str = "") -> dict[str, list]:
        """Key paths to their values; TOML's dotted keys (camera.aperture = [...]) arrive as
        nested tables and are joined again."""
        flat = {}
        for name, value in raw.items():
            path = f"{prefix}.{name}" if prefix else name
            if isinstance(value, dict):
                flat |= self.flat_sweep(value, key, path)
            elif not isinstance(value, list) or not value:
                self.fail(f"{key}.{path}", f"expected a list of the values to sweep, got "
                                           f"{describe_value(value)}")
            elif len(value) > MAX_COUNT:
                self.fail(f"{key}.{path}", f"{len(value)} values; at most {MAX_COUNT}")
            else:
                flat[path] = value
        return flat

    def point(self, data: dict, path: Path, overrides: dict, key: str):
        """A sweep point's SceneSource and Scene, built here so a bad value fails now."""
        try:
            changed = with_overrides(data, overrides, str(path))
            scene = scene_from_dict(changed, source=str(path), base_dir=path.parent)
        except SceneError as error:
            shown = ", ".join(f"{k} = {v!r}" for k, v in overrides.items())
            self.fail(key if overrides else key.rsplit(".", 1)[0] + ".scene",
                      f"{shown + ': ' if shown else ''}{error.line()}")
        digest = hashlib.sha256(canonical_json(changed).encode()).hexdigest()
        return SceneSource(str(path.resolve()), tuple(overrides.items()), digest), scene

    def cameras(self, raw: Any, key: str) -> tuple[CameraSpec, ...]:
        """The entry's cameras, from the job file alone (an animation's rules that need the
        scene and the settings: `animated`)."""
        if raw is None:
            return (CameraSpec("camera"),)
        raw = self.table(raw, key, CAMERA_KINDS)
        if len(raw) != 1:
            self.fail(key, f"expected one of {', '.join(CAMERA_KINDS)}, got "
                           f"{', '.join(raw) or 'none'}")
        kind, value = next(iter(raw.items()))
        where = f"{key}.{kind}"
        if kind == "orbit":
            value = self.table(value, where, ORBIT_KEYS)
            if "views" not in value:
                self.fail(where, "needs views = N (cameras evenly round the look point)")
            views = self.integer(value["views"], f"{where}.views", 1, MAX_COUNT)
            elevation = None
            if "elevation" in value:
                elevation = self.number(value["elevation"], f"{where}.elevation")
                if abs(elevation) > MAX_ELEVATION:
                    self.fail(f"{where}.elevation", f"must be between -{MAX_ELEVATION:g} and "
                                                    f"{MAX_ELEVATION:g} degrees, got {elevation:g}")
            return tuple(CameraSpec("orbit", k, views=views, elevation=elevation) for k in range(views))
        if kind == "poses":
            poses = self.entries(value, where)
            return tuple(self.pose(pose, f"{where}[{k}]", k) for k, pose in enumerate(poses))
        return self.animation(value, where)

    def pose(self, raw: dict, key: str, index: int) -> CameraSpec:
        raw = self.table(raw, key, POSE_KEYS)
        for needed in ("eye", "look"):
            if needed not in raw:
                self.fail(key, f"needs {needed} = [x, y, z]")
        eye, look = self.vec3(raw["eye"], f"{key}.eye"), self.vec3(raw["look"], f"{key}.look")
        up = self.vec3(raw["up"], f"{key}.up") if "up" in raw else None
        if eye == look:                      # the camera rules of scene_file's [camera]
            self.fail(f"{key}.look", f"is the same point as {key}.eye; the camera needs "
                                     "eye - look to be a direction")
        if up is not None and not any(up):
            self.fail(f"{key}.up", "must not be zero length; up says which way is up in the image")
        return CameraSpec("pose", index, eye=eye, look=look, up=up)

    def animation(self, raw: Any, key: str) -> tuple[CameraSpec, ...]:
        raw = self.table(raw, key, ANIMATION_KEYS)
        if "frames" not in raw:
            self.fail(key, "needs frames = N")
        frames = self.integer(raw["frames"], f"{key}.frames", 1, MAX_COUNT)
        step = self.number(raw.get("step", 1.0), f"{key}.step", above=0.0)
        exposure = self.number(raw.get("exposure", 0.0), f"{key}.exposure", minimum=0.0)
        last = (frames - 1) * step + exposure
        if last > MAX_NUMBER:
            self.fail(key, f"the last frame's shutter closes at {last:g}, past {MAX_NUMBER:g}")
        return tuple(CameraSpec("frame", t, shutter=(t * step, t * step + exposure))
                     for t in range(frames))

    def animated(self, key: str, scene, settings) -> None:
        """An animation's rules that need the scene and the settings."""
        still = [s for s in settings if not METHODS[s.method].shutter]
        if still:
            self.fail(key, f"an animation is the ray tracer's (motion during the shutter; the "
                           f"{METHODS[still[0].method].title} draws time 0), but setting "
                           f"{still[0].name!r} is method {still[0].method}")
        if not declares_motion(scene):
            self.fail(key, "nothing in the scene moves (no object has a velocity or "
                           "angular_velocity): every frame would be the same")

    # ---- [[settings]]

    def setting(self, raw: dict, key: str, size: tuple[int, int]) -> Setting:
        raw = self.table(raw, key, SETTING_KEYS)
        method = self.choice(raw.get("method", "raster"), f"{key}.method", "method", METHODS)
        name = _name(self, raw.get("name", method), f"{key}.name")
        background = self.choice(raw.get("background", "opaque"), f"{key}.background",
                                 "background", BACKGROUNDS)
        outputs = self.outputs(raw.get("outputs"), f"{key}.outputs", background)
        common = {"name": name, "method": method, "outputs": outputs, "background": background,
                  "size": self.size(raw["size"], f"{key}.size") if "size" in raw else size}
        try:                 # the method's rules, once (renderer/methods: its options type)
            options = method_options(method, self.option_values(raw, key))
        except OptionError as error:
            self.fail(f"{key}.{error.fields[0]}", error.reason)
        return Setting(**common, options=options)

    def option_values(self, raw: dict, key: str) -> dict:
        """The methods' option keys given, as values of their types (their ranges, and which
        method takes them, are the options types' to check)."""
        values = {}
        for option in (option for option in OPTION_KEYS if option in raw):
            where, value = f"{key}.{option}", raw[option]
            if option == "shading":
                values[option] = self.choice(value, where, "shading", SHADING_MODES)
            elif option == "pattern":
                values[option] = self.string(value, where)
            elif option == "adaptive_threshold":
                values[option] = self.number(value, where)
            else:
                values[option] = self.integer(value, where, -2 ** 63, None)
        return values

    def outputs(self, raw: Any, key: str, background: str) -> tuple[Output, ...]:
        if raw is None:
            raw = [{}]
        outputs = tuple(self.output(entry, f"{key}[{i}]", background)
                        for i, entry in enumerate(self.entries(raw, key)))
        _unique(self, [(o.name, f"{key}[{i}].name") for i, o in enumerate(outputs)], "the file name")
        return outputs

    def output(self, raw: dict, key: str, background: str) -> Output:
        if isinstance(raw, dict) and "depth" in raw:
            raw = self.table(raw, key, DEPTH_KEYS)
            depth = self.choice(raw["depth"], f"{key}.depth", "depth format", DEPTH_FORMATS)
            return Output(self.file_name(raw, key, f".{depth}", default_output_name(None, depth)),
                          depth=depth)
        raw = self.table(raw, key, OUTPUT_KEYS)

        def parsed(option, parse, default=None):
            if option not in raw:
                return default
            value = raw[option]
            if isinstance(value, bool) or not isinstance(value, (str, int, float)):
                self.fail(f"{key}.{option}", f"expected a string or number, got {describe_value(value)}")
            try:
                return parse(str(value))
            except ValueError as error:
                self.fail(f"{key}.{option}", str(error))

        bits = parsed("bits", stage.parse_bits)
        output_format = self.choice(raw.get("format", stage.format_for(".png", bits)),
                                    f"{key}.format", "format", stage.FORMATS)
        dither = self.choice(raw.get("dither", "none"), f"{key}.dither", "dither", stage.DITHERS)
        try:
            settings = stage.OutputSettings(transfer=parsed("transfer", stage.parse_transfer, stage.Transfer()),
                                            bits=bits, dither=dither,
                                            halftone=parsed("halftone", stage.parse_halftone),
                                            format=output_format)
            settings.check_background(background)
        except OptionError as error:               # the rule's own words (OutputSettings)
            self.fail(f"{key}.{error.fields[0]}", error.reason)
        suffix = stage.FORMATS[output_format]
        return Output(self.file_name(raw, key, suffix, default_output_name(settings, None)), settings)

    def file_name(self, raw: dict, key: str, suffix: str, default: str) -> str:
        if "name" not in raw:
            return default
        name = _name(self, raw["name"], f"{key}.name")
        if Path(name).suffix.lower() != suffix:
            self.fail(f"{key}.name", f"{name!r} is written as {suffix}; name it "
                                     f"{Path(name).stem}{suffix}")
        return name

