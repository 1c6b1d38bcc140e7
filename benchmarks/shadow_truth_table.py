"""The shadow maps against ray-cast truth on every built-in scene with shadow maps, per size and
filter, printed as a markdown table (issue 28).

    .venv/bin/python benchmarks/shadow_truth_table.py [--sizes 320x240,640x480]
        [--filters hard,pcf2x2,pcf3x3,pcf5x5] [--scenes NAME,...] [--json FILE]

Each scene of renderer.core.builtin.builtin_scenes() whose shadow_layout has maps at the size
is measured by renderer/checks/shadow_truth.py's shadows_vs_truth (the reference's lookup
against the ray tracer's shadow rays) with every light's Shadow(filter=...) set to each
filter in turn (renderer/study/shadow_report.py with_shadow_setting), the rest as authored.
Columns: the pixels compared (lit receivers, any light), wrong beyond 2 px of the true shadow
boundary (count and share of those compared: the headline), acne pixels, wrong outside the
1-texel band (count and share of all pixels) and each light's world texel (d0: directional
light 0, the map's t; p0: point light 0, t at its median compared pixel). The figures do not
depend on the machine; the time does (the whole table: about five minutes on the project's
2-core machine). Not a test.
"""

from __future__ import annotations

import argparse
import json
import time
from pathlib import Path

from renderer.checks.shadow_truth import EDGE_KEY, shadows_vs_truth
from renderer.cli.options import parse_size
from renderer.core.builtin import builtin_scenes
from renderer.core.scene_file import load_scene
from renderer.core.shadows import shadow_layout
from renderer.study.shadow_report import with_shadow_setting

from common import machine, revision       # benchmarks/common.py

FILTERS = "hard,pcf2x2,pcf3x3,pcf5x5"
SIZES = "320x240,640x480"


def shadowed_scenes(names, size) -> list[str]:
    """The built-in scenes among `names` (all if empty) with shadow maps at `size`."""
    scenes = builtin_scenes()
    return [name for name in (names or scenes)
            if shadow_layout(load_scene(scenes[name]), *size).any]


def texels(figures: dict) -> str:
    """Each light's world texel, e.g. "d0 0.00316, p0 0.0169"."""
    return ", ".join(f"{light['kind'][0]}{light['index']} "
                     + ("-" if light["world_texel"] is None else f"{light['world_texel']:.3g}")
                     for light in figures["lights"])


def row(name: str, size, filter: str) -> dict:
    """The figures of one scene at one size with one filter."""
    scene = with_shadow_setting(load_scene(builtin_scenes()[name]), "filter", filter)
    figures = shadows_vs_truth(scene, *size).as_dict()
    return {"scene": name, "size": f"{size[0]}x{size[1]}", "filter": filter,
            "considered": figures["considered_pixels"],
            "beyond": figures[f"{EDGE_KEY}_pixels"], "beyond_fraction": figures[f"{EDGE_KEY}_fraction"],
            "acne": figures["acne_pixels"], "outside_band": figures["wrong_outside_band_pixels"],
            "outside_band_fraction": figures["wrong_outside_band_fraction"], "texels": texels(figures)}


def line(r: dict) -> str:
    return (f"| {r['scene']} | {r['size']} | {r['filter']} | {r['considered']:,} | {r['beyond']:,} "
            f"({r['beyond_fraction']:.3%}) | {r['acne']:,} | {r['outside_band']:,} "
            f"({r['outside_band_fraction']:.3%}) | {r['texels']} |")


def main() -> None:
    options = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    options.add_argument("--sizes", default=SIZES)
    options.add_argument("--filters", default=FILTERS)
    options.add_argument("--scenes", default="", help="comma-separated built-in scenes (default: all with shadow maps)")
    options.add_argument("--json", help="also write the rows to this JSON file")
    options.add_argument("--out", help="also write table.md (this output) and rows.json to this folder "
                                       "(docs/report/shadow-truth: the README's table comes from it)")
    args = options.parse_args()
    sizes = [parse_size(s) for s in args.sizes.split(",")]
    names = [n for n in args.scenes.split(",") if n]
    start = time.perf_counter()
    lines = []

    def say(text: str = "") -> None:
        lines.append(text)
        print(text, flush=True)

    say(f"Shadow maps against ray-cast truth; {machine()}; {time.strftime('%Y-%m-%d %H:%M')}; "
        f"commit {revision()}")
    say()
    say("| scene | size | filter | compared px | wrong beyond 2 px | acne px | wrong outside the band "
        "| world texel |")
    say("| --- | --- | --- | ---: | ---: | ---: | ---: | --- |")
    rows = []
    for size in sizes:
        for name in shadowed_scenes(names, size):
            for filter in args.filters.split(","):
                rows.append(row(name, size, filter))
                say(line(rows[-1]))
    say()
    say("Per scene, the worst of the four filters (acne px / wrong beyond 2 px, share of compared):")
    say()
    sizes_seen = list(dict.fromkeys(r["size"] for r in rows))
    say("| scene | " + " | ".join(sizes_seen) + " |")
    say("| --- |" + " ---: |" * len(sizes_seen))
    for name in dict.fromkeys(r["scene"] for r in rows):
        cells = []
        for size in sizes_seen:
            mine = [r for r in rows if r["scene"] == name and r["size"] == size]
            cells.append(f"{max(r['acne'] for r in mine)} / {max(r['beyond_fraction'] for r in mine):.3%}"
                         if mine else "-")
        say(f"| {name} | " + " | ".join(cells) + " |")
    say()
    worst = max(rows, key=lambda r: r["beyond_fraction"])
    say(f"Acne: {sum(r['acne'] for r in rows)} pixels in all. Wrong beyond 2 px: at most "
        f"{worst['beyond_fraction']:.3%} ({worst['scene']} {worst['size']} {worst['filter']}).")
    say(f"{len(rows)} rows in {time.perf_counter() - start:.0f} s. Reproduce: .venv/bin/python "
        f"benchmarks/shadow_truth_table.py --sizes {args.sizes} --filters {args.filters}"
        + (f" --scenes {args.scenes}" if names else ""))
    if args.json:
        with open(args.json, "w") as out:
            json.dump(rows, out, indent=1)
    if args.out:
        folder = Path(args.out)
        folder.mkdir(parents=True, exist_ok=True)
        # a page of the manual (docs/report/index.md): its title first
        (folder / "table.md").write_text("# Shadow maps against ray-cast truth\n\n" + "\n".join(lines) + "\n")
        (folder / "rows.json").write_text(json.dumps(rows, indent=1) + "\n")


if __name__ == "__main__":
    main()
