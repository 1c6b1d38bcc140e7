"""The window viewer's frame time beside the headless frame time at the same size, printed.

    .venv/bin/python benchmarks/bench_viewer.py [--size 640x480] [--frames 120] [--rounds 3]

Each round runs, per scene, the viewer in its scripted mode (`renderer view SCENE --frames N
--orbit 1 --no-vsync --stats ...`, in a window on the display in DISPLAY, else on a virtual
one this script starts), once with double and once with triple buffering, and then the same
N frames headless in this process: the camera turned 1 degree and GpuRenderer.update()
before every frame, as in the viewer, then render() (drawing and reading the colour back,
as `renderer render` does) and, separately, draw() alone plus glFinish (the drawing a window
also does). Medians over the frames of all rounds; the rounds alternate so that both sides
see the same machine.

Viewer frame time is from swap to swap: events, the update, drawing, the copy to the back
buffer and the swap (on Xvfb a copy of the image into the X server); the viewer's drawing
(draw() and glFinish, as its --stats report it) is printed beside it. Not a test: this
machine is shared and noisy.

It writes benchmarks/results/viewer.json (the figures, with machine, date, load and commit)
and viewer.md (the table made from it: `markdown`), which docs/benchmarks.md includes.
"""

from __future__ import annotations

import argparse
import contextlib
import json
import os
import statistics
import subprocess
import sys
import tempfile
import time
from dataclasses import replace
from pathlib import Path

from renderer.core.builtin import resolve_scene
from renderer.cli.options import parse_size
from renderer.gpu import GpuRenderer
from renderer.methods import open_renderer
from renderer.viewer.orbit import OrbitCamera
from renderer.core.scene_file import load_scene
from renderer.viewer.virtual_display import virtual_display

from common import measured_line, write_results          # benchmarks/common.py

SCENES = ("sphere", "coloured_lights", "hierarchy", "point_light_plane")


def viewer_run(scene: str, size, frames: int, display: str, triple: bool) -> dict:
    with tempfile.TemporaryDirectory() as folder:
        stats = Path(folder) / "stats.json"
        command = [sys.executable, "-m", "renderer", "view", scene, "--size", f"{size[0]}x{size[1]}",
                   "--frames", str(frames), "--orbit", "1", "--no-vsync", "--stats", str(stats)]
        if triple:
            command.append("--triple-buffering")
        subprocess.run(command, check=True, capture_output=True, env={**os.environ, "DISPLAY": display})
        return json.loads(stats.read_text())


def headless_run(gpu: GpuRenderer, authored, frames: int) -> tuple[list[float], list[float]]:
    """(render ms, draw ms) per frame, the camera turning 1 degree a frame."""
    orbit = OrbitCamera(authored.camera)
    frame = None

    def render():
        nonlocal frame
        frame = gpu.render(depth=False, out=frame)

    def draw():
        gpu.draw()
        gpu.ctx.finish()

    def timed(work) -> list[float]:
        milliseconds = []
        for _ in range(frames):
            orbit.orbit(1.0, 0.0)
            gpu.scene.camera = orbit.camera
            start = time.perf_counter()
            gpu.update()
            work()
            milliseconds.append((time.perf_counter() - start) * 1000.0)
        return milliseconds

    return timed(render), timed(draw)


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--size", type=parse_size, default=(640, 480))
    parser.add_argument("--frames", type=int, default=120)
    parser.add_argument("--rounds", type=int, default=3)
    args = parser.parse_args()
    width, height = args.size

    display_context = contextlib.nullcontext(os.environ["DISPLAY"]) if os.environ.get("DISPLAY") \
        else virtual_display()
    with display_context as display:
        results = {name: {"double": [], "triple": [], "latency_double": [], "latency_triple": [],
                          "viewer_draw": [], "render": [], "draw": []} for name in SCENES}
        renderers = {}
        for name in SCENES:
            authored = load_scene(resolve_scene(name))
            renderers[name] = (open_renderer(replace(authored), (width, height), context_kind="egl"),
                               authored)
        for round_ in range(args.rounds):
            for name in SCENES:
                for buffering in ("double", "triple"):
                    stats = viewer_run(name, args.size, args.frames, display, buffering == "triple")
                    # Per-frame times stay in the subprocess; its median stands for the round.
                    results[name][buffering].append(stats["frame_ms_median"])
                    results[name][f"latency_{buffering}"].append(stats["latency_ms_median"])
                    if buffering == "double":
                        results[name]["viewer_draw"].append(stats["draw_ms_median"])
                gpu, authored = renderers[name]
                render_ms, draw_ms = headless_run(gpu, authored, args.frames)
                results[name]["render"].append(statistics.median(render_ms))
                results[name]["draw"].append(statistics.median(draw_ms))
            print(f"round {round_ + 1}/{args.rounds} done", file=sys.stderr)
        gl = next(iter(renderers.values()))[0].gl_info["GL_RENDERER"]
        for gpu, _ in renderers.values():
            gpu.release()

    print(f"\n{width}x{height}, {args.frames} frames x {args.rounds} rounds, camera turning 1 degree "
          f"a frame, v-sync off; {gl}; medians of the rounds' medians (ms)\n")
    rows = [{"scene": name} | {key: median(values) for key, values in results[name].items()}
            for name in SCENES]
    figures = {"gl_renderer": gl, "display": "DISPLAY" if os.environ.get("DISPLAY") else "Xvfb",
               "size": [width, height], "frames": args.frames, "rounds": args.rounds, "scenes": rows}
    print(table(figures))
    print(f"wrote {write_results('viewer', figures, markdown)}")


def median(values: list) -> float | None:
    """The median of the values there are, rounded (None: none, as a run too short for a latency)."""
    values = [v for v in values if v is not None]
    return round(statistics.median(values), 3) if values else None


def ms(value: float | None) -> str:
    return "–" if value is None else f"{value:.2f}"


def table(figures: dict) -> str:
    """The table of medians (ms), one row per scene."""
    lines = ["| scene | headless `render()` ms (draw + colour read-back) | headless `draw()` ms "
             "| viewer ms, double buffering | viewer ms, triple | viewer / headless "
             "| viewer's drawing ms | latency ms, double / triple |",
             "| --- | ---: | ---: | ---: | ---: | ---: | ---: | --- |"]
    for r in figures["scenes"]:
        lines.append(f"| {r['scene']} | {r['render']:.2f} | {r['draw']:.2f} | {r['double']:.2f} "
                     f"| {r['triple']:.2f} | {r['double'] / r['render']:.2f}× | {r['viewer_draw']:.2f} "
                     f"| {ms(r['latency_double'])} / {ms(r['latency_triple'])} |")
    return "\n".join(lines)


def markdown(document: dict) -> str:
    """docs/benchmarks.md's table of the viewer against the headless path, made from a results
    document (write_results)."""
    f = document["figures"]
    window = "on Xvfb" if f["display"] == "Xvfb" else "on the display in DISPLAY"
    head = (f"{f['size'][0]}×{f['size'][1]}, v-sync off, {f['frames']} frames × {f['rounds']} rounds, "
            f"the camera turning 1° a frame; medians of the rounds' medians; the window {window}; "
            f"GL: {f['gl_renderer']}.")
    return "\n".join([head, "", table(f), "", measured_line(document), ""])


if __name__ == "__main__":
    main()
