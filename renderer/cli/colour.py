"""`renderer colour`: the CIE chromaticity diagram, luminance histogram and Munsell table of
an image or a scene's frame (renderer/study/colour_report.py)."""

from __future__ import annotations

from renderer.cli.options import load, output_path, parse_size
from renderer.core.memory import raster_need

COLOUR_SIZE = (320, 240)             # `renderer colour`'s frame of a scene


def add_parser(sub) -> None:
    """`colour`'s parser: the source, --out, the backend, an image's colour space, a scene's
    frame size, the context."""
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


def run(args) -> int:
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
        size = args.size or COLOUR_SIZE
        scene = load(args.source, raster_need(size, [args.backend]))
        source = scene_source(scene, size, args.backend, args.context)
    written = write_colour_report(source, out)
    pixels = int(source.covered.sum())
    print(f"wrote {', '.join(str(path) for path in written)} ({pixels} pixels, {args.backend})")
    return 0
