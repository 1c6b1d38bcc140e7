"""What a camera move costs the viewer's ray tracer: RayTracer.update() against a new RayTracer.

    .venv/bin/python benchmarks/bench_raytrace_update.py [--size 640x480] [--steps 5] [--context egl]

Per scene (the classic scene, the built-in `sphere`, the 20,480-triangle icosphere of
benchmarks/bench_raytrace.py), --steps times: the camera orbits 1 degree; then, alternating,
a RayTracer made afresh for the new camera (the ray scene with its BVH build, the compile, the
textures) and update() on a tracer made once (the BVH refitted, the textures written in
place); each followed by one 1-spp frame, whose bytes must be the same. Medians in ms. The
window viewer does update() (renderer/viewer/viewer.py). Not a test: this machine is shared
and noisy; the load average is printed.

It writes benchmarks/results/raytrace_update.json (the figures, with machine, date, load and
commit) and raytrace_update.md (the table made from it: `markdown`), which docs/viewer.md
includes.
"""

from __future__ import annotations

import os
import statistics
import time
from dataclasses import replace

from bench_raytrace import icosphere_scene              # benchmarks/bench_raytrace.py
from common import arguments, measured_line, write_results   # benchmarks/common.py
from renderer.core.builtin import resolve_scene
from renderer.core.scene_file import load_scene
from renderer.gpu.context import make_context
from renderer.methods import open_renderer
from renderer.viewer.controls import working_copy
from renderer.viewer.orbit import OrbitCamera


def timed(function):
    start = time.perf_counter()
    value = function()
    return (time.perf_counter() - start) * 1000.0, value


def main() -> None:
    args = arguments(__doc__, "steps", 5)
    ctx = make_context(args.context)
    scenes = {"classic": load_scene(resolve_scene("classic")), "sphere": load_scene(resolve_scene("sphere")),
              "icosphere 20480": icosphere_scene()}
    print(f"{args.size[0]}x{args.size[1]}, {args.context}, load average "
          f"{os.getloadavg()[0]:.1f}; medians of {args.steps} one-degree orbit steps (ms)")
    print(f"{'scene':<16} {'triangles':>9} {'new tracer':>11} {'update()':>9} {'ratio':>6} "
          f"{'frame':>7}")
    rows = []
    for name, scene in scenes.items():
        shown = working_copy(scene)
        orbit = OrbitCamera(scene.camera)
        tracer = open_renderer(shown, args.size, method="raytrace", context=ctx)
        fresh_ms, update_ms, frame_ms = [], [], []
        try:
            for _ in range(args.steps):
                orbit.orbit(1.0, 0.0)
                shown.camera = orbit.camera
                ms, new = timed(lambda: open_renderer(replace(shown, objects=list(shown.objects)),
                                                      args.size, method="raytrace", context=ctx))
                with new:
                    expected = new.render()
                fresh_ms.append(ms)
                ms, _ = timed(tracer.update)
                update_ms.append(ms)
                ms, frame = timed(tracer.render)
                frame_ms.append(ms)
                assert frame.linear.tobytes() == expected.linear.tobytes(), name
            triangles = len(tracer.ray_scene.triangles)
        finally:
            tracer.release()
        fresh, update = statistics.median(fresh_ms), statistics.median(update_ms)
        print(f"{name:<16} {triangles:>9,} {fresh:>11.1f} {update:>9.1f} {fresh / update:>5.0f}x "
              f"{statistics.median(frame_ms):>7.1f}")
        rows.append({"scene": name, "triangles": triangles, "new_tracer_ms": round(fresh, 2),
                     "update_ms": round(update, 2), "frame_ms": round(statistics.median(frame_ms), 1)})
    figures = {"gl_renderer": ctx.info["GL_RENDERER"], "context": args.context, "size": list(args.size),
               "steps": args.steps, "scenes": rows}
    print(f"wrote {write_results('raytrace_update', figures, markdown)}")


def markdown(document: dict) -> str:
    """docs/viewer.md's table of a camera move's cost to the ray tracer, made from a results
    document (write_results)."""
    f = document["figures"]
    width, height = f["size"]
    lines = [f"{width}×{height}, medians of {f['steps']} one-degree orbit steps; "
             f"GL: {f['gl_renderer']}, context {f['context']}.", "",
             "| scene | triangles | new tracer ms | `update()` ms | new tracer / `update()` | 1-spp frame ms |",
             "| --- | ---: | ---: | ---: | ---: | ---: |"]
    lines += [f"| {r['scene']} | {r['triangles']:,} | {r['new_tracer_ms']:.1f} | {r['update_ms']:.1f} "
              f"| {r['new_tracer_ms'] / r['update_ms']:.0f}× | {r['frame_ms']:.1f} |" for r in f["scenes"]]
    return "\n".join(lines + ["", measured_line(document), ""])


if __name__ == "__main__":
    main()
