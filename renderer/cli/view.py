"""`renderer view`: a scene in a window (renderer/viewer/), or, with --frames, a scripted run
that prints frame-time statistics and writes a screenshot."""

from __future__ import annotations

from renderer.cli.options import DEFAULT_SIZE, load, memory_option, output_path, parse_size, positive_int
from renderer.core.memory import raster_need


def add_parser(sub) -> None:
    """`view`'s parser: the window's size, the scripted mode, what the window starts with."""
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
                           "otherwise the file the S key writes (default out/view-SCENE-NNN.png); "
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
    view.add_argument("--method", choices=("raster", "raytrace", "pathtrace", "radiosity"), default="raster",
                      help="start with the rasteriser (default), the ray tracer, the path tracer or "
                           "radiosity; the tracers refine while the view is still, one sample per "
                           "pixel a frame, radiosity converges a step a frame (the M key)")
    memory_option(view)


def run(args) -> int:
    """The window viewer (renderer/viewer/viewer.py); without a display, one line and status 2."""
    from renderer.core.imageio import check_outputs, image_format, outputs
    from renderer.core.jsonio import json_text
    from renderer.viewer.reference_view import figures_line
    from renderer.viewer.viewer import Viewer
    from renderer.methods import METHODS
    chosen = METHODS[args.method]
    scene = load(args.scene, raster_need(args.size, ["gpu"]),    # the viewer's rasteriser is always made
                 chosen.need(args.size, ["gpu"], chosen.options()))
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
        figures, samples, radiosity = viewer.figures, viewer.samples, viewer.radiosity_line
        shown = viewer.shown_image() if scripted and args.screenshot is not None else None
    if scripted:
        with outputs(args.screenshot, args.stats) as out:    # both or neither
            if shown is not None:
                out.image(args.screenshot, shown)
            if args.stats is not None:
                out.text(args.stats, json_text(stats.summary() | {"reference": figures,
                                                                  "raytrace_spp": samples,
                                                                  "radiosity": radiosity}))
        print(stats.line())
        if figures is not None:
            print(figures_line(figures))
        if samples is not None:
            print(f"{'path' if args.method == 'pathtrace' else 'ray'} tracing: {samples} spp")
        if radiosity is not None:
            print(radiosity)
        if args.screenshot is not None:
            print(f"wrote {args.screenshot}")
    return 0
