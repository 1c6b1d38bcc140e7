"""What leaving out the shadow work a scene does not need saves, printed (issue 15).

    .venv/bin/python benchmarks/bench_shadow_pruning.py [--size 640x480] [--rounds 15]
        [--scenes every built-in scene by default] [--context egl]

renderer/core/shadows.py plans each frame's shadow passes by the pair rule of
renderer/core/shadow_casting.py: a caster that cannot shadow any receiver (a convex solid lit
from outside, or around its lamp; a planar mesh with everything on its lit side; a caster
whose box across a directional light misses every receiver's) is not drawn into a map, a
cube face whose frustum holds no caster-receiver pair is not drawn at all (its lookups read
as lit), a light with no pair draws no pass, and a light that no caster can ever shadow gets
no map at all (the scene's programs then have no shadow code: "none" below).
For each scene two renderers are timed in turn, round after round (both see the same load):
GpuRenderer as it is, and GpuRenderer(prune_shadows=False), which draws every caster into
every map and cube face. Both read back colour and depth as render() does. Without pruning a
directional map is fitted to every caster, so that image may differ; the frame's work is
what is compared. Programs whose object receives no shadow compile no lookup at all (the
scene-level counterpart: benchmarks/bench_shadows.py, with shadows against without).
Not a test: this machine is shared and noisy.

Run on every built-in scene (no --scenes), it writes benchmarks/results/shadow_pruning.json
(the figures, with machine, date, load and commit) and shadow_pruning.md (the table made from
it: `markdown`), which docs/benchmarks.md includes; a run on other scenes only prints.
"""

from __future__ import annotations

from renderer.core.builtin import builtin_scenes
from renderer.core.scene_file import load_scene
from renderer.gpu.context import make_context, release_context
from renderer.core.raster_options import RasterOptions
from renderer.gpu.pipeline import GpuRenderer
from renderer.methods import open_renderer

from common import alternating_ms, machine, measured_line, parser, write_results   # benchmarks/common.py

SCENES = ",".join(sorted(builtin_scenes()))


def work(gpu: GpuRenderer) -> str:
    """"passes, caster draws" of the shadow plan the renderer's last frame drew ("none": the
    scene has no maps at all)."""
    if gpu.shadow_maps is None:
        return "none"
    plan = gpu.drawn_shadow_plan
    if plan is None:
        return "0, 0"
    return f"{len(plan.passes)}, {sum(len(p.casters) for p in plan.passes)}"


def main() -> None:
    options = parser(__doc__, "rounds", 15)
    options.add_argument("--scenes", default=SCENES)
    args = options.parse_args()
    width, height = args.size
    print(f"Shadow pruning at {width}x{height}, median of {args.rounds} frames each, in turn")
    ctx = make_context(args.context)
    print(f"{machine()}; {ctx.info['GL_RENDERER']} ({args.context})")
    print(f"{'scene':<16} {'passes, draws (pruned)':>23} {'(all)':>9} {'pruned ms':>10} "
          f"{'all ms':>8} {'saved':>7}")
    rows = []
    try:
        for name in args.scenes.split(","):
            scene = load_scene(name)
            with open_renderer(scene, (width, height), context=ctx) as pruned, \
                    open_renderer(scene, (width, height), context=ctx,
                                  options=RasterOptions(prune_shadows=False)) as full:
                frames = [pruned.render(), full.render()]
                calls = [lambda: pruned.render(out=frames[0]), lambda: full.render(out=frames[1])]
                ms_pruned, ms_full = alternating_ms(calls, args.rounds)
                drawn = work(pruned), work(full)
            print(f"{name:<16} {drawn[0]:>23} {drawn[1]:>9} {ms_pruned:>10.1f} "
                  f"{ms_full:>8.1f} {1 - ms_pruned / ms_full:>7.0%}")
            rows.append({"scene": name, "pruned": drawn[0], "all": drawn[1],
                         "pruned_ms": round(ms_pruned, 3), "all_ms": round(ms_full, 3)})
        gl = ctx.info["GL_RENDERER"]
    finally:
        release_context(ctx)
    if args.scenes == SCENES:                         # docs/benchmarks.md's table: every scene
        figures = {"gl_renderer": gl, "context": args.context, "size": [width, height],
                   "rounds": args.rounds, "scenes": rows}
        print(f"wrote {write_results('shadow_pruning', figures, markdown)}")
    print(f"Reproduce: .venv/bin/python benchmarks/bench_shadow_pruning.py --size {width}x{height} "
          f"--rounds {args.rounds}")


def markdown(document: dict) -> str:
    """docs/benchmarks.md's table of shadow pruning, made from a results document
    (write_results): the scenes where the pruned plan's passes and draws differ from drawing
    everything, then those where they are the same."""
    f = document["figures"]
    width, height = f["size"]
    differ = [r for r in f["scenes"] if r["pruned"] != r["all"]]
    same = [f"{r['scene']} ({r['pruned']})" for r in f["scenes"] if r["pruned"] == r["all"]]
    lines = [f"{width}×{height}, medians of {f['rounds']} frames each, the two renderers in turn; "
             f"GL: {f['gl_renderer']}, context {f['context']}.", "",
             "| scene | pruned: passes, draws | all: passes, draws | pruned ms | all ms |",
             "| --- | --- | --- | ---: | ---: |"]
    lines += [f"| {r['scene']} | {r['pruned']} | {r['all']} | {r['pruned_ms']:.1f} | {r['all_ms']:.1f} |"
              for r in differ]
    if same:
        lines += ["", "The same in both (passes, draws; none: no light of the scene gets a map either "
                  "way): " + ", ".join(same) + "."]
    return "\n".join(lines + ["", measured_line(document), ""])


if __name__ == "__main__":
    main()
