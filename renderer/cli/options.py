"""What several commands share: the argparse types, the option groups more than one command
takes (scene, --size and --context; --method and the ray tracer's options with the lens's;
--max-memory), the parser that refuses a command line in two lines, and the scene loading
and ray-option checks of `render` and `compare`."""

from __future__ import annotations

import argparse
import sys
from pathlib import Path

from renderer.core.ray_depth import MAX_DEPTH_LIMIT
from renderer.core.path_options import PATH_DEPTH_LIMIT
from renderer.core.ray_sampling import MAX_LIGHT_SAMPLES, RAY_PATTERNS
from renderer.core.radiosity_options import (DEFAULT_ELEMENTS_ACROSS, MAX_AREA_SAMPLES, MAX_HEMICUBE,
                                             MAX_LIGHT_BUFFER, MAX_REFINE, SOLVERS)
from renderer.errors import OptionError, UsageError, UserError

DEFAULT_SIZE = (640, 480)


def parse_size(text: str) -> tuple[int, int]:
    try:
        width, height = (int(part) for part in text.lower().split("x"))
    except ValueError:
        raise argparse.ArgumentTypeError(f"expected WIDTHxHEIGHT such as 640x480, got {text!r}") from None
    if not (1 <= width <= 16384 and 1 <= height <= 16384):
        raise argparse.ArgumentTypeError(f"width and height must be 1 to 16384 pixels, got {text!r}")
    return width, height


def positive_int(text: str) -> int:
    try:
        value = int(text)
    except ValueError:
        value = 0
    if value < 1:
        raise argparse.ArgumentTypeError(f"expected a whole number of at least 1, got {text!r}")
    return value


def channel_threshold(text: str) -> int:
    try:
        value = int(text)
    except ValueError:
        value = -1
    if not 0 <= value <= 255:
        raise argparse.ArgumentTypeError(f"expected a whole number of levels from 0 to 255, got {text!r}")
    return value


def output_path(text: str) -> Path:
    """An output file or folder name. An empty one is refused with one line (a UserError,
    which argparse lets through), before any work: Path('') would be the current folder."""
    if not text:
        raise UserError("an empty output name; name the file or folder, e.g. out.png or out/")
    return Path(text)


class Parser(argparse.ArgumentParser):
    """argparse, but a refused command line is a UsageError: main() prints the reason after
    the (sub)command's name on one line, then its usage on one line (never wrapped), and
    returns 2."""

    def error(self, message):
        raise UsageError(message, prog=self.prog, usage=self.usage_line())

    def parse_args(self, args=None, namespace=None):
        # argparse hands a subcommand's unknown options up to the top: refuse them with the
        # subcommand's usage, which is the one that lists what it takes.
        args, extras = self.parse_known_args(args, namespace)
        if extras:
            getattr(args, "parser", self).error(f"unrecognized arguments: {' '.join(extras)}")
        return args

    def usage_line(self) -> str:
        formatter = argparse.HelpFormatter(self.prog, width=1_000_000)
        formatter.add_usage(self.usage, self._actions, self._mutually_exclusive_groups)
        return formatter.format_help().strip()


def scene_options(p) -> None:
    """The scene argument, --size and --context (render, compare)."""
    p.add_argument("scene", nargs="?", help="scene file or built-in scene name (default: the default scene)")
    p.add_argument("--size", type=parse_size, default=DEFAULT_SIZE, metavar="WxH",
                   help="image size in pixels (default 640x480)")
    p.add_argument("--context", choices=("auto", "egl", "osmesa"), default="auto",
                   help="headless GL context (default: EGL, then OSMesa)")


def raytrace_options(p) -> None:
    """--method and the ray tracer's options, the lens's among them (render, compare)."""
    p.add_argument("--method", choices=("raster", "raytrace", "radiosity", "pathtrace"),
                   help="raster (default): the rasteriser; raytrace: the ray tracer (shadows, "
                        "reflection, refraction; docs/conventions.md, \"Rays\"); radiosity: "
                        "light from emitting surfaces, bounced between diffuse ones (docs/radiosity.md); "
                        "pathtrace: the path tracer, every bounce of light by Monte Carlo (docs/pathtrace.md)")
    p.add_argument("--spp", type=int, default=None, metavar="N",
                   help="ray and path tracers: samples per pixel (default 1; the path tracer's 16)")
    p.add_argument("--pattern", default=None, metavar="|".join(RAY_PATTERNS),
                   help="ray and path tracers: sample positions (default regular; the path tracer's jittered; "
                        "docs/conventions.md, "
                        "\"Sample positions\")")
    p.add_argument("--adaptive-threshold", type=float, default=None, metavar="T",
                   help="ray tracer, --pattern adaptive: refine a pixel whose first 4 samples' "
                        "clamped colours differ by more than T in some channel (default 2/255)")
    p.add_argument("--max-depth", type=int, default=None, metavar="D",
                   help="ray tracer: bounces of reflection and refraction, 0 to "
                        f"{MAX_DEPTH_LIMIT} (default 4); path tracer: bounces of a path, 0 to "
                        f"{PATH_DEPTH_LIMIT} (default 32)")
    p.add_argument("--seed", type=int, default=None, metavar="S",
                   help="ray tracer: seed of the random numbers (0 to 2^32 - 1)")
    p.add_argument("--light-samples", type=int, default=None, metavar="M",
                   help=f"ray tracer: points sampled on each area light per hit, 1 to "
                        f"{MAX_LIGHT_SAMPLES} (default 1; docs/conventions.md, \"Area lights\")")
    lens_options(p)
    p.add_argument("--element-size", type=float, default=None, metavar="S",
                   help="radiosity: the longest edge of an element, scene units (default: the "
                        f"scene's diagonal / {DEFAULT_ELEMENTS_ACROSS})")
    p.add_argument("--hemicube", type=int, default=None, metavar="N",
                   help="radiosity: pixels across a hemicube's top face, a power of two from 4 to "
                        f"{MAX_HEMICUBE} (default 64)")
    p.add_argument("--solver", default=None, metavar="|".join(SOLVERS),
                   help="radiosity: how the equation is solved (default gauss-seidel)")
    p.add_argument("--light-buffer", type=int, default=None, metavar="N",
                   help="radiosity: pixels across each view a point or directional light sees the "
                        f"elements through, a power of two from 4 to {MAX_LIGHT_BUFFER} (default 512)")
    p.add_argument("--area-samples", type=int, default=None, metavar="K",
                   help=f"radiosity: an area light seen from K x K of its points, 1 to {MAX_AREA_SAMPLES} "
                        "(default 4)")
    p.add_argument("--refine", type=int, default=None, metavar="L",
                   help=f"radiosity: cut the elements where radiosity changes fast in four, L times, 0 to "
                        f"{MAX_REFINE} (default 0; docs/radiosity.md)")
    p.add_argument("--refine-threshold", type=float, default=None, metavar="T",
                   help="radiosity: an element is cut where its Gouraud display differs from its own "
                        "radiosity by more than T levels of 255 (default 4)")


def lens_options(p) -> None:
    """The thin lens's overrides of the scene's camera (part of raytrace_options)."""
    p.add_argument("--aperture", type=float, default=None, metavar="A",
                   help="ray tracer: the thin lens's radius in scene units, >= 0, instead of "
                        "the scene's camera.aperture (depth of field; 0: a pinhole)")
    p.add_argument("--focus-distance", type=float, default=None, metavar="F",
                   help="ray tracer: the view depth in focus, > 0, instead of the scene's "
                        "camera.focus_distance")


def memory_option(p) -> None:
    """--max-memory, the last option of each command that renders."""
    p.add_argument(
        "--max-memory", type=memory_size, metavar="SIZE",
        help="refuse, before any work, what would need more memory than this (512M, 4G, ...; "
             "default: half of this machine's memory; renderer/core/memory.py)")


def memory_size(text: str) -> int:
    from renderer.core.memory import parse_size as parse_memory
    try:
        return parse_memory(text)
    except ValueError as error:
        raise argparse.ArgumentTypeError(str(error)) from None


def load(scene_arg, *needs):
    """The scene named on the command line, read for a command that will then take each of
    `needs` (renderer/core/memory.py Need): refused in one line as soon as its triangles are
    known to need more than the memory limit, before they are built, and checked whole once
    read."""
    from renderer.core import memory
    from renderer.core.builtin import resolve_scene
    from renderer.core.scene_file import load_scene
    path = resolve_scene(scene_arg)
    for need in needs:                     # a size too large for any scene: said first
        need.check_unread(Path(path).stem)
    with memory.planned(*needs):
        scene = load_scene(path)
    for need in needs:
        need.check(scene)
    return scene


# RayOptions' and RadiosityOptions' fields -> the command line's options (renderer/core/ray_options.py
# and radiosity_options.py hold the rules).
RAY_FLAGS = {"samples": "--spp", "pattern": "--pattern", "max_depth": "--max-depth", "seed": "--seed",
             "adaptive_threshold": "--adaptive-threshold", "light_samples": "--light-samples",
             "aperture": "--aperture", "focus_distance": "--focus-distance",
             "element_size": "--element-size", "hemicube": "--hemicube", "solver": "--solver",
             "light_buffer": "--light-buffer", "area_samples": "--area-samples", "refine": "--refine",
             "refine_threshold": "--refine-threshold"}


def _dest(flag: str) -> str:
    return flag[2:].replace("-", "_")


def spelled(error, args) -> str:
    """An OptionError as the command line says it: each field given as its option and the
    value given (`--spp 2 --pattern adaptive: adaptive sampling needs ...`); where none of
    the fields was given (a format implied by -o's suffix), the first one's option."""
    flags = [RAY_FLAGS.get(field, f"--{field.replace('_', '-')}") for field in error.fields]
    words = [f"{flag} {show_option(getattr(args, _dest(flag)))}" for flag in flags
             if getattr(args, _dest(flag), None) is not None]
    return f"{' '.join(words or flags[:1])}: {error.reason}"


def show_option(value) -> str:
    return f"{value:g}" if isinstance(value, float) else str(value)


def ray_options_given(args) -> dict:
    """The method options' fields the command line gave (the others keep their defaults; one
    of another method's is refused by name, renderer/methods method_options)."""
    return {field: getattr(args, _dest(flag)) for field, flag in RAY_FLAGS.items()
            if getattr(args, _dest(flag), None) is not None}


def check_raytrace_options(args) -> None:
    """args.options: the method's options from those given, checked by their type's rules
    (an OptionError spelled as the options were given, with the usage); --method's default
    (raster) is set here, so that `compare --methods` can refuse a --method given. With
    --methods the options given are the ray tracer's."""
    from renderer.methods import method_options
    methods = getattr(args, "methods", False)
    if methods and args.method is not None:
        args.parser.error(f"--methods renders both methods; leave out --method {args.method}")
    args.method = args.method or "raster"
    try:
        args.options = method_options("raytrace" if methods else args.method, ray_options_given(args))
    except OptionError as error:
        args.parser.error(spelled(error, args))


def load_traced(args, *needs):
    """The scene (`load`, for `needs`), checked against the lens overrides (an aperture on a
    parallel camera: one line naming the option, status 2); open_renderer applies them."""
    scene = load(args.scene, *needs)
    try:
        args.options.scene_for(scene)
    except OptionError as error:
        raise UserError(spelled(error, args)) from None
    return scene


def warn_if_nothing_drawn(scene, frame) -> None:
    """One line on stderr when no pixel of the frame was drawn, saying why if the objects'
    bounding boxes tell (renderer/core/visibility.py). The exit status stays as it is."""
    if not frame.rgba8[..., 3].any():
        from renderer.core.visibility import nothing_in_view
        reason = nothing_in_view(scene, scene.matrices(*frame.size))
        print(f"renderer: warning: nothing was drawn: {reason}", file=sys.stderr)
