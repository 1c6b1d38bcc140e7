"""The tessellation stages' cost and error (issue 34), printed and written to
benchmarks/results/tessellation.json and .md (docs/tessellation.md includes the .md):

    .venv/bin/python benchmarks/bench_tessellation.py [--size 640x480] [--frames 30]

One Phong-shaded sphere of radius 1 seen from 3 units (it fills about half the frame's
height), drawn by the rasteriser (GpuRenderer.draw, GL finished, on llvmpipe) in each way:
through the tessellation stages with levels by need at a target error in pixels, at fixed
levels, and without them as the icosphere the CPU makes (subdivisions 3, the default, to 5).
For each: the median frame time of --frames frames drawn in turn with the others (so all see
the same load), the triangles drawn (the stages' from their twin, reference/tessellation/
surface.py, bit for bit the GPU's), the geometric error in pixels (each triangle's centroid's
depth below the sphere, the deepest point of a small triangle, times the pixels per unit at its
depth, the largest), and the image error against the ray tracer's exact sphere on the interior
pixels (two pixels inside both outlines), in levels of 255: largest and mean. The last line
compares the stages at 0.25 pixel with the least-subdivided icosphere whose geometric error is
as small. Not a test: this machine is shared and noisy.
"""

from __future__ import annotations

import argparse

import numpy as np
from scipy import ndimage

from reference.tessellation.surface import tessellated_mesh
from renderer.core.scene_file import scene_from_dict
from renderer.gpu.context import activate, make_context
from renderer.methods import open_renderer

from common import alternating_ms, measured_line, write_results          # benchmarks/common.py

WAYS = [("by need, 0.25 px", {"tessellation": {"error": 0.25}}),
        ("by need, 0.1 px", {"tessellation": {"error": 0.1}}),
        ("fixed level 4", {"tessellation": {"level": 4}}),
        ("fixed level 8", {"tessellation": {"level": 8}}),
        ("fixed level 16", {"tessellation": {"level": 16}}),
        ("icosphere 3 (CPU)", {"subdivisions": 3}),
        ("icosphere 4 (CPU)", {"subdivisions": 4}),
        ("icosphere 5 (CPU)", {"subdivisions": 5})]


def scene_for(way: dict):
    shape = {"type": "sphere", "radius": 1.0}
    obj = {"name": "ball", "material": {"kd": [0.7, 0.3, 0.2], "ks": [0.5, 0.5, 0.5], "n": 30.0,
                                         "shading": "phong"}, "receives_shadows": False}
    if "subdivisions" in way:
        shape["subdivisions"] = way["subdivisions"]
    else:
        obj["tessellation"] = way["tessellation"]
    obj["shape"] = shape
    return scene_from_dict({
        "background": [0.1, 0.1, 0.15], "ambient": [0.1, 0.1, 0.1],
        "camera": {"eye": [0.0, 0.5, 3.0], "look": [0.0, 0.0, 0.0], "fov_y": 45.0},
        "lights": [{"type": "point", "position": [2.0, 3.0, 3.0], "intensity": [1.0, 1.0, 1.0],
                    "shadows": False}],
        "objects": [obj]})


def drawn_triangles(scene, size):
    """(T, 3, 3) camera-relative world corners of what the camera pass draws of the sphere."""
    width, height = size
    matrices = scene.matrices(width, height)
    obj, m = scene.objects[0], matrices.objects[0]
    if obj.tessellation is not None:
        positions, _, faces = tessellated_mesh(obj, m, matrices.view, matrices.projection, height)
    else:
        positions, faces = obj.mesh.positions, obj.mesh.faces
    world = np.asarray(positions, np.float64) @ m.model[:3, :3].T + m.model[:3, 3]
    return world[np.asarray(faces)], matrices


def geometric_error_px(triangles, matrices, height, centre, radius) -> float:
    centroids = triangles.mean(axis=1)
    depth_below = radius - np.linalg.norm(centroids - centre, axis=1)
    clip = np.concatenate([centroids, np.ones((len(centroids), 1))], axis=1) @ (
        matrices.projection @ matrices.view).T
    pixels_per_unit = height * matrices.projection[1, 1] / (2 * clip[:, 3])
    facing = (centroids - centre) @ np.zeros(3) <= 0        # every triangle (the far side too)
    return float((depth_below * pixels_per_unit)[facing].max())


def image_error(ctx, scene, size) -> tuple[float, float]:
    with open_renderer(scene, size, context=ctx) as raster:
        a = raster.render(depth=False).rgba8
    with open_renderer(scene, size, method="raytrace", context=ctx) as tracer:
        b = tracer.render(depth=False).rgba8
    interior = ndimage.binary_erosion((a[..., 3] > 0) & (b[..., 3] > 0), iterations=2)
    levels = np.abs(a[..., :3].astype(int) - b[..., :3].astype(int)).max(-1)[interior]
    return float(levels.max()), float(levels.mean())


def markdown(document: dict) -> str:
    f = document["figures"]
    lines = [f"One Phong-shaded sphere at {f['size']}, drawn by the rasteriser on the GPU (llvmpipe) "
             f"each way; frame times the median of {f['frames']} frames drawn in turn; errors against "
             "the exact sphere (geometric, in pixels) and against the ray tracer's image on the interior "
             "pixels (levels of 255).", "",
             "| way | triangles | frame ms | geometric error px | image error max | image error mean |",
             "| --- | ---: | ---: | ---: | ---: | ---: |"]
    for row in f["rows"]:
        lines.append(f"| {row['way']} | {row['triangles']:,} | {row['frame_ms']:.2f} | {row['geometric_px']:.3f} | "
                     f"{row['image_max']:.0f} | {row['image_mean']:.3f} |")
    same = f["same_error"]
    lines += ["", f"The stages ({same['tessellated']}) against the least-subdivided icosphere with no more "
                  f"geometric error ({same['icosphere']}): {same['ratio']:.2f}x its frame time.", "",
              measured_line(document), ""]
    return "\n".join(lines)


def main() -> None:
    from renderer.cli.options import parse_size
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--size", type=parse_size, default=(640, 480))
    parser.add_argument("--frames", type=int, default=30)
    args = parser.parse_args()
    ctx = make_context("egl")
    size = tuple(args.size)
    renderers, rows = [], []
    for name, way in WAYS:
        scene = scene_for(way)
        triangles, matrices = drawn_triangles(scene, size)
        sphere = scene.objects[0].shape
        centre = np.asarray(sphere.centre) - matrices.origin
        image_max, image_mean = image_error(ctx, scene, size)
        rows.append({"way": name, "triangles": int(len(triangles)),
                     "geometric_px": geometric_error_px(triangles, matrices, size[1], centre, sphere.radius),
                     "image_max": image_max, "image_mean": image_mean})
        renderers.append(open_renderer(scene, size, context=ctx))

    def drawing(renderer):
        def draw():
            activate(ctx)
            renderer.draw()
            ctx.finish()
        return draw
    for renderer in renderers:
        drawing(renderer)()                                   # compile and warm up
    times = alternating_ms([drawing(r) for r in renderers], args.frames)
    for row, ms, renderer in zip(rows, times, renderers):
        row["frame_ms"] = ms
        renderer.release()
    tessellated = rows[0]
    icosphere = next((row for row in rows if "CPU" in row["way"] and row["geometric_px"] <= tessellated["geometric_px"]),
                     rows[-1])
    figures = {"size": f"{size[0]}x{size[1]}", "frames": args.frames, "rows": rows,
               "same_error": {"tessellated": tessellated["way"], "icosphere": icosphere["way"],
                              "ratio": tessellated["frame_ms"] / icosphere["frame_ms"]}}
    path = write_results("tessellation", figures, markdown)
    for row in rows:
        print(row)
    print(f"wrote {path}")


if __name__ == "__main__":
    main()
