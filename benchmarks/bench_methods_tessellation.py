"""Where the rasteriser and the ray tracer differ on a scene of analytic spheres, before and
after the spheres go through the tessellation stages (issue 34), printed and written to
benchmarks/results/methods_tessellation.json and .md (the README and docs/tessellation.md
include the .md):

    .venv/bin/python benchmarks/bench_methods_tessellation.py [--scene classic] [--sizes 320x240,640x480]

For each size: `renderer compare SCENE --methods` (renderer/checks/methods.py: the chain of
frames from the rasteriser's to the ray tracer's, each pixel's difference put down to the step
that makes it) as the scene is, its spheres drawn as the icosphere the CPU makes, and with
`--tessellate PIXELS` (every untextured analytic sphere through the stages, levels by need) at
0.25 pixel (the default) and 0.1: the pixels of each cause. Counts, not times: the same on any
machine that runs the same GL.
"""

from __future__ import annotations

import argparse

from renderer.checks.methods import CAUSES, compare_methods
from renderer.cli.options import parse_size
from renderer.core.scene_file import load_scene
from renderer.core.tessellation import TARGET_PIXEL_ERROR, with_tessellated_spheres

from common import fill_readme_block, measured_line, write_results          # benchmarks/common.py


def markdown(document: dict) -> str:
    figures = document["figures"]
    errors = figures["errors"]
    lines = [f"`renderer compare {figures['scene']} --methods`, the rasteriser against the ray tracer "
             f"({figures['gl']}): pixels put down to each cause, with the scene's "
             f"{figures['spheres']} spheres as the icosphere the CPU makes (before) and through the "
             f"tessellation stages (`--tessellate PIXELS`).", "",
             "| size | cause | before | " + " | ".join(f"--tessellate {e:g}" for e in errors) + " |",
             "| --- | --- | ---: | " + " | ".join("---:" for _ in errors) + " |"]
    for row in figures["rows"]:
        for cause in (c.name for c in CAUSES):
            counts = [row["before"][cause], *(row[f"after {e:g}"][cause] for e in errors)]
            if any(counts):
                lines.append(f"| {row['size']} | {cause} | " + " | ".join(f"{n:,}" for n in counts) + " |")
    lines += ["", measured_line(document), ""]
    return "\n".join(lines)


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--scene", default="classic")
    parser.add_argument("--sizes", default="160x120,320x240,640x480")
    parser.add_argument("--errors", default="0.25,0.1", help="the --tessellate targets, pixels")
    parser.add_argument("--context", choices=("egl", "osmesa"), default="egl")
    args = parser.parse_args()
    scene = load_scene(args.scene)
    errors = [float(e) for e in args.errors.split(",")]
    ways = [("before", scene)] + [(f"after {e:g}", with_tessellated_spheres(scene, e)[0]) for e in errors]
    count = with_tessellated_spheres(scene, TARGET_PIXEL_ERROR)[1]
    rows, gl = [], ""
    for size in args.sizes.split(","):
        width, height = parse_size(size)
        counts = {}
        for name, which in ways:
            result = compare_methods(which, width, height, context_kind=args.context)
            counts[name] = result.counts()
            info = result.raytrace.gl_info or {}
            gl = f"{info.get('GL_RENDERER')}, {info.get('context')}"
            print(f"{size} {name}: " + ", ".join(f"{k} {v}" for k, v in counts[name].items()))
        rows.append({"size": f"{width}×{height}", **counts})
    figures = {"scene": args.scene, "spheres": count, "errors": errors, "gl": gl, "rows": rows}
    path = write_results("methods_tessellation", figures, markdown)
    fill_readme_block("methods_tessellation")
    print(f"wrote {path}")


if __name__ == "__main__":
    main()
