"""The command line: `renderer render | view | compare | shaders | report | batch | scenes |
extremes | colour` (also `python -m renderer`).

A user's mistake (bad scene, bad output name, no GL) is one line on stderr and exit status
2, with nothing written; an option argparse refuses is its reason on one line and the
command's usage on the next, also status 2; a write the system refuses (read-only, disk full,
I/O error: errors.SystemFault) is one line and status 1, with nothing written either; a bug
keeps its traceback. `compare` exits 1 when the images fail the pipeline tolerance.

Every command writes its files through one transaction (renderer/core/imageio.py, `outputs`):
its output names are checked before any work, and its files are renamed into place together.
"""

from __future__ import annotations

import argparse
import contextlib
import os
import statistics
import sys
import time
from dataclasses import replace
from pathlib import Path

from renderer import __version__
from renderer.checks.tolerance import PIPELINE_TOLERANCE
from renderer.core.frame import BACKGROUNDS
from renderer.core.ray_depth import MAX_DEPTH_LIMIT
from renderer.core.ray_sampling import MAX_LIGHT_SAMPLES, RAY_PATTERNS
from renderer.core.memory import check_raytrace_render, check_render
from renderer.errors import UsageError, UserError, escaped

DEFAULT_SIZE = (640, 480)
COLOUR_SIZE = (320, 240)             # `renderer colour`'s frame of a scene


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


class _Parser(argparse.ArgumentParser):
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


def build_parser() -> argparse.ArgumentParser:
    parser = _Parser(prog="renderer", description="A GLSL renderer checked against a NumPy reference.")
    parser.add_argument("--version", action="version", version=f"renderer {__version__}")
    sub = parser.add_subparsers(dest="command", required=True, parser_class=_Parser)

    def common(p):
        p.add_argument("scene", nargs="?", help="scene file or built-in scene name (default: the default scene)")
        p.add_argument("--size", type=parse_size, default=DEFAULT_SIZE, metavar="WxH",
                       help="image size in pixels (default 640x480)")
        p.add_argument("--context", choices=("auto", "egl", "osmesa"), default="auto",
                       help="headless GL context (default: EGL, then OSMesa)")

    def raytrace_options(p):
        p.add_argument("--method", choices=("raster", "raytrace"),
                       help="raster (default): the rasteriser; raytrace: the ray tracer (shadows, "
                            "reflection, refraction; docs/conventions.md, \"Rays\")")
        p.add_argument("--spp", type=positive_int, default=1, metavar="N",
                       help="ray tracer: samples per pixel (default 1)")
        p.add_argument("--pattern", choices=RAY_PATTERNS, default="regular",
                       help="ray tracer: sample positions (default regular; docs/conventions.md, "
                            "\"Sample positions\")")
        p.add_argument("--adaptive-threshold", type=float, default=None, metavar="T",
                       help="ray tracer, --pattern adaptive: refine a pixel whose first 4 samples' "
                            "clamped colours differ by more than T in some channel (default 2/255)")
        p.add_argument("--max-depth", type=int, default=4, metavar="D",
                       help="ray tracer: bounces of reflection and refraction, 0 to "
                            f"{MAX_DEPTH_LIMIT} (default 4)")
        p.add_argument("--seed", type=int, default=None, metavar="S",
                       help="ray tracer: seed of the random numbers (0 to 2^32 - 1)")
        p.add_argument("--light-samples", type=int, default=None, metavar="M",
                       help=f"ray tracer: points sampled on each area light per hit, 1 to "
                            f"{MAX_LIGHT_SAMPLES} (default 1; docs/conventions.md, \"Area lights\")")
        lens_options(p)

    def lens_options(p):
        p.add_argument("--aperture", type=float, default=None, metavar="A",
                       help="ray tracer: the thin lens's radius in scene units, >= 0, instead of "
                            "the scene's camera.aperture (depth of field; 0: a pinhole)")
        p.add_argument("--focus-distance", type=float, default=None, metavar="F",
                       help="ray tracer: the view depth in focus, > 0, instead of the scene's "
                            "camera.focus_distance")

    render = sub.add_parser("render", help="render a scene to PNG")
    common(render)
    raytrace_options(render)
    render.add_argument("-o", "--output", type=output_path, metavar="OUT.png",
                        help="image to write, in the format its suffix names (.png, .jpg, .webp, "
                             ".tif, ...; default: SCENE_NAME.png)")
    render.add_argument("--backend", choices=("gpu", "reference"), default="gpu")
    render.add_argument("--depth", type=output_path, metavar="OUT.npy|OUT.exr",
                        help="also write camera-space depth (float32, +inf where empty) as a "
                             "NumPy array or an OpenEXR plane Z")
    render.add_argument("-q", "--quiet", action="store_true",
                        help="do not say where the image was written (one line on stderr)")
    render.add_argument("--background", choices=BACKGROUNDS, default="opaque",
                        help="opaque (default): the picture as an image viewer shows it, the "
                             "scene's background colour where nothing is drawn (RGB); transparent: "
                             "RGBA, alpha 0 where nothing is drawn and 255 elsewhere")
    output_options(render)

    view = sub.add_parser("view", help="open a scene in a window (glfw): orbit, pan, zoom, "
                                       "switch shading, compare with the reference; H for help")
    view.add_argument("scene", nargs="?", help="scene file or built-in scene name (default: the default scene)")
    view.add_argument("--size", type=parse_size, default=DEFAULT_SIZE, metavar="WxH",
                      help="window size in pixels (default 640x480)")
    view.add_argument("--frames", type=positive_int, metavar="N",
                      help="scripted: render N frames, save --screenshot, print frame-time "
                           "statistics and exit")
    view.add_argument("--screenshot", type=output_path, metavar="OUT.png",
                      help="with --frames: what the window shows after the last frame; "
                           "otherwise the file the S key writes (default view-SCENE-NNN.png); "
                           "in the format its suffix names (.png, .jpg, ...)")
    view.add_argument("--stats", type=output_path, metavar="OUT.json",
                      help="with --frames: also write the frame-time statistics as JSON")
    view.add_argument("--orbit", type=float, default=0.0, metavar="DEGREES_PER_FRAME",
                      help="turn the camera about its look point every frame")
    view.add_argument("--reference", choices=("off", "side-by-side", "difference"), default="off",
                      help="start with the reference view shown (the C key cycles it)")
    view.add_argument("--triple-buffering", action="store_true",
                      help="start with triple buffering (the B key toggles it)")
    view.add_argument("--no-vsync", action="store_true", help="start with v-sync off (the V key)")
    view.add_argument("--method", choices=("raster", "raytrace"), default="raster",
                      help="start with the rasteriser (default) or the ray tracer, which refines "
                           "while the view is still, one sample per pixel a frame (the M key)")

    compare = sub.add_parser(
        "compare", help="render through the GPU and the reference and compare",
        description="Render a scene through the GPU and the NumPy reference, write gpu.png, "
                    "reference.png and diff.png, and print the figures as one JSON object. "
                    "Exit status: 0 when the two agree within the pipeline tolerance "
                    f"({PIPELINE_TOLERANCE.describe()}; docs/conventions.md), 1 when they do not "
                    "(what fails is said on stderr), 2 for bad input. With --methods: the "
                    "rasteriser against the ray tracer instead, status 0; with --shadows-vs-truth: "
                    "the rasteriser's shadow maps against ray-cast shadows, status 0; with "
                    "--depth-vs-truth: the GPU's depth against ray-cast depth, status 0.")
    common(compare)
    raytrace_options(compare)
    compare.add_argument("--out", type=output_path, help="folder for gpu.png, reference.png, diff.png "
                                                   "(default: compare-SCENE_NAME)")
    compare.add_argument("--methods", action="store_true",
                         help="the rasteriser against the ray tracer (--spp, --pattern, --max-depth, "
                              "--seed), both on the GPU: where they differ and why (shadows, "
                              "reflection, edges, tessellation, ...); writes raster.png, raytrace.png, "
                              "causes.png and methods.json (default folder: compare-methods-SCENE_NAME)")
    compare.add_argument("--shadows-vs-truth", action="store_true",
                         help="how wrong the rasteriser's shadow maps are against ray-cast "
                              "shadows (pixels wrongly lit or shadowed, inside or outside a "
                              "1-texel band around the true edge, acne, peter-panning); writes "
                              "shadow_truth.png and shadow_truth.json (default folder: "
                              "compare-shadows-SCENE_NAME)")
    compare.add_argument("--depth-vs-truth", action="store_true",
                         help="the GPU's depth against a float64 ray cast through each pixel "
                              "centre at the surfaces the rasteriser draws: the relative error's "
                              "99.9th percentile and maximum, in all and per object; writes "
                              "depth_truth.png and depth_truth.json (default folder: "
                              "compare-depth-SCENE_NAME)")
    compare.add_argument("--threshold", type=channel_threshold, default=PIPELINE_TOLERANCE.threshold,
                         metavar="LEVELS",
                         help="per-channel threshold in levels of 255, 0 to 255; the pipeline "
                              f"tolerance with this threshold decides the exit status (default "
                              f"{PIPELINE_TOLERANCE.threshold}, the tolerance's own)")

    shaders = sub.add_parser("shaders", help="write the exact GLSL a scene's draws use")
    shaders.add_argument("scene", nargs="?", help="scene file or built-in scene name (default: the default scene)")
    shaders.add_argument("--out", type=output_path, help="folder for VARIANT.vert/.geom/.frag "
                                                   "(default: shaders-SCENE_NAME)")

    report = sub.add_parser("report", help="error against run time over quality settings "
                                           "(results.csv, plots, report.md)")
    report.add_argument("scenes", nargs="*", metavar="SCENE",
                        help="scene files or built-in names (default: the built-in scenes made "
                             "for --method: for raytrace those with spheres, planes, k_r or k_t, "
                             "for raster the others; with --quick, two small ones, or classic)")
    report.add_argument("--out", type=output_path, required=True, help="folder for the report")
    report.add_argument("--quick", action="store_true",
                        help="a reduced sweep at 64x48 that takes about a minute (for CI)")
    report.add_argument("--size", type=parse_size, metavar="WxH",
                        help="image size (default 160x120; 64x48 with --quick)")
    report.add_argument("--cache", type=Path, metavar="DIR",
                        help="ground-truth cache (default ~/.cache/checked-renderer/truth)")
    report.add_argument("--context", choices=("auto", "egl", "osmesa"), default="auto",
                        help="headless GL context (default: EGL, then OSMesa)")
    report.add_argument("--method", choices=("raster", "raytrace"), default="raster",
                        help="raster (default): the rasteriser's knobs; raytrace: the ray "
                             "tracer's (samples per pixel by pattern, adaptive thresholds, max "
                             "depth), against a ray-traced ground truth")
    report.add_argument("--knobs", type=lambda text: tuple(k.strip() for k in text.split(",")),
                        metavar="K,K", help="only these knob families (default all): raster: "
                        "antialiasing, tessellation, shading, precision, shadows (map resolution, "
                        "filter, bias rule against ray-cast truth), filter and texture_resolution "
                        "(textured scenes), output (the output stage's methods at 1 to 8 bits); raytrace: antialiasing, max_depth, precision")
    report.add_argument("--address", metavar="auto|HOST:PORT",
                        help="run the settings on a running Ray cluster's workers (auto: the one "
                             "`ray start` made on this machine); default: this process. results.csv "
                             "is the same apart from the times and the `worker` that took them")
    report.add_argument("--workers", type=positive_int, metavar="N",
                        help="run the settings on N Ray workers (default with --address: one per "
                             "CPU); without --address, on a local Ray started for this report")

    batch = sub.add_parser(
        "batch", help="render a job file's items (scenes x cameras x sweeps x settings) into a "
                      "folder with a manifest; on Ray's workers when installed (docs/batch-format.md)",
        description="Render every item of a job file once into --out, each item's files written "
                    "whole and recorded in --out/manifest.jsonl (SHA-256 of every file); a re-run "
                    "with the same --out skips the items already complete. Exit status: 0 when "
                    "every item was written, 1 when some failed (a re-run tries them again), 2 "
                    "for bad input, with nothing written.")
    batch.add_argument("job", metavar="JOB.toml", help="the job file (docs/batch-format.md)")
    batch.add_argument("--out", type=output_path, required=True, metavar="DIR",
                       help="folder for the items' files and manifest.jsonl")
    batch.add_argument("--address", metavar="auto|HOST:PORT",
                       help="a running Ray cluster (auto: the one `ray start` made on this "
                            "machine); default: a local Ray started for this job, or this process "
                            "when Ray is not installed")
    batch.add_argument("--workers", type=positive_int, metavar="N",
                       help="workers of a local Ray (default: one per core)")
    batch.add_argument("--compare", action="store_true",
                       help="also render each item with the NumPy reference and compare, as "
                            "`renderer compare` does (gpu.png, reference.png, diff.png in the "
                            "item's compare/ folder, the figures in its record)")
    batch.add_argument("--context", choices=("auto", "egl", "osmesa"), default="auto",
                       help="the workers' headless GL context (default: EGL, then OSMesa)")

    sub.add_parser("scenes", help="list the built-in scenes")

    extremes = sub.add_parser("extremes", help="render the extreme scenes (assets/extreme/) through "
                                               "both pipelines and report their stability")
    extremes.add_argument("scenes", nargs="*", help="further scene files to measure alike")
    extremes.add_argument("--out", type=output_path, default=Path("extremes"),
                          help="folder for extremes.json and extremes.md (default: extremes)")
    extremes.add_argument("--size", type=parse_size, default=(320, 240), metavar="WxH",
                          help="image size in pixels (default 320x240)")
    extremes.add_argument("--context", choices=("both", "egl", "osmesa"), default="both",
                          help="GL contexts to render with (default: both)")
    extremes.add_argument("--method", choices=("both", "raster", "raytrace"), default="both",
                          help="which cases: rasterised, ray traced (scene files named rt_*), or "
                               "both (default)")
    extremes.add_argument("--no-sweep", action="store_true",
                          help="leave out the light-elevation sweep of shadow maps (measured "
                               "with the rasterised cases otherwise)")
    colour = sub.add_parser("colour", help="CIE chromaticity diagram, luminance histogram and "
                                           "Munsell table of an image or a scene's frame")
    colour.add_argument("source", metavar="IMAGE-or-SCENE",
                        help="an image file (PNG 8/16-bit, other formats Pillow reads, .exr, .npy) "
                             "or a scene file or built-in scene name")
    colour.add_argument("--out", type=output_path, required=True,
                        help="folder for chromaticity.png, luminance.png, munsell.md, colour.json")
    colour.add_argument("--backend", choices=("gpu", "reference"), default="gpu",
                        help="the colour pass (and a scene's renderer): gpu (default) or reference")
    colour.add_argument("--colorspace", choices=("srgb", "linear"),
                        help="an image's RGB: srgb-encoded (default for integer images) or linear "
                             "light (default for .exr and .npy)")
    colour.add_argument("--size", type=parse_size, metavar="WxH",
                        help=f"a scene's frame size (default {COLOUR_SIZE[0]}x{COLOUR_SIZE[1]})")
    colour.add_argument("--context", choices=("auto", "egl", "osmesa"), default="auto",
                        help="headless GL context (default: EGL, then OSMesa)")
    for name in ("render", "view", "compare", "shaders", "report", "extremes", "batch"):
        sub.choices[name].add_argument(
            "--max-memory", type=memory_size, metavar="SIZE",
            help="refuse, before any work, what would need more memory than this (512M, 4G, ...; "
                 "default: half of this machine's memory; renderer/core/memory.py)")
    for subparser in sub.choices.values():       # for the commands' own checks of their options
        subparser.set_defaults(parser=subparser)
    return parser


def output_options(render) -> None:
    """render's output stage (docs/conventions.md, "Output"). Their values are parsed in
    `output_settings`, so that each refusal is one line naming the option (no usage)."""
    from renderer.core.output_settings import DITHERS, FORMATS, MAX_BITS, MIN_BITS, MIN_CELL
    stage = render.add_argument_group(
        "output stage", "With any of --transfer, --bits, --dither, --halftone, --format the "
        "frame's linear colour is encoded by the transfer curve, quantised to N bits per "
        "channel (dithered or half-toned) or kept float, and written in the format; without "
        "them the image is GL's 8-bit colour as drawn (which equals --transfer linear --bits 8).")
    stage.add_argument("--transfer", metavar="linear|srgb|gamma:G",
                       help="the display's transfer curve (default linear; gamma:2.2 is V = L^(1/2.2))")
    stage.add_argument("--bits", metavar="N", help=f"bits per channel, {MIN_BITS} to {MAX_BITS} "
                                                   "(default the format's: 8 for png8, 16 for png16)")
    stage.add_argument("--dither", metavar="METHOD",
                       help=f"{', '.join(DITHERS)} (default none: the nearest code); in linear light")
    stage.add_argument("--halftone", metavar="CELL[:ANGLE]",
                       help=f"a CMYK clustered-dot half-tone: cells CELL pixels wide (at least "
                            f"{MIN_CELL:g}), screens turned ANGLE degrees (default 0); 1 bit per channel")
    stage.add_argument("--format", metavar="FORMAT",
                       help=f"{', '.join(FORMATS)}: 8- or 16-bit PNG, float32 OpenEXR or NumPy "
                            "(default from -o's suffix: .png is png8, png16 with --bits over 8)")
    stage.add_argument("--alpha", type=output_path, metavar="OUT.png|OUT.npy",
                       help="also write the coverage alpha, as 8-bit grey PNG or float32 NumPy")


def memory_size(text: str) -> int:
    from renderer.core.memory import parse_size as parse_memory
    try:
        return parse_memory(text)
    except ValueError as error:
        raise argparse.ArgumentTypeError(str(error)) from None


def _load(scene_arg):
    from renderer.core.builtin import resolve_scene
    from renderer.core.scene_file import load_scene
    return load_scene(resolve_scene(scene_arg))


def check_raytrace_options(args) -> None:
    """Refuses what does not go together; --method's default (raster) is set here, so that
    `compare --methods` can refuse a --method given."""
    methods = getattr(args, "methods", False)
    if methods and args.method is not None:
        args.parser.error(f"--methods renders both methods; leave out --method {args.method}")
    args.method = args.method or "raster"
    traced = methods or args.method == "raytrace"
    if not traced and (args.spp != 1 or args.pattern != "regular" or args.max_depth != 4
                       or args.seed is not None or args.adaptive_threshold is not None):
        also = " or --methods" if hasattr(args, "methods") else ""
        args.parser.error("--spp, --pattern, --max-depth, --seed and --adaptive-threshold are for "
                          f"--method raytrace{also}")
    if not 0 <= args.max_depth <= MAX_DEPTH_LIMIT:
        args.parser.error(f"--max-depth must be between 0 and {MAX_DEPTH_LIMIT}, got {args.max_depth}")
    check_light_samples_option(args, traced)
    if args.adaptive_threshold is not None and args.pattern != "adaptive":
        args.parser.error(f"--adaptive-threshold is for --pattern adaptive, not {args.pattern}")
    check_lens_options(args, traced)
    if traced:
        from renderer.core.ray_sampling import ray_sampling
        options = _raytrace_options(args)
        try:
            ray_sampling(options["pattern"], options["samples"], options["seed"], options["adaptive_threshold"],
                         options["light_samples"])
        except ValueError as error:
            given = [f"--spp {args.spp}", f"--pattern {args.pattern}"]
            given += [] if args.seed is None else [f"--seed {args.seed}"]
            given += [] if args.adaptive_threshold is None else [f"--adaptive-threshold {args.adaptive_threshold:g}"]
            given += [] if args.light_samples is None else [f"--light-samples {args.light_samples}"]
            args.parser.error(f"{' '.join(given)}: {error}")


def check_light_samples_option(args, traced: bool) -> None:
    """--light-samples: for the ray tracer only, 1 to MAX_LIGHT_SAMPLES."""
    if args.light_samples is None:
        return
    if not traced:
        also = " or --methods" if hasattr(args, "methods") else ""
        args.parser.error(f"--light-samples is for --method raytrace{also}")
    if not 1 <= args.light_samples <= MAX_LIGHT_SAMPLES:
        args.parser.error(f"--light-samples must be between 1 and {MAX_LIGHT_SAMPLES}, got {args.light_samples}")


LENS_OPTIONS = {"aperture": "--aperture", "focus_distance": "--focus-distance"}


def check_lens_options(args, traced: bool) -> None:
    """The thin lens's options are the ray tracer's (the rasteriser's camera is a pinhole)."""
    given = [option for key, option in LENS_OPTIONS.items() if getattr(args, key, None) is not None]
    if given and not traced:
        also = " or --methods" if hasattr(args, "methods") else ""
        args.parser.error(f"{' and '.join(given)} {'is' if len(given) == 1 else 'are'} for "
                          f"--method raytrace{also}")


def _load_traced(args):
    """The scene, its camera's lens set by --aperture and --focus-distance where given, each
    checked as the scene file's key is: one line naming the option, status 2."""
    from renderer.core.scene_file import with_lens
    from renderer.errors import SceneError, show_number
    scene = _load(args.scene)
    values = {key: getattr(args, key) for key in LENS_OPTIONS if getattr(args, key, None) is not None}
    if not values:
        return scene
    try:
        camera = with_lens(scene.camera, values, source=scene.source or scene.name)
    except SceneError as error:
        raise UserError(f"{LENS_OPTIONS[error.key]} {show_number(values[error.key])}: "
                        f"{error.reason}") from None
    return replace(scene, camera=camera)


def _raytrace_options(args) -> dict:
    from renderer.core.sampling import DEFAULT_SEED
    return {"samples": args.spp, "pattern": args.pattern, "max_depth": args.max_depth,
            "seed": DEFAULT_SEED if args.seed is None else args.seed,
            "adaptive_threshold": args.adaptive_threshold,
            "light_samples": 1 if args.light_samples is None else args.light_samples}


def samples_fired(frame) -> str:
    """What an adaptive frame traced: 'mean 4.72 spp, 6.0% of pixels refined'."""
    from renderer.core.ray_sampling import FIRST_SET
    return f"mean {frame.samples.mean():.2f} spp, {(frame.samples > FIRST_SET).mean():.1%} of pixels refined"


def _raytrace_gpu(scene, size, context_kind, options, frames=1):
    from renderer.gpu.raytracer import RayTracer
    with RayTracer(scene, *size, context_kind=context_kind, **options) as tracer:
        timings, frame = [], None
        for _ in range(frames):
            frame = tracer.render()
            timings.append(frame.milliseconds)
        return frame, statistics.median(timings), tracer.gl_info


def _render_gpu(scene, size, context_kind, frames=1):
    from renderer.gpu.pipeline import GpuRenderer
    with GpuRenderer(scene, *size, context_kind=context_kind) as gpu:
        timings, frame = [], None
        for _ in range(frames):
            frame = gpu.render(depth=True)
            timings.append(frame.milliseconds)
        # Read while the context is alive: afterwards it no longer knows its kind.
        return frame, statistics.median(timings), gpu.gl_info, gpu.subpixel_bits


def warn_if_nothing_drawn(scene, frame) -> None:
    """One line on stderr when no pixel of the frame was drawn, saying why if the objects'
    bounding boxes tell (renderer/core/visibility.py). The exit status stays as it is."""
    if not frame.rgba8[..., 3].any():
        from renderer.core.visibility import nothing_in_view
        reason = nothing_in_view(scene, scene.matrices(*frame.size))
        print(f"renderer: warning: nothing was drawn: {reason}", file=sys.stderr)


OUTPUT_OPTIONS = ("transfer", "bits", "dither", "halftone", "format")     # the stage's own


def output_settings(args):
    """The output stage's OutputSettings from render's options, or None when none of
    OUTPUT_OPTIONS is given (the frame's rgba8 is written as drawn). Checked before any work:
    each refusal is one line naming the option (or -o's file) and the reason, status 2."""
    from renderer.core import output_settings as stage
    given = [f"--{key}" for key in OUTPUT_OPTIONS if getattr(args, key) is not None]
    if not given:
        return None

    def parsed(key, parse, default=None):
        text = getattr(args, key)
        if text is None:
            return default
        try:
            return parse(text)
        except ValueError as error:
            raise UserError(f"--{key} {text}: {error}") from None

    bits = parsed("bits", stage.parse_bits)
    suffix = None if args.output is None else args.output.suffix.lower()
    named = stage.format_for(".png" if suffix is None else suffix, bits)
    if named is None and args.format is None:
        raise UserError(f"{' and '.join(given)} {'writes' if len(given) == 1 else 'write'} .png "
                        f"(png8, png16), .exr or .npy files, not {suffix or 'a file without a suffix'}; "
                        f"name it {args.output.with_suffix('.png').name}, or leave out "
                        f"{', '.join(given)} for an image Pillow writes", file=str(args.output))
    try:
        settings = stage.OutputSettings(transfer=parsed("transfer", stage.parse_transfer, stage.Transfer()),
                                        bits=bits, dither=args.dither or "none",
                                        halftone=parsed("halftone", stage.parse_halftone),
                                        format=args.format or named)
    except ValueError as error:                  # its line names the option
        raise UserError(str(error)) from None
    wanted = stage.FORMATS[settings.format]
    if suffix is not None and suffix != wanted:
        raise UserError(f"--format {settings.format} writes {wanted} files; name it "
                        f"{args.output.with_suffix(wanted).name}", file=str(args.output))
    if settings.format == "exr" and args.background == "transparent":
        raise UserError("--background transparent: OpenEXR's alpha is premultiplied, and the "
                        "frame's colour where nothing is drawn is the background's under alpha 0; "
                        "write --format npy (straight RGBA), or add --alpha OUT.npy")
    return settings


def check_plane_suffixes(args) -> None:
    """--depth: .npy or .exr; --alpha: .png or .npy (one line naming the file)."""
    if args.depth is not None and args.depth.suffix.lower() not in (".npy", ".exr"):
        raise UserError("--depth writes float32 depth as .npy (NumPy) or .exr (OpenEXR); name "
                        "the file e.g. depth.npy", file=str(args.depth))
    if args.alpha is not None and args.alpha.suffix.lower() not in (".png", ".npy"):
        raise UserError("--alpha writes the coverage as .png (8-bit grey) or .npy (float32); "
                        "name the file e.g. alpha.png", file=str(args.alpha))


def _stage_words(settings) -> str:
    """'srgb, 4 bits, bayer8, png8' for the line that says what was written."""
    words = [str(settings.transfer)]
    if settings.quantised:
        words.append(f"{settings.code_bits} bit{'s' if settings.code_bits > 1 else ''}")
        words += [f"halftone {settings.halftone}"] if settings.halftone else \
            ([] if settings.dither == "none" else [settings.dither])
    return ", ".join(words + [settings.format])


def render_frame(args, scene, settings):
    """`render`'s frame and, with output settings, the output stage's array of its linear
    colour and the stage's milliseconds (None, 0 without). The GPU's pass runs on the
    renderer's own context, while it is alive."""
    linear = settings is not None or (args.alpha is not None and args.alpha.suffix.lower() == ".npy")
    traced = args.method == "raytrace"
    if args.backend == "reference":
        if traced:
            from reference.raytrace.pipeline import render as reference_raytrace
            frame = reference_raytrace(scene, *args.size, **_raytrace_options(args))
        else:
            import reference
            frame = reference.render(scene, *args.size, linear=linear)
        if settings is None:
            return frame, None, 0.0
        import reference.output
        start = time.perf_counter()
        staged = reference.output.apply(frame.linear, settings)
        return frame, staged, (time.perf_counter() - start) * 1000.0
    if traced:
        from renderer.gpu.raytracer import RayTracer
        renderer = RayTracer(scene, *args.size, context_kind=args.context, **_raytrace_options(args))
    else:
        from renderer.gpu.pipeline import GpuRenderer
        renderer = GpuRenderer(scene, *args.size, context_kind=args.context)
    with renderer:
        frame = renderer.render() if traced else renderer.render(depth=True, linear=linear)
        if settings is None:
            return frame, None, 0.0
        from renderer.gpu.output import OutputPass
        start = time.perf_counter()
        staged = OutputPass(renderer.ctx).apply(frame.linear, settings)
        return frame, staged, (time.perf_counter() - start) * 1000.0


def write_render(out, output, frame, staged, settings, args) -> None:
    """The files of `render` into the transaction `out`: the image (as drawn, or the output
    stage's array in its format, RGB or RGBA by --background), --depth, --alpha."""
    import numpy as np
    from renderer.core.output_settings import INTEGER_FORMATS
    if settings is None:
        out.image(output, frame.image(args.background))
    else:
        channels = staged if args.background == "transparent" else staged[..., :3]
        if settings.quantised:
            out.png_codes(output, channels, settings.code_bits, INTEGER_FORMATS[settings.format])
        elif settings.format == "exr":
            out.exr(output, channels)
        else:
            out.npy(output, np.ascontiguousarray(channels))
    if args.depth is not None:
        (out.exr if args.depth.suffix.lower() == ".exr" else out.npy)(args.depth, frame.depth)
    if args.alpha is not None:
        if args.alpha.suffix.lower() == ".png":
            out.png_codes(args.alpha, frame.rgba8[..., 3:], 8, 8)
        else:
            out.npy(args.alpha, np.ascontiguousarray(frame.linear[..., 3]))


def cmd_render(args) -> int:
    from renderer.core.imageio import check_outputs, image_format, outputs
    from renderer.core.output_settings import FORMATS
    from renderer.core.paths import output_stem
    settings = output_settings(args)         # a bad option or name: said before any work
    if args.output is not None and settings is None:
        image_format(args.output, alpha=args.background == "transparent")
    check_plane_suffixes(args)
    check_outputs(args.output, args.depth, args.alpha)   # a folder, a file as parent, one file twice
    check_raytrace_options(args)
    scene = _load_traced(args)
    if args.method == "raytrace":
        check_raytrace_render(scene, args.size, [args.backend], args.spp)
    else:
        check_render(scene, args.size, [args.backend])
    suffix = ".png" if settings is None else FORMATS[settings.format]
    output = args.output or Path(f"{output_stem(scene)}{suffix}")
    check_outputs(output, args.depth, args.alpha)
    frame, staged, stage_ms = render_frame(args, scene, settings)
    warn_if_nothing_drawn(scene, frame)
    with outputs(output, args.depth, args.alpha) as out:     # all or none
        write_render(out, output, frame, staged, settings, args)
    if not args.quiet:
        written = [str(path) for path in (output, args.depth, args.alpha) if path is not None]
        written = f"{', '.join(written[:-1])} and {written[-1]}" if len(written) > 1 else written[0]
        method = "" if args.method == "raster" else f"raytrace {args.spp} spp, "
        if args.method == "raytrace" and args.pattern == "adaptive":
            method = f"raytrace adaptive up to {args.spp} spp: {samples_fired(frame)}, "
        stage = "" if settings is None else f"; output {_stage_words(settings)}, {stage_ms:.1f} ms"
        print(f"wrote {written} ({args.size[0]}x{args.size[1]}, {method}{args.backend}, "
              f"{frame.milliseconds:.1f} ms{stage})", file=sys.stderr)
    return 0


def cmd_view(args) -> int:
    """The window viewer (renderer/viewer/viewer.py); without a display, one line and status 2."""
    from renderer.core.imageio import check_outputs, image_format, outputs
    from renderer.core.jsonio import json_text
    from renderer.viewer.reference_view import figures_line
    from renderer.viewer.viewer import Viewer
    scene = _load(args.scene)
    check_render(scene, args.size, ["gpu"])
    if args.method == "raytrace":
        check_raytrace_render(scene, args.size, ["gpu"], 1)
    if args.frames is None and args.stats is not None:
        args.parser.error("--stats needs --frames (the scripted mode)")
    if args.screenshot is not None:          # before the window opens: a screenshot is RGB
        image_format(args.screenshot)
    scripted = args.frames is not None
    check_outputs(args.screenshot, args.stats if scripted else None)
    with Viewer(scene, *args.size, vsync=not args.no_vsync,
                buffering=3 if args.triple_buffering else 2, reference=args.reference,
                screenshot=None if scripted else args.screenshot, method=args.method) as viewer:
        if not scripted:
            print(f"renderer view: {scene.name}; H for help, Esc to quit")
        try:
            stats = viewer.run(args.frames, args.orbit, None)     # the screenshot: below, with --stats
        except KeyboardInterrupt:              # Ctrl-C in the terminal: as good as Esc
            return 0
        figures, samples = viewer.figures, viewer.samples
        shown = viewer.shown_image() if scripted and args.screenshot is not None else None
    if scripted:
        with outputs(args.screenshot, args.stats) as out:    # both or neither
            if shown is not None:
                out.image(args.screenshot, shown)
            if args.stats is not None:
                out.text(args.stats, json_text(stats.summary() | {"reference": figures,
                                                                  "raytrace_spp": samples}))
        print(stats.line())
        if figures is not None:
            print(figures_line(figures))
        if samples is not None:
            print(f"ray tracing: {samples} spp")
        if args.screenshot is not None:
            print(f"wrote {args.screenshot}")
    return 0


def cmd_compare_methods(args) -> int:
    """`compare --methods` (from cmd_compare, its options checked): the table on stdout, its
    figures and images in --out; status 0 (an explanation, not a check)."""
    from renderer.checks.methods import cause_image, compare_methods
    from renderer.core.imageio import check_folder, check_outputs, outputs
    from renderer.core.jsonio import json_text
    from renderer.core.paths import output_stem
    scene = _load_traced(args)
    check_render(scene, args.size, ["gpu"])
    check_raytrace_render(scene, args.size, ["gpu"], args.spp)
    out = check_folder(args.out or Path(f"compare-methods-{output_stem(scene)}"))
    names = [out / name for name in ("raster.png", "raytrace.png", "causes.png", "methods.json")]
    check_outputs(*names)
    result = compare_methods(scene, *args.size, context_kind=args.context, threshold=args.threshold,
                             **_raytrace_options(args))
    warn_if_nothing_drawn(scene, result.raytrace)
    with outputs(*names) as written:             # all four or none
        written.png(names[0], result.raster.image())
        written.png(names[1], result.raytrace.image())
        written.png(names[2], cause_image(result.causes, result.raytrace.rgba8))
        written.text(names[3], json_text(result.as_dict()))
    print(result.table())
    return 0


def cmd_compare_shadows(args) -> int:
    """`compare --shadows-vs-truth` (from cmd_compare): the figures as one JSON line and one
    readable line on stdout, the classification image and the figures in --out; status 0
    (a measurement, not a check)."""
    from renderer.checks.shadow_truth import shadows_vs_truth
    from renderer.core.shadows import has_shadow_maps
    if args.methods:
        args.parser.error("--shadows-vs-truth and --methods are two different comparisons; give one")
    if args.method is not None:
        args.parser.error(f"--shadows-vs-truth measures the rasteriser's shadow maps; leave out "
                          f"--method {args.method}")
    check_raytrace_options(args)
    scene = _load(args.scene)
    if not has_shadow_maps(scene):
        raise UserError("the scene has no shadow maps to hold against ray-cast truth (no light "
                        "with shadows on, nothing that casts or nothing that receives)",
                        file=scene.source or scene.name)
    check_render(scene, args.size, ["reference"])
    names = _measurement_files(args, scene, "shadows", "shadow_truth")
    return _write_measurement(names, shadows_vs_truth(scene, *args.size))


def _measurement_files(args, scene, folder: str, stem: str) -> list[Path]:
    """A measurement's image and figures, STEM.png and STEM.json, in --out (default
    compare-FOLDER-SCENE), checked before anything is rendered."""
    from renderer.core.imageio import check_folder, check_outputs
    from renderer.core.paths import output_stem
    out = check_folder(args.out or Path(f"compare-{folder}-{output_stem(scene)}"))
    names = [out / f"{stem}.png", out / f"{stem}.json"]
    check_outputs(*names)
    return names


def _write_measurement(names: list[Path], result) -> int:
    """Write a measurement's image and figures (both or neither) and print the figures as one
    JSON line and one readable line; status 0 (a measurement, not a check)."""
    from renderer.core.imageio import outputs
    from renderer.core.jsonio import json_text, to_json
    figures = result.as_dict()
    with outputs(*names) as written:
        written.png(names[0], result.image())
        written.text(names[1], json_text(figures))
    print(to_json(figures))
    print(result.line())
    return 0


def cmd_compare_depth(args) -> int:
    """`compare --depth-vs-truth` (from cmd_compare): the figures as one JSON line and one
    readable line on stdout, the error image and the figures in --out; status 0 (a
    measurement, not a check)."""
    from renderer.checks.depth_truth import depth_vs_truth
    if args.methods or args.shadows_vs_truth:
        other = "--methods" if args.methods else "--shadows-vs-truth"
        args.parser.error(f"--depth-vs-truth and {other} are two different comparisons; give one")
    if args.method is not None:
        args.parser.error(f"--depth-vs-truth measures the rasteriser's depth; leave out "
                          f"--method {args.method}")
    check_raytrace_options(args)
    scene = _load(args.scene)
    check_render(scene, args.size, ["gpu"])
    names = _measurement_files(args, scene, "depth", "depth_truth")
    return _write_measurement(names, depth_vs_truth(scene, *args.size, context=args.context))


def cmd_compare(args) -> int:
    from renderer.checks.against_reference import against_reference
    from renderer.core.imageio import check_folder, check_outputs, outputs
    from renderer.core.paths import output_stem
    from renderer.core.jsonio import to_json
    if args.out is not None:
        check_folder(args.out)
    if args.depth_vs_truth:
        return cmd_compare_depth(args)
    if args.shadows_vs_truth:
        return cmd_compare_shadows(args)
    check_raytrace_options(args)
    if args.methods:
        return cmd_compare_methods(args)
    scene = _load_traced(args)
    if args.method == "raytrace":
        check_raytrace_render(scene, args.size, ["gpu", "reference"], args.spp)
    else:
        check_render(scene, args.size, ["gpu", "reference"])
    out = check_folder(args.out or Path(f"compare-{output_stem(scene)}"))
    names = [out / "gpu.png", out / "reference.png", out / "diff.png"]
    check_outputs(*names)
    # Median of a few frames: the first one pays for shader compilation.
    if args.method == "raytrace":
        options = _raytrace_options(args)
        gpu_frame, gpu_ms, gl_info = _raytrace_gpu(scene, args.size, args.context, options, frames=3)
        subpixel_bits = None
    else:
        options = None
        gpu_frame, gpu_ms, gl_info, subpixel_bits = _render_gpu(scene, args.size, args.context, frames=3)
    check = against_reference(scene, args.size, gpu_frame, method=args.method, options=options,
                              subpixel_bits=subpixel_bits, threshold=args.threshold)
    warn_if_nothing_drawn(scene, gpu_frame)
    with outputs(*names) as written:             # all three or none
        written.png(names[0], gpu_frame.rgba8)
        written.png(names[1], check.reference.rgba8)
        written.png(names[2], check.heat)
    figures = check.figures | {"gpu_ms": gpu_ms, "gl_renderer": gl_info["GL_RENDERER"],
                               "context": gl_info["context"], "passes": check.figures["passes"]}
    print(to_json(figures))
    if check.failures:
        print(f"renderer compare: {output_stem(scene)} fails the pipeline tolerance: "
              f"{'; '.join(check.failures)}", file=sys.stderr)
        return 1
    return 0


def cmd_shaders(args) -> int:
    """One set of files per shader variant the scene draws with, named after the variant,
    and a line per variant naming the objects that use it."""
    from renderer.core.drawn import triangle_bound
    from renderer.core.imageio import check_folder, outputs
    from renderer.core.paths import output_stem
    from renderer.core.shadows import has_shadow_maps
    from renderer.gpu.shaders import ShaderVariant, program_sources
    if args.out is not None:
        check_folder(args.out)
    scene = _load(args.scene)
    out = check_folder(args.out or Path(f"shaders-{output_stem(scene)}"))
    users: dict[ShaderVariant, list[str]] = {}
    maps = has_shadow_maps(scene)
    for obj in scene.objects:
        if triangle_bound(obj):            # what the camera pass may draw (renderer/core/drawn.py)
            variant = ShaderVariant.for_material(scene, obj.material,
                                                 shadows=maps and obj.receives_shadows)
            users.setdefault(variant, []).append(obj.name)
    suffixes = {"vertex_shader": "vert", "geometry_shader": "geom", "fragment_shader": "frag"}
    lines = []
    with outputs() as written:                   # every variant's files or none
        for variant, names in users.items():
            files = []
            for stage, source in program_sources(variant).items():
                files.append(written.text(out / f"{variant.name}.{suffixes[stage]}", source.text).name)
            lines.append(f"{variant.name}: {', '.join(files)} (objects: {', '.join(names)})")
    for line in lines:
        print(line)
    return 0


def cmd_report(args) -> int:
    from renderer.core.builtin import builtin_scenes, made_for_raytracing
    from renderer.study.report import run_report
    from renderer.core.imageio import check_folder, check_outputs
    from renderer.study.report_settings import QUICK_SCENES, RAY_QUICK_SCENES
    check_outputs(check_folder(args.out) / "report.md", args.out / "results.csv")
    traced = args.method == "raytrace"
    if args.scenes or args.quick:
        names = args.scenes or (RAY_QUICK_SCENES if traced else QUICK_SCENES)
        scenes = [_load(name) for name in names]
    else:                  # the built-in scenes made for the method (their descriptions say)
        scenes = [_load(name) for name in builtin_scenes() if made_for_raytracing(name) == traced]
        if not scenes:
            raise UserError(f"no built-in scene is made for --method {args.method}; name the "
                            "scenes to report", key="SCENE")
    result = run_report(scenes, args.out, method=args.method, quick=args.quick, size=args.size,
                        cache_dir=args.cache, context_kind=args.context, knobs=args.knobs,
                        address=args.address, workers=args.workers)
    print(f"wrote {args.out / 'report.md'}, results.csv ({len(result.rows)} rows) and "
          f"{len(result.files) - 2} plots in {result.seconds:.0f} s")
    return 0


def cmd_colour(args) -> int:
    """chromaticity.png, luminance.png, munsell.md and colour.json in --out (renderer/study/
    colour_report.py), all or none."""
    from renderer.core.imageio import check_folder, check_outputs
    from renderer.study.colour_report import COLOUR_FILES, write_colour_report
    from renderer.study.colour_source import image_source, is_image_name, scene_source
    out = check_folder(args.out)
    check_outputs(*(out / name for name in COLOUR_FILES))
    if is_image_name(args.source):
        if args.size is not None:
            args.parser.error("--size sets a scene's frame; an image has its own size")
        source = image_source(args.source, args.colorspace, args.backend, args.context)
    else:
        if args.colorspace is not None:
            args.parser.error("--colorspace says how an image is encoded; a scene's frame is linear")
        scene = _load(args.source)
        size = args.size or COLOUR_SIZE
        check_render(scene, size, [args.backend])
        source = scene_source(scene, size, args.backend, args.context)
    written = write_colour_report(source, out)
    pixels = int(source.covered.sum())
    print(f"wrote {', '.join(str(path) for path in written)} ({pixels} pixels, {args.backend})")
    return 0


def cmd_batch(args) -> int:
    """`renderer batch`: everything checked (job file, scenes, outputs, --out's manifest)
    before the executor starts (renderer/batch/run.py); the summary on stderr."""
    from renderer.batch.job_file import read_job
    from renderer.batch.run import plan_job, run_plan
    from renderer.cluster.executor import InProcessExecutor, open_executor
    plan = plan_job(read_job(args.job), args.out, compare=args.compare)
    # Nothing left to render (a finished job run again): no workers to start.
    opened = open_executor(args.address, args.workers) if plan.todo else InProcessExecutor()
    with opened as executor:
        summary = run_plan(plan, executor, context_kind=args.context)
    for line in summary.lines():
        print(f"renderer {line}", file=sys.stderr)
    return 1 if summary.failed else 0


def cmd_scenes(args) -> int:
    from renderer.core.builtin import builtin_scenes, describe
    for name in builtin_scenes():
        print(f"{name}\t{describe(name)}")
    return 0


def cmd_extremes(args) -> int:
    """extremes.json and extremes.md in --out; status 1 when a case fails (as authored)."""
    from renderer.core.builtin import resolve_scene
    from renderer.gpu.context import make_context, release_context
    from renderer.study.extremes import all_pass, extreme_scenes, measure_extremes, write_report
    from renderer.study.shadow_sweep import measure_sweep, sweep_acne
    from renderer.core.scene_file import load_scene
    from renderer.core.imageio import check_folder, check_outputs
    check_outputs(check_folder(args.out) / "extremes.json", args.out / "extremes.md")
    extra = [resolve_scene(arg) for arg in args.scenes]
    for path in extra:
        load_scene(path)                     # a bad extra scene: its one line before any work
    kinds = ("egl", "osmesa") if args.context == "both" else (args.context,)
    contexts = {}
    try:
        for kind in kinds:
            contexts[kind] = make_context(kind)
        methods = ("raster", "raytrace") if args.method == "both" else (args.method,)
        cases = measure_extremes(extreme_scenes(extra), args.size, contexts, methods)
        sweep = None if args.no_sweep or "raster" not in methods else measure_sweep(args.size, contexts)
    finally:
        for ctx in contexts.values():
            release_context(ctx)
    json_path, md_path = write_report(args.out, cases, args.size, sweep)
    for case in cases:
        state = "refused" if "refused" in case else ("pass" if case["passes"] else "FAIL")
        if case.get("before"):
            state = f"{state.lower()} (the 'before' of reversed-Z)"
        print(f"{case['case']}: {state}")
    for row in sweep or ():
        print(f"light elevation {row['elevation']}: {sweep_acne(row)} acne pixels")
    print(f"wrote {json_path} and {md_path}")
    return 0 if all_pass(cases, sweep or ()) else 1


# Options that name a file or folder to write (or, --cache, to read and write): each goes
# through renderer.core.paths.checked_path before the command starts. Scene arguments and
# mesh files are checked where they are read (resolve_scene, load_scene, load_mesh).
PATH_OPTIONS = ("output", "depth", "alpha", "out", "screenshot", "stats", "cache")


def _check_paths(args) -> None:
    from renderer.core.paths import checked_path
    for name in PATH_OPTIONS:
        if getattr(args, name, None) is not None:
            setattr(args, name, checked_path(getattr(args, name)))


COMMANDS = {"render": cmd_render, "view": cmd_view, "compare": cmd_compare, "shaders": cmd_shaders, "report": cmd_report,
            "batch": cmd_batch, "scenes": cmd_scenes, "extremes": cmd_extremes, "colour": cmd_colour}


def main(argv=None) -> int:
    try:
        try:
            args = build_parser().parse_args(argv)
        except SystemExit as done:       # --help, --version: printed; their status
            return done.code
        _check_paths(args)
        from renderer.core.memory import limit_set
        max_memory = getattr(args, "max_memory", None)       # else the limit in force stays
        with limit_set(max_memory) if max_memory is not None else contextlib.nullcontext():
            return COMMANDS[args.command](args)
    except UsageError as error:
        print(f"{error.prog}: {escaped(error.reason)}", file=sys.stderr)
        print(error.usage, file=sys.stderr)
        return 2
    except UserError as error:           # 2: the user's mistake; 1: a SystemFault (errors.py)
        print(f"renderer: {error.line()}", file=sys.stderr)
        return error.status
    except BrokenPipeError:              # `renderer scenes | head`: the reader left, not an error
        sys.stdout = open(os.devnull, "w")
        return 0


if __name__ == "__main__":
    sys.exit(main())
