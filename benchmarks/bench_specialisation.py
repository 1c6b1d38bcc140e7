"""Specialised shaders and frustum culling against the all-features build, printed.

    .venv/bin/python benchmarks/bench_specialisation.py [--size 640x480] [--rounds 15] [--context egl]

For every built-in scene, and for `crowd` (a row of matte and glossy spheres of which the
camera sees a few), the same scene is drawn by two GpuRenderers on one context:
- specialised (the default): each material's program has only what it uses (its lights as
  compile-time constants, the specular term only where k_s > 0, back-face code only for a
  two-sided material) and objects wholly outside the view volume are not drawn;
- all-features (`GpuRenderer(..., specialise=False)`): the same GLSL files with everything
  compiled in, light counts and sides read from uniforms, every object drawn.
It prints the median frame time of each (frames alternate between the two, so both see the
same machine load), their ratio, and whether the two images are bit-identical; then the
geometric mean of the ratios. Not a test: this machine is shared and noisy.

It writes benchmarks/results/specialisation.json (the figures, with machine, date, load and
commit) and specialisation.md (the table made from it: `markdown`), which
docs/specialisation.md includes.
"""

from __future__ import annotations

import math
import statistics

import numpy as np

from renderer.core.builtin import builtin_scenes
from renderer.gpu.context import make_context
from renderer.core.raster_options import RasterOptions
from renderer.methods import open_renderer
from renderer.core.primitives import icosphere
from renderer.core.scene import Camera, DirectionalLight, Material, PointLight, Scene, SceneObject, Transform
from renderer.core.scene_file import load_scene

from common import arguments, measured_line, write_results          # benchmarks/common.py


def crowd_scene() -> Scene:
    """A row of 36 spheres of 5,120 triangles each along x, half matte (k_s = 0) and half
    glossy; the camera looks at the first few, so most of the row is off-screen."""
    mesh = icosphere(radius=1.0, subdivisions=4)
    matte = Material(kd=(0.7, 0.5, 0.3), shading="phong")
    glossy = Material(kd=(0.3, 0.4, 0.8), ks=(0.6, 0.6, 0.6), n=40.0, shading="phong")
    objects = [SceneObject(f"ball{i}", mesh, glossy if i % 2 else matte,
                           Transform(translate=(2.5 * i, 0.0, 0.0))) for i in range(36)]
    return Scene(camera=Camera(eye=(1.0, 1.5, 6.0), look=(1.5, 0.0, 0.0), fov_y=40.0, far=30.0),
                 objects=objects,
                 directional_lights=[DirectionalLight(direction=(-1.0, -1.0, -1.0))],
                 point_lights=[PointLight(position=(2.0, 3.0, 2.0), intensity=(0.5, 0.5, 0.5))],
                 name="crowd")


def scenes() -> list[Scene]:
    return [load_scene(path) for _, path in sorted(builtin_scenes().items())] + [crowd_scene()]


def measure(ctx, scene: Scene, size, rounds: int) -> dict:
    with open_renderer(scene, size, context=ctx) as specialised, \
            open_renderer(scene, size, context=ctx, options=RasterOptions(specialise=False)) as general:
        first = specialised.render(), general.render()          # compiles; not timed
        times = {"specialised": [], "all-features": []}
        for _ in range(rounds):
            times["specialised"].append(specialised.render(out=first[0]).milliseconds)
            times["all-features"].append(general.render(out=first[1]).milliseconds)
        drawn = len(specialised.drawn_objects), len(general.drawn_objects)
    medians = {kind: statistics.median(values) for kind, values in times.items()}
    return {"scene": scene.name, **medians,
            "ratio": medians["all-features"] / medians["specialised"],
            "identical": bool(np.array_equal(first[0].rgba8, first[1].rgba8)),
            "drawn": drawn, "objects": len(scene.objects)}


def main() -> None:
    args = arguments(__doc__, "rounds", 15)
    ctx = make_context(args.context)
    info = ctx.info
    print(f"{info['GL_RENDERER']} | {args.context} | {args.size[0]}x{args.size[1]} | "
          f"medians of {args.rounds} frames each, alternating")
    print(f"{'scene':<18} {'objects drawn':>14} {'specialised ms':>15} {'all-features ms':>16} "
          f"{'ratio':>6}  images")
    ratios, rows = [], []
    for scene in scenes():
        row = measure(ctx, scene, args.size, args.rounds)
        ratios.append(row["ratio"])
        rows.append({"scene": row["scene"], "drawn": row["drawn"][0], "objects": row["objects"],
                     "specialised_ms": round(row["specialised"], 3),
                     "all_features_ms": round(row["all-features"], 3), "identical": row["identical"]})
        drawn = f"{row['drawn'][0]}/{row['drawn'][1]}"
        print(f"{row['scene']:<18} {drawn:>14} {row['specialised']:>15.2f} "
              f"{row['all-features']:>16.2f} {row['ratio']:>6.2f}  "
              f"{'identical' if row['identical'] else 'DIFFERENT'}")
    print(f"geometric mean of the ratios: {math.exp(statistics.fmean(map(math.log, ratios))):.2f}")
    figures = {"gl_renderer": info["GL_RENDERER"], "context": args.context, "size": list(args.size),
               "rounds": args.rounds, "scenes": rows}
    ctx.release()
    print(f"wrote {write_results('specialisation', figures, markdown)}")


def markdown(document: dict) -> str:
    """docs/specialisation.md's table, made from a results document (write_results): per scene
    the objects drawn, both medians, their ratio and whether the images are identical; then the
    geometric mean and the range of the ratios."""
    f = document["figures"]
    width, height = f["size"]
    lines = [f"{width}×{height}, medians of {f['rounds']} frames each, the two builds alternating "
             f"frame by frame; GL: {f['gl_renderer']}, context {f['context']}.", "",
             "| scene | objects drawn | specialised ms | all-features ms | speed-up | images |",
             "| --- | ---: | ---: | ---: | ---: | --- |"]
    ratios = []
    for r in f["scenes"]:
        ratio = r["all_features_ms"] / r["specialised_ms"]
        ratios.append(ratio)
        lines.append(f"| {r['scene']} | {r['drawn']}/{r['objects']} | {r['specialised_ms']:.2f} | "
                     f"{r['all_features_ms']:.2f} | {ratio:.2f}× | "
                     f"{'identical' if r['identical'] else '**different**'} |")
    mean = math.exp(statistics.fmean(map(math.log, ratios)))
    lines += ["", f"Speed-up of the specialised build, geometric mean over the {len(ratios)} scenes: "
              f"**{mean:.2f}×** (from {min(ratios):.2f}× to {max(ratios):.2f}×).",
              "", measured_line(document), ""]
    return "\n".join(lines)


if __name__ == "__main__":
    main()
