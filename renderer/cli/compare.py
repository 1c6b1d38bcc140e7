"""`renderer compare`: a scene through the GPU and the NumPy reference against the pipeline
tolerance; with --methods the rasteriser against the ray tracer, with --shadows-vs-truth the
shadow maps against ray-cast shadows, with --depth-vs-truth the GPU's depth against ray-cast
depth, with --radiosity-vs-pathtrace radiosity against the path tracer."""

from __future__ import annotations

import statistics
import sys
from pathlib import Path

from renderer.checks.tolerance import PIPELINE_TOLERANCE
from renderer.cli.options import (channel_threshold, check_raytrace_options, load, load_traced,
                                  memory_option, output_path, raytrace_options, scene_options, spelled,
                                  warn_if_nothing_drawn)
from renderer.core.memory import raster_need
from renderer.errors import OptionError, UserError


def add_parser(sub) -> None:
    """`compare`'s parser: the scene and method options, --out, the three other comparisons,
    --threshold."""
    compare = sub.add_parser(
        "compare", help="render through the GPU and the reference and compare",
        description="Render a scene through the GPU and the NumPy reference, write gpu.png, "
                    "reference.png and diff.png, and print the figures as one JSON object. "
                    "Exit status: 0 when the two agree within the pipeline tolerance "
                    f"({PIPELINE_TOLERANCE.describe()}; docs/conventions.md), 1 when they do not "
                    "(what fails is said on stderr), 2 for bad input. With --methods: the "
                    "rasteriser against the ray tracer instead, status 0; with --shadows-vs-truth: "
                    "the rasteriser's shadow maps against ray-cast shadows, status 0; with "
                    "--depth-vs-truth: the GPU's depth against ray-cast depth, status 0; with "
                    "--radiosity-vs-pathtrace: radiosity against the path tracer, status 0.")
    scene_options(compare)
    raytrace_options(compare)
    compare.add_argument("--out", type=output_path, help="folder for gpu.png, reference.png, diff.png "
                                                   "(default: out/compare-SCENE_NAME)")
    compare.add_argument("--methods", action="store_true",
                         help="the rasteriser against the ray tracer (--spp, --pattern, --max-depth, "
                              "--seed), both on the GPU: where they differ and why (shadows, "
                              "reflection, edges, tessellation, ...); writes raster.png, raytrace.png, "
                              "causes.png and methods.json (default folder: compare-methods-SCENE_NAME)")
    compare.add_argument("--tessellate", type=float, nargs="?", const=0.25, default=None, metavar="PIXELS",
                         help="with --methods: draw each untextured analytic sphere through the "
                              "tessellation stages, levels by need keeping the surface within PIXELS "
                              "(default 0.25) of its triangles, instead of as an icosphere "
                              "(docs/tessellation.md)")
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
    compare.add_argument("--radiosity-vs-pathtrace", action="store_true",
                         help="radiosity against the path tracer (4096 paths a pixel) at three "
                              "element sizes, each half the last (--element-size, default the "
                              "scene's diagonal / 6; --hemicube): the mean |difference| as the "
                              "elements refine; writes radiosity_vs_pathtrace.png (the finest "
                              "size's difference) and .json (default folder: "
                              "compare-radiosity-SCENE_NAME)")
    compare.add_argument("--threshold", type=channel_threshold, default=PIPELINE_TOLERANCE.threshold,
                         metavar="LEVELS",
                         help="per-channel threshold in levels of 255, 0 to 255; the pipeline "
                              f"tolerance with this threshold decides the exit status (default "
                              f"{PIPELINE_TOLERANCE.threshold}, the tolerance's own)")
    memory_option(compare)


def _render_gpu(scene, args, frames=1):
    """(the median frame's Frame, its milliseconds, gl_info, the context's subpixel bits for
    the reference rasteriser) of `frames` GPU frames."""
    from renderer.methods import open_renderer
    with open_renderer(scene, args.size, method=args.method, options=args.options,
                       context_kind=args.context) as renderer:
        timings, frame = [], None
        for _ in range(frames):
            frame = renderer.render(depth=True)
            timings.append(frame.milliseconds)
        # Read while the context is alive: afterwards it no longer knows its kind.
        return frame, statistics.median(timings), renderer.gl_info, renderer.subpixel_bits


def run_methods(args) -> int:
    """`compare --methods` (from run, its options checked): the table on stdout, its
    figures and images in --out; status 0 (an explanation, not a check)."""
    from renderer.checks.methods import cause_image, compare_methods
    from renderer.core.imageio import check_folder, check_outputs, outputs
    from renderer.core.jsonio import json_text
    from renderer.core.paths import default_output, output_stem
    from renderer.methods import METHODS
    scene = load_traced(args, *(chosen.need(args.size, ["gpu"], args.options if chosen.options
                                            is type(args.options) else chosen.options())
                                for chosen in METHODS.values()))
    if args.tessellate is not None:
        from renderer.core.tessellation import with_tessellated_spheres
        if not args.tessellate > 0 or args.tessellate == float("inf"):
            raise UserError(f"must be a number of pixels above 0, got {args.tessellate:g}", key="--tessellate")
        scene, count = with_tessellated_spheres(scene, args.tessellate)
        if not count:
            raise UserError("the scene has no untextured analytic sphere to tessellate", key="--tessellate")
    out = check_folder(args.out or default_output(f"compare-methods-{output_stem(scene)}"))
    names = [out / name for name in ("raster.png", "raytrace.png", "causes.png", "methods.json")]
    check_outputs(*names)
    result = compare_methods(scene, *args.size, context_kind=args.context, threshold=args.threshold,
                             options=args.options)
    warn_if_nothing_drawn(scene, result.raytrace)
    with outputs(*names) as written:             # all four or none
        written.png(names[0], result.raster.image())
        written.png(names[1], result.raytrace.image())
        written.png(names[2], cause_image(result.causes, result.raytrace.rgba8))
        written.text(names[3], json_text(result.as_dict()))
    print(result.table())
    return 0


def run_shadows(args) -> int:
    """`compare --shadows-vs-truth` (from run): the figures as one JSON line and one
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
    scene = load(args.scene, raster_need(args.size, ["reference"]))
    if not has_shadow_maps(scene):
        raise UserError("the scene has no shadow maps to hold against ray-cast truth (no light "
                        "with shadows on, nothing that casts or nothing that receives)",
                        file=scene.source or scene.name)
    names = _measurement_files(args, scene, "shadows", "shadow_truth")
    return _write_measurement(names, shadows_vs_truth(scene, *args.size))


def _measurement_files(args, scene, folder: str, stem: str) -> list[Path]:
    """A measurement's image and figures, STEM.png and STEM.json, in --out (default
    compare-FOLDER-SCENE), checked before anything is rendered."""
    from renderer.core.imageio import check_folder, check_outputs
    from renderer.core.paths import default_output, output_stem
    out = check_folder(args.out or default_output(f"compare-{folder}-{output_stem(scene)}"))
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


def run_depth(args) -> int:
    """`compare --depth-vs-truth` (from run): the figures as one JSON line and one
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
    scene = load(args.scene, raster_need(args.size, ["gpu"]))
    names = _measurement_files(args, scene, "depth", "depth_truth")
    return _write_measurement(names, depth_vs_truth(scene, *args.size, context=args.context))


def run_radiosity(args) -> int:
    """`compare --radiosity-vs-pathtrace` (from run): the figures as one JSON line and one
    readable line, the difference image and the figures in --out; status 0 (a measurement)."""
    from renderer.checks.radiosity_vs_pathtrace import radiosity_vs_pathtrace
    from renderer.core.radiosity_options import RadiosityOptions
    others = [flag for flag, given in (("--methods", args.methods), ("--shadows-vs-truth", args.shadows_vs_truth),
                                       ("--depth-vs-truth", args.depth_vs_truth)) if given]
    if others:
        args.parser.error(f"--radiosity-vs-pathtrace and {others[0]} are two different comparisons; give one")
    if args.method is not None:
        args.parser.error(f"--radiosity-vs-pathtrace draws both methods; leave out --method {args.method}")
    try:
        options = RadiosityOptions(element_size=args.element_size, hemicube=args.hemicube or 64)
    except OptionError as error:
        args.parser.error(spelled(error, args))
    scene = load(args.scene, raster_need(args.size, ["gpu"]))
    names = _measurement_files(args, scene, "radiosity", "radiosity_vs_pathtrace")
    return _write_measurement(names, radiosity_vs_pathtrace(scene, *args.size, options.element_size,
                                                            options.hemicube, args.context))


def run(args) -> int:
    """The GPU's frame (the median of three) against the reference's: the figures as one JSON
    line, the images in --out; status 1 when they fail the pipeline tolerance. The other
    comparisons branch off here."""
    from renderer.checks.against_reference import against_reference
    from renderer.methods import method
    from renderer.core.imageio import check_folder, check_outputs, outputs
    from renderer.core.paths import default_output, output_stem
    from renderer.core.jsonio import to_json
    if args.out is not None:
        check_folder(args.out)
    if args.radiosity_vs_pathtrace:
        return run_radiosity(args)
    if args.depth_vs_truth:
        return run_depth(args)
    if args.shadows_vs_truth:
        return run_shadows(args)
    check_raytrace_options(args)
    if args.methods:
        return run_methods(args)
    if args.tessellate is not None:
        args.parser.error("--tessellate is for --methods: the rasteriser against the ray tracer")
    scene = load_traced(args, method(args.method).need(args.size, ["gpu", "reference"], args.options))
    out = check_folder(args.out or default_output(f"compare-{output_stem(scene)}"))
    names = [out / "gpu.png", out / "reference.png", out / "diff.png"]
    check_outputs(*names)
    # Median of a few frames: the first one pays for shader compilation.
    gpu_frame, gpu_ms, gl_info, subpixel_bits = _render_gpu(scene, args, frames=3)
    check = against_reference(scene, args.size, gpu_frame, method=args.method, options=args.options,
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
