"""`renderer report`: error against run time over quality settings (renderer/study/report.py),
in this process or on Ray's workers."""

from __future__ import annotations

from pathlib import Path

from renderer.cli.options import load, memory_option, output_path, parse_size, positive_int
from renderer.errors import UserError


def add_parser(sub) -> None:
    """`report`'s parser: the scenes, --out, the sweep's size and knobs, where it runs."""
    report = sub.add_parser("report", help="error against run time over quality settings "
                                           "(results.csv, plots, report.md)")
    report.add_argument("scenes", nargs="*", metavar="SCENE",
                        help="scene files or built-in names (default: the built-in scenes made "
                             "for --method: for raytrace those with spheres, planes, k_r or k_t, "
                             "for raster the others; with --quick, two small ones, or classic)")
    report.add_argument("--out", type=output_path, required=True, help="folder for the report")
    extent = report.add_mutually_exclusive_group()
    extent.add_argument("--quick", action="store_true",
                        help="a reduced sweep of two small scenes at 64x48 (for CI: under 90 s)")
    extent.add_argument("--exhaustive", action="store_true",
                        help="every setting, 64 samples a pixel and 5 runs each (hours for the "
                             "built-in scenes; the default sweep takes up to 16 samples and 3 runs)")
    report.add_argument("--size", type=parse_size, metavar="WxH",
                        help="image size (default 160x120; 64x48 with --quick)")
    report.add_argument("--cache", type=Path, metavar="DIR",
                        help="ground-truth cache (default ~/.cache/checked-renderer/truth)")
    report.add_argument("--context", choices=("auto", "egl", "osmesa"), default="auto",
                        help="headless GL context (default: EGL, then OSMesa)")
    report.add_argument("--method", choices=("raster", "raytrace", "radiosity"), default="raster",
                        help="raster (default): the rasteriser's knobs; raytrace: the ray "
                             "tracer's (samples per pixel by pattern, adaptive thresholds, max "
                             "depth), against a ray-traced ground truth; radiosity: element size, "
                             "hemicube, iterations, against a path-traced truth")
    report.add_argument("--knobs", type=lambda text: tuple(k.strip() for k in text.split(",")),
                        metavar="K,K", help="only these knob families (default all): raster: "
                        "antialiasing, tessellation, shading, precision, shadows (map resolution, "
                        "filter, bias rule against ray-cast truth), filter and texture_resolution "
                        "(textured scenes), output (the output stage's methods at 1 to 8 bits); raytrace: antialiasing, max_depth, precision; "
                        "radiosity: element_size, hemicube, iterations")
    report.add_argument("--address", metavar="auto|HOST:PORT",
                        help="run the settings on a running Ray cluster's workers (auto: the one "
                             "`ray start` made on this machine); default: this process. results.csv "
                             "is the same apart from the times and the `worker` that took them")
    report.add_argument("--workers", type=positive_int, metavar="N",
                        help="run the settings on N Ray workers (default with --address: one per "
                             "CPU); without --address, on a local Ray started for this report")
    memory_option(report)


def run(args) -> int:
    """The scenes checked, the sweep run, one line saying what was written."""
    from renderer.core.builtin import builtin_scenes, made_for
    from renderer.study.report import run_report
    from renderer.core.imageio import check_folder, check_outputs
    from renderer.study.report_settings import QUICK_SCENES_OF
    check_outputs(check_folder(args.out) / "report.md", args.out / "results.csv")
    if args.scenes or args.quick:
        names = args.scenes or QUICK_SCENES_OF[args.method]
        scenes = [load(name) for name in names]
    else:                  # the built-in scenes made for the method (their descriptions say)
        scenes = [load(name) for name in builtin_scenes() if made_for(name) == args.method]
        if not scenes:
            raise UserError(f"no built-in scene is made for --method {args.method}; name the "
                            "scenes to report", key="SCENE")
    sweep_name = "quick" if args.quick else "exhaustive" if args.exhaustive else "standard"
    result = run_report(scenes, args.out, method=args.method, sweep_name=sweep_name, size=args.size,
                        cache_dir=args.cache, context_kind=args.context, knobs=args.knobs,
                        address=args.address, workers=args.workers)
    print(f"wrote {args.out / 'report.md'}, results.csv ({len(result.rows)} rows) and "
          f"{len(result.files) - 2} plots in {result.seconds:.0f} s")
    return 0
