"""`renderer render`: a scene to an image file, with --depth and --alpha beside it, through
the output stage (docs/conventions.md, "Output") when any of its options is given."""

from __future__ import annotations

import contextlib
import sys
import time

from renderer.cli.options import (check_raytrace_options, load_traced, memory_option, output_path,
                                  raytrace_options, scene_options, spelled, warn_if_nothing_drawn)
from renderer.core.frame import BACKGROUNDS
from renderer.errors import OptionError, UserError


def add_parser(sub) -> None:
    """`render`'s parser: the scene and method options, the files, the output stage."""
    render = sub.add_parser("render", help="render a scene to PNG")
    scene_options(render)
    raytrace_options(render)
    render.add_argument("-o", "--output", type=output_path, metavar="OUT.png",
                        help="image to write, in the format its suffix names (.png, .jpg, .webp, "
                             ".tif, ...; default: out/SCENE_NAME.png)")
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
    memory_option(render)


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


OUTPUT_OPTIONS = ("transfer", "bits", "dither", "halftone", "format")     # the stage's own


def output_settings(args):
    """The output stage's OutputSettings from render's options (-o's suffix names the format:
    .exr and .npy are the stage's float formats even with no option of its own), or None when
    none of OUTPUT_OPTIONS is given and -o is an image Pillow writes (the frame's rgba8 as
    drawn). Checked before any work:
    each refusal is one line naming the option (or -o's file) and the reason, status 2."""
    from renderer.core import output_settings as stage
    given = [f"--{key}" for key in OUTPUT_OPTIONS if getattr(args, key) is not None]
    suffix = None if args.output is None else args.output.suffix.lower()
    if not given and stage.format_for(suffix or ".png") not in stage.FLOAT_FORMATS:
        return None                 # -o x.exr or x.npy alone: the stage's float format by suffix

    def parsed(key, parse, default=None):
        text = getattr(args, key)
        if text is None:
            return default
        try:
            return parse(text)
        except ValueError as error:
            raise UserError(f"--{key} {text}: {error}") from None

    bits = parsed("bits", stage.parse_bits)
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
        settings.check_background(args.background)
    except OptionError as error:
        raise UserError(spelled(error, args)) from None
    wanted = stage.FORMATS[settings.format]
    if suffix is not None and suffix != wanted:
        raise UserError(f"--format {settings.format} writes {wanted} files; name it "
                        f"{args.output.with_suffix(wanted).name}", file=str(args.output))
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
    from renderer.methods import open_renderer
    linear = settings is not None or (args.alpha is not None and args.alpha.suffix.lower() == ".npy")
    with open_renderer(scene, args.size, method=args.method, backend=args.backend,
                       options=args.options, context_kind=args.context) as renderer, \
            progress_bar(args, renderer.height) as progress:
        frame = renderer.render(depth=True, linear=linear, progress=progress)
        if settings is None:
            return frame, None, 0.0
        start = time.perf_counter()
        staged = _output_stage(args.backend, renderer).apply(frame.linear, settings)
        return frame, staged, (time.perf_counter() - start) * 1000.0


@contextlib.contextmanager
def progress_bar(args, rows: int):
    """progress(rows done, rows) for Renderer.render: a bar on stderr (tqdm) for a frame that
    takes more than two seconds (a ray-traced render of many samples), when stderr is a
    terminal and not --quiet; it goes when the frame is done."""
    from tqdm import tqdm
    bar = tqdm(total=rows, unit="row", file=sys.stderr, delay=2.0, leave=False, dynamic_ncols=True,
               disable=args.quiet or not sys.stderr.isatty())

    def progress(done: int, total: int) -> None:
        bar.update(done - bar.n)
    try:
        yield progress
    finally:
        bar.close()


def _output_stage(backend: str, renderer):
    """The output stage's twin of `backend`: the GPU's pass on the renderer's context, or
    the reference's (reference/output/)."""
    if backend == "reference":
        import reference.output
        return reference.output
    from renderer.gpu.output import OutputPass
    return OutputPass(renderer.ctx)


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


def run(args) -> int:
    """Every option and output name checked before any work; the files all or none; one
    line on stderr saying what was written (unless --quiet)."""
    from renderer.core.imageio import check_outputs, image_format, outputs
    from renderer.methods import method
    from renderer.core.output_settings import FORMATS
    from renderer.core.paths import default_output, output_stem
    settings = output_settings(args)         # a bad option or name: said before any work
    if args.output is not None and settings is None:
        image_format(args.output, alpha=args.background == "transparent")
    check_plane_suffixes(args)
    check_outputs(args.output, args.depth, args.alpha)   # a folder, a file as parent, one file twice
    check_raytrace_options(args)
    chosen = method(args.method)
    scene = load_traced(args, chosen.need(args.size, [args.backend], args.options))
    suffix = ".png" if settings is None else FORMATS[settings.format]
    output = args.output or default_output(f"{output_stem(scene)}{suffix}")
    check_outputs(output, args.depth, args.alpha)
    frame, staged, stage_ms = render_frame(args, scene, settings)
    warn_if_nothing_drawn(scene, frame)
    with outputs(output, args.depth, args.alpha) as out:     # all or none
        write_render(out, output, frame, staged, settings, args)
    if not args.quiet:
        written = [str(path) for path in (output, args.depth, args.alpha) if path is not None]
        written = f"{', '.join(written[:-1])} and {written[-1]}" if len(written) > 1 else written[0]
        words = chosen.words(args.options, frame)
        stage = "" if settings is None else f"; output {_stage_words(settings)}, {stage_ms:.1f} ms"
        print(f"wrote {written} ({args.size[0]}x{args.size[1]}, {words + ', ' if words else ''}{args.backend}, "
              f"{frame.milliseconds:.1f} ms{stage})", file=sys.stderr)
    return 0
