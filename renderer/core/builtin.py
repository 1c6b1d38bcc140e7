"""The built-in scenes (assets/scenes/*.toml) and how a scene argument becomes a file.

    builtin_scenes()        {"sphere": Path(".../assets/scenes/sphere.toml"), ...}
    resolve_scene(None)     the default scene, "sphere"
    resolve_scene("hierarchy") or resolve_scene("my/scene.toml")  -> Path
    is_scene_name("hierarchy")  True: no folder, no .toml suffix (may name a built-in scene)
    describe("sphere")      its one-line description (for `renderer scenes`)
    scene_descriptions()    {"sphere": "The default: ...", ...}
    made_for_raytracing("classic")  True: its description says "--method raytrace"
"""

from __future__ import annotations

import difflib
import tomllib
from pathlib import Path

from renderer.core import resources
from renderer.core.paths import checked_path
from renderer.core.user_files import SCENE_FILE, FileRefused, open_user_file, read_user_file
from renderer.errors import SceneError

DEFAULT_SCENE = "sphere"

# What the description of a built-in scene made for the ray tracer says (its author's word:
# reflection, refraction or shadows that only the ray tracer drew when it was made). Shapes
# are no mark: the shadow scenes use them so that the ray tracer's shadows, their truth, come
# from exact spheres and planes, and they are made for the rasteriser.
RAYTRACE_MARK = "--method raytrace"
# And of one made for radiosity: lit by surfaces that emit, which only radiosity reads.
RADIOSITY_MARK = "--method radiosity"


def assets_dir() -> Path:
    """The assets folder (renderer.core.resources finds it in a checkout or a wheel); a
    SceneError when it is missing."""
    try:
        return resources.assets_dir()
    except FileNotFoundError as exc:
        raise SceneError(str(exc)) from None


def builtin_scenes() -> dict[str, Path]:
    """Name (the file's stem) to path of every built-in scene, sorted by name."""
    folder = assets_dir() / "scenes"
    return {path.stem: path for path in sorted(folder.glob("*.toml"))}


def is_scene_name(arg: str) -> bool:
    """Whether a scene argument has the form of a built-in scene's name: no folder and no
    `.toml` suffix. (Whether such a scene exists is resolve_scene's question.)"""
    path = Path(arg)
    return path.name == arg and path.suffix.lower() != ".toml"


def resolve_scene(arg: str | None) -> Path:
    """The scene file an argument names, on the command line and in load_scene alike.

    None means the default scene. An existing file wins; then a bare name (no folder, no
    .toml suffix) is looked up among the built-in scenes; anything else is an error.
    """
    scenes = builtin_scenes()
    if arg is None:
        return scenes[DEFAULT_SCENE]
    path = checked_path(arg, error=SceneError)
    if path.is_file():
        return path
    if is_scene_name(arg) and arg in scenes:
        return scenes[arg]
    if path.exists():           # a folder, a FIFO, a device: the opener says which
        try:
            open_user_file(path, SCENE_FILE).close()
        except FileRefused as refused:
            raise SceneError(refused.reason, file=arg) from None
        return path
    close = difflib.get_close_matches(arg, list(scenes), n=1, cutoff=0.6)
    hint = f"did you mean {close[0]!r}? " if close else ""
    raise SceneError(f"no such scene file or built-in scene; {hint}"
                     f"built-in scenes: {', '.join(scenes)}", file=arg)


def scene_description(path: Path) -> str:
    """The scene's one-line `description` key ("" if it has none or cannot be read: read
    through renderer/core/user_files.py, as a scene file is)."""
    try:
        data = tomllib.loads(read_user_file(path, SCENE_FILE).decode("utf-8"))
    # TOMLDecodeError and UnicodeDecodeError are ValueErrors
    except (FileRefused, ValueError, RecursionError):
        return ""
    description = data.get("description", "")
    return " ".join(description.split()) if isinstance(description, str) else ""


def describe(scene: str) -> str:
    """One-line description of a built-in scene (by name) or of a scene file (by path)."""
    scenes = builtin_scenes()
    return scene_description(scenes[scene] if scene in scenes else Path(scene))


def scene_descriptions() -> dict[str, str]:
    """Name to one-line description of every built-in scene."""
    return {name: scene_description(path) for name, path in builtin_scenes().items()}


def made_for(scene: str) -> str:
    """The method (renderer/methods' name) the built-in scene or scene file is made for:
    "raytrace" where its description says RAYTRACE_MARK, "radiosity" where RADIOSITY_MARK,
    else "raster"."""
    if made_for_raytracing(scene):
        return "raytrace"
    return "radiosity" if RADIOSITY_MARK in describe(scene) else "raster"


def made_for_raytracing(scene: str) -> bool:
    """Whether the built-in scene (by name) or scene file (by path) is made for the ray tracer:
    its description says RAYTRACE_MARK. `renderer report` with no scenes reports these with
    --method raytrace, the others with --method raster."""
    return RAYTRACE_MARK in describe(scene)
