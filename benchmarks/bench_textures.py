"""What texturing costs (issue 17's benchmark): frame time textured against untextured, GPU and
reference, and what the texture code costs programs without textures, printed.

    .venv/bin/python benchmarks/bench_textures.py [--size 640x480] [--frames 21] [--context egl]
        [--reference-frames 3] [--base 4a2db29] [--rounds 15] [--quick]

1. Textured against untextured: for each built-in textured scene (textured_mesh, checker_horizon,
   globe), under each filter (every textured material's, renderer/study/texture_report.py
   with_texture_setting), and the same scene with no texture at all (each material's texture
   removed: the untextured programs, no UVs uploaded), at --size:
   - GPU: GpuRenderer.render() (the draw, colour and depth read back), the two renderers' frames
     alternating (common.alternating_ms), the median of --frames; the ratio textured / untextured;
   - reference: reference.render() in float32, --reference-frames frames each, alternating too.
2. No texture code in untextured programs: for untextured built-in scenes (sphere, mesh_file,
   shadow_room), every program's GLSL (`renderer shaders`) at --base (the last commit before
   issue 17's texture code) and in this tree, each run through the C preprocessor (`cpp -P`:
   the #ifdef'd-out text and the comments gone; the GLSL compiler sees nothing else), compared
   token for token; and their frame times side by side: each version in its own worker process
   (benchmarks/ab_raytrace.py --method raster's), frames interleaved for --rounds rounds, the
   paired ratio, and whether the images are identical.
`--quick`: 5 GPU frames, the reference at the default filter only, 5 rounds.
Not a test: this machine is shared and noisy; the load average is printed.

It writes benchmarks/results/textures.json (the figures, with machine, date, load and commit)
and textures.md (the two tables made from it: `markdown`), which docs/textures.md includes.
"""

from __future__ import annotations

import argparse
import hashlib
import shutil
import statistics
import subprocess
import sys
import tempfile
import time
from pathlib import Path

import numpy as np

from renderer.core.builtin import builtin_scenes
from renderer.core.scene_file import load_scene
from renderer.gpu.context import make_context
from renderer.methods import open_renderer
from renderer.study.texture_report import filter_name, with_texture_setting, with_textures

import ab_raytrace                                        # benchmarks/ab_raytrace.py
from common import alternating_ms, machine, measured_line, parser, write_results   # benchmarks/common.py

TEXTURED_SCENES = ("textured_mesh", "checker_horizon", "globe")
FILTERS = (("nearest", 1), ("bilinear", 1), ("mip-nearest", 1), ("trilinear", 1), ("anisotropic", 16))
UNTEXTURED_SCENES = ("sphere", "mesh_file", "shadow_room")
BASE = "4a2db29"                 # main before issue 17 (issue 16's last commit): no texture code


def untextured(scene):
    return with_textures(scene, lambda texture: None)


def reference_ms(scenes, width: int, height: int, frames: int) -> list[float]:
    """The median ms of reference.render() of each scene, frames alternating."""
    renderers = [open_renderer(s, (width, height), backend="reference") for s in scenes]
    return alternating_ms([r.render for r in renderers], frames)


def textured_against_untextured(args, ctx) -> list[dict]:
    width, height = args.size
    print(f"## Textured against untextured, {width}x{height}: GPU median of {args.frames} frames, "
          f"reference of {args.reference_frames}, alternating")
    print()
    print("| scene | filter | GPU ms | untextured GPU ms | GPU ratio | reference ms | untextured "
          "reference ms | reference ratio |")
    print("| --- | --- | ---: | ---: | ---: | ---: | ---: | ---: |")
    rows = []
    for name in TEXTURED_SCENES:
        scene = load_scene(builtin_scenes()[name])
        plain = untextured(scene)
        authored = scene.objects[0].material.texture.sampler
        for setting in FILTERS:
            drawn = with_texture_setting(scene, "filter", setting)
            with open_renderer(drawn, (width, height), context=ctx) as gpu, \
                    open_renderer(plain, (width, height), context=ctx) as bare:
                gpu.render()
                bare.render()                                          # compiled, uploaded
                ms, bare_ms = alternating_ms([gpu.render, bare.render], args.frames)
            cells = [f"{ms:.2f}", f"{bare_ms:.2f}", f"{ms / bare_ms:.2f}"]
            row = {"scene": name, "filter": filter_name(setting),
                   "as_authored": setting[0] == authored.filter,
                   "gpu_ms": round(ms, 3), "untextured_gpu_ms": round(bare_ms, 3)}
            if not args.quick or setting[0] == authored.filter:
                ref, ref_bare = reference_ms([drawn, plain], width, height, args.reference_frames)
                cells += [f"{ref:.0f}", f"{ref_bare:.0f}", f"{ref / ref_bare:.2f}"]
                row |= {"reference_ms": round(ref, 1), "untextured_reference_ms": round(ref_bare, 1)}
            else:
                cells += ["", "", ""]
            mark = " (as authored)" if setting[0] == authored.filter else ""
            print(f"| {name} | {filter_name(setting)}{mark} | " + " | ".join(cells) + " |", flush=True)
            rows.append(row)
    return rows


def preprocessed_programs(tree: Path, scene: str, out: Path) -> dict[str, str]:
    """{file name: SHA-256 of its GLSL after the C preprocessor} of `renderer shaders SCENE`
    run in `tree`; the text alone where there is no cpp."""
    subprocess.run([sys.executable, "-m", "renderer", "shaders", scene, "--out", str(out)],
                   cwd=tree, env={"PYTHONPATH": str(tree), "PATH": "/usr/bin:/bin"},
                   check=True, capture_output=True)
    programs = {}
    for path in sorted(out.iterdir()):
        # cpp knows no #version, #extension or GLSL's #line N M: they are left out of both sides.
        text = "".join(line for line in path.read_text().splitlines(keepends=True)
                       if not line.lstrip().startswith(("#version", "#extension", "#line")))
        if shutil.which("cpp"):
            text = subprocess.run(["cpp", "-P", "-undef", "-nostdinc", "-w", "-"], input=text,
                                  text=True, capture_output=True, check=True).stdout
        programs[path.name] = hashlib.sha256(" ".join(text.split()).encode()).hexdigest()
    return programs


def untextured_programs(args) -> list[dict]:
    width, height = args.size
    print()
    print(f"## Untextured scenes: {args.base} (before issue 17) against this tree, {width}x{height}, "
          f"{args.rounds} rounds, frames interleaved")
    if not shutil.which("cpp"):
        print("(no cpp here: the programs are compared as text, comments and all)")
    print()
    print("| scene | programs | identical after the preprocessor | base ms | this ms | base / this "
          "(medians) | paired | identical images |")
    print("| --- | ---: | --- | ---: | ---: | ---: | ---: | --- |")
    rows = []
    with tempfile.TemporaryDirectory() as temp:
        base = ab_raytrace.export(args.base, Path(temp) / "base")
        here = ab_raytrace.ROOT
        for name in UNTEXTURED_SCENES:
            programs = [preprocessed_programs(tree, name, Path(temp) / f"{label}-{name}")
                        for label, tree in (("base", base), ("here", here))]
            options = argparse.Namespace(scene=name, size=args.size, spp=1, max_depth=4,
                                         context=args.context, method="raster")
            processes, infos = zip(*(ab_raytrace.start(tree, options) for tree in (base, here)))
            times = ([], [])
            for k in range(args.rounds):
                for i in ((0, 1) if k % 2 == 0 else (1, 0)):
                    times[i].append(ab_raytrace.frame_ms(processes[i])[0])
            for process in processes:
                process.stdin.close()
                process.wait()
            a, b = (statistics.median(t) for t in times)
            paired = statistics.median(x / y for x, y in zip(*times))
            differ = sorted(n for n in programs[0].keys() | programs[1].keys()
                            if programs[0].get(n) != programs[1].get(n))
            same = "yes" if not differ else f"**no**: {', '.join(differ)}"
            print(f"| {name} | {len(programs[1])} | {same} | "
                  f"{a:.2f} | {b:.2f} | {a / b:.3f} | {paired:.3f} | "
                  f"{'yes' if infos[0]['rgba8'] == infos[1]['rgba8'] else '**no**'} |", flush=True)
            identical = sum(programs[0].get(n) == h for n, h in programs[1].items())
            rows.append({"scene": name, "programs": len(programs[1]), "identical": identical, "differ": differ,
                         "base_ms": round(a, 3), "this_ms": round(b, 3), "paired": round(paired, 4),
                         "identical_images": infos[0]["rgba8"] == infos[1]["rgba8"]})
    return rows


def main() -> None:
    p = parser(__doc__, "frames", 21)
    p.add_argument("--reference-frames", type=int, default=3)
    p.add_argument("--base", default=BASE, help="the revision before issue 17's texture code")
    p.add_argument("--rounds", type=int, default=15)
    p.add_argument("--quick", action="store_true")
    args = p.parse_args()
    if args.quick:
        args.frames, args.rounds = 5, 5
    ctx = make_context(args.context)
    print(f"{machine()}; {time.strftime('%Y-%m-%d %H:%M UTC', time.gmtime())}")
    print(f"GL_RENDERER: {ctx.info['GL_RENDERER']}; numpy {np.__version__}")
    print()
    figures = {"size": list(args.size), "context": args.context, "gl_renderer": ctx.info["GL_RENDERER"],
               "frames": args.frames, "reference_frames": args.reference_frames, "base": args.base,
               "rounds": args.rounds}
    figures["textured"] = textured_against_untextured(args, ctx)
    figures["untextured_programs"] = untextured_programs(args)
    print()
    print(machine())
    print(f"wrote {write_results('textures', figures, markdown)}")


def markdown(document: dict) -> str:
    """The table docs/textures.md includes, made from a results document (write_results). The
    second part's comparison with an old commit is printed, not tabulated: later issues have
    changed those programs for their own reasons, so it no longer measures issue 17 alone."""
    f = document["figures"]
    width, height = f["size"]
    lines = [f"Textured against untextured at {width}×{height}, {f['context']} ({f['gl_renderer']}): "
             f"GPU frames the median of {f['frames']}, the reference's of {f['reference_frames']}, "
             "the textured and the untextured renderer's frames alternating.", "",
             "| scene | filter | GPU ms | untextured | textured / untextured | reference ms | untextured "
             "| textured / untextured |", "| --- | --- | ---: | ---: | ---: | ---: | ---: | ---: |"]
    for r in f["textured"]:
        cells = [f"{r['gpu_ms']:.2f}", f"{r['untextured_gpu_ms']:.2f}", f"{r['gpu_ms'] / r['untextured_gpu_ms']:.2f}"]
        if "reference_ms" in r:
            cells += [f"{r['reference_ms']:,.0f}", f"{r['untextured_reference_ms']:,.0f}",
                      f"{r['reference_ms'] / r['untextured_reference_ms']:.2f}"]
        else:
            cells += ["", "", ""]
        mark = " (as authored)" if r["as_authored"] else ""
        lines.append(f"| `{r['scene']}` | {r['filter']}{mark} | " + " | ".join(cells) + " |")
    return "\n".join(lines + ["", measured_line(document), ""])


if __name__ == "__main__":
    main()
