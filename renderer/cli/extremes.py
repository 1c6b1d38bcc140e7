"""`renderer extremes`: the extreme scenes (assets/extreme/) through both pipelines, and the
shadow maps' light-elevation sweep, reported as extremes.json and extremes.md."""

from __future__ import annotations


from renderer.cli.options import memory_option, output_path, parse_size
from renderer.core.paths import default_output


def add_parser(sub) -> None:
    """`extremes`' parser: further scenes, --out, --size, the contexts and methods, --no-sweep."""
    extremes = sub.add_parser("extremes", help="render the extreme scenes (assets/extreme/) through "
                                               "both pipelines and report their stability")
    extremes.add_argument("scenes", nargs="*", help="further scene files to measure alike")
    extremes.add_argument("--out", type=output_path, default=default_output("extremes"),
                          help="folder for extremes.json and extremes.md (default: out/extremes)")
    extremes.add_argument("--size", type=parse_size, default=(320, 240), metavar="WxH",
                          help="image size in pixels (default 320x240)")
    extremes.add_argument("--context", choices=("both", "egl", "osmesa"), default="both",
                          help="GL contexts to render with (default: both)")
    extremes.add_argument("--method", choices=("both", "raster", "raytrace", "radiosity"), default="both",
                          help="which cases: rasterised, ray traced (scene files named rt_*), "
                               "radiosity's (named rad_*), or every kind (both, the default)")
    extremes.add_argument("--no-sweep", action="store_true",
                          help="leave out the light-elevation sweep of shadow maps (measured "
                               "with the rasterised cases otherwise)")
    memory_option(extremes)


def run(args) -> int:
    """extremes.json and extremes.md in --out; status 1 when a case fails (as authored)."""
    from renderer.core.builtin import resolve_scene
    from renderer.gpu.context import make_context, release_context
    from renderer.study.extremes import (CASES, all_pass, case_state, extreme_scenes, measure_extremes,
                                         summary, write_report)
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
        methods = tuple(CASES) if args.method == "both" else (args.method,)
        def said(case):                   # each case as it finishes: minutes of work in all
            print(f"{case['case']}: {case_state(case)}", flush=True)
        cases = measure_extremes(extreme_scenes(extra), args.size, contexts, methods, on_case=said)
        sweep = None if args.no_sweep or "raster" not in methods else measure_sweep(
            args.size, contexts, on_row=lambda row: print(
                f"light elevation {row['elevation']}: {sweep_acne(row)} acne pixels", flush=True))
    finally:
        for ctx in contexts.values():
            release_context(ctx)
    json_path, md_path = write_report(args.out, cases, args.size, sweep)
    print(summary(cases))
    print(f"wrote {json_path} and {md_path}")
    return 0 if all_pass(cases, sweep or ()) else 1
