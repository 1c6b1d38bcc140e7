"""The aliasing the ray tracer's texture LOD rule leaves (issue 17; docs/conventions.md,
"Textures in the ray tracer"): RMSE against a many-sample render, printed.

    .venv/bin/python benchmarks/bench_texture_aliasing.py [--size 160x120] [--truth 256]
        [--context egl] [SCENE ...]

The ray tracer reads a texture's level 0 with its magnification filter (no derivatives, no
mipmaps), so where a pixel covers many texels (a checkerboard to the horizon, a globe's
texture at its limb) one sample per pixel picks texels at random and aliases (moire); more
samples per pixel average the texels over the pixel, as a box filter. For each scene (by
default the analytic shapes' textured scenes, tests/scenes/rt_checker_horizon.toml and
rt_globe.toml, and the built-in checker_horizon, globe and textured_mesh),
the GPU ray tracer (renderer/gpu/raytracer.py) at --size: 1 sample (regular: the pixel's
centre), 4 and 16 jittered samples, and --truth jittered samples as the reference; the RMSE of
each against it over the RGB of rgba8 (0-255; the compare tool's `rmse`), over all pixels and
over the textured surface's pixels whose view depth is beyond the median (the far half, where
the texture is minified); and the same for the scene untextured, the edges' share of it. The
jittered truth is itself within about RMSE(16) sqrt(16/truth) of the limit. Not a test:
tests/test_raytrace_textures.py holds the trend.

It writes benchmarks/results/texture_aliasing.json (the figures, with machine, date, load and
commit) and texture_aliasing.md (the table made from it: `markdown`), which docs/textures.md
includes.
"""

from __future__ import annotations

import os
from dataclasses import replace
from pathlib import Path

import numpy as np

from renderer.core.builtin import builtin_scenes
from renderer.core.scene_file import load_scene
from renderer.core.ray_options import RayOptions
from renderer.gpu.context import make_context
from renderer.methods import open_renderer

from common import machine, measured_line, parser, write_results       # benchmarks/common.py

# The analytic shapes' textured scenes, and the built-in textured scenes where they exist.
SCENES = [str(Path(__file__).resolve().parents[1] / "tests" / "scenes" / f"{name}.toml")
          for name in ("rt_checker_horizon", "rt_globe")] \
    + [name for name in ("checker_horizon", "globe", "textured_mesh") if name in builtin_scenes()]
SETTINGS = ((1, "regular"), (4, "jittered"), (16, "jittered"))
ROOT = Path(__file__).resolve().parents[1]


def rmse(a, b, where=None) -> float:
    d = a[..., :3].astype(np.float64) - b[..., :3].astype(np.float64)
    d = d if where is None else d[where]
    return float(np.sqrt(np.mean(d * d)))


def aliasing(scene, width: int, height: int, truth_samples: int, ctx) -> dict:
    """{(spp, pattern): (rmse all, rmse far half)} against `truth_samples` jittered samples."""
    with open_renderer(scene, (width, height), method="raytrace", context=ctx,
                       options=RayOptions(samples=truth_samples, pattern="jittered")) as rt:
        truth = rt.render()
    depth = truth.depth[np.isfinite(truth.depth)]
    far = np.isfinite(truth.depth) & (truth.depth > np.median(depth))
    out = {}
    for samples, pattern in SETTINGS:
        with open_renderer(scene, (width, height), method="raytrace", context=ctx,
                           options=RayOptions(samples=samples, pattern=pattern)) as rt:
            frame = rt.render()
        out[(samples, pattern)] = (rmse(frame.rgba8, truth.rgba8), rmse(frame.rgba8, truth.rgba8, far))
    return out


def untextured(scene):
    """`scene` with every material's texture taken off."""
    objects = [replace(obj, material=replace(obj.material, texture=None)) for obj in scene.objects]
    return replace(scene, objects=objects)


def main() -> None:
    p = parser(__doc__, "truth", 256)
    p.set_defaults(size=(160, 120))
    p.add_argument("scenes", nargs="*", default=SCENES)
    args = p.parse_args()
    width, height = args.size
    ctx = make_context(args.context)
    print(machine())
    print(f"{width}x{height}, truth {args.truth} jittered samples, {args.context}; RMSE of rgba8 RGB (0-255)")
    print(f"{'scene':<22} {'samples':<12} {'all pixels':>10} {'far half':>9}   untextured: all, far half")
    figures = {"size": [width, height], "truth": args.truth, "context": args.context,
               "gl_renderer": ctx.info["GL_RENDERER"], "scenes": []}
    for name in args.scenes:
        scene = load_scene(name)
        textured = aliasing(scene, width, height, args.truth, ctx)
        plain = aliasing(untextured(scene), width, height, args.truth, ctx)
        rows = []
        for setting, (whole, far) in textured.items():
            samples, pattern = setting
            print(f"{scene.name:<22} {f'{samples} {pattern}':<12} {whole:>10.2f} {far:>9.2f}"
                  f"   {plain[setting][0]:.2f}, {plain[setting][1]:.2f}")
            rows.append({"samples": samples, "pattern": pattern, "all": round(whole, 3),
                         "far": round(far, 3), "untextured_all": round(plain[setting][0], 3),
                         "untextured_far": round(plain[setting][1], 3)})
        source = os.path.relpath(name, ROOT) if os.path.exists(name) else "built-in"
        figures["scenes"].append({"scene": scene.name, "source": source, "settings": rows})
    ctx.release()
    print(f"wrote {write_results('texture_aliasing', figures, markdown)}")


def markdown(document: dict) -> str:
    """The table docs/textures.md includes, made from a results document (write_results)."""
    f = document["figures"]
    width, height = f["size"]
    first = f["scenes"][0]["settings"] if f["scenes"] else []
    header = ", ".join(f"{r['samples']}" + (" (centre)" if r["pattern"] == "regular" else f" {r['pattern']}")
                       for r in first)
    lines = [f"RMSE (rgba8 RGB, 0–255) against {f['truth']} jittered samples per pixel at {width}×{height}, "
             f"the GPU ray tracer, {f['context']} ({f['gl_renderer']}); samples per pixel {header}; "
             "the far half: the pixels beyond the median view depth, where the texture is minified.", "",
             "| scene | textured | far half | the same scene untextured |", "| --- | --- | --- | --- |"]
    for s in f["scenes"]:
        def joined(key):
            return " / ".join(f"{r[key]:.1f}" for r in s["settings"])
        lines.append(f"| `{s['scene']}` ({s['source']}) | {joined('all')} | {joined('far')} | {joined('untextured_all')} |")
    return "\n".join(lines + ["", measured_line(document), ""])


if __name__ == "__main__":
    main()
