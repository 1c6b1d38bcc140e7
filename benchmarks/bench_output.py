"""What the output stage costs (issue 18): ms per frame of each method on the GPU
(renderer/gpu/output.py, OutputPass.apply: upload, dispatch, read-back) and in the NumPy twin
(reference.output.apply), what error diffusion's wavefront dispatches cost by themselves, and
what making the blue-noise mask costs, printed.

    .venv/bin/python benchmarks/bench_output.py [--size 640x480] [--frames 15] [--context egl]

The input is the linear colour of a rendered frame (--scene, default sphere). For each case in
CASES (a method at a bit depth, sRGB transfer; float output too), the GPU and the twin are
called in turn (common.alternating_ms) after one warm-up call each (the program's compile, the
tables), and the medians printed. Error diffusion's dispatches: the same W + s (H - 1)
dispatches, uniform writes and memory barriers as OutputPass._diffuse with every wavefront's
rows left empty (each invocation returns at once), against the whole pass, alternating. The
mask: renderer/core/blue_noise.py's void-and-cluster, its cache cleared, made --frames // 5 + 1
times, the median.
Not a test: this machine is shared and noisy; the load average is printed.

It writes benchmarks/results/output.json (the figures, with machine, date, load and commit) and
output.md (the tables made from it: `markdown`), which docs/colour-and-output.md includes.
"""

from __future__ import annotations

import statistics
import time

import reference.output
from renderer.core.blue_noise import blue_noise_ranks
from renderer.core.error_kernels import KERNELS, wavefronts
from renderer.core.output_settings import ERROR_DIFFUSION, Halftone, OutputSettings, Transfer
from renderer.core.scene_file import load_scene
from renderer.gpu.context import make_context
from renderer.gpu.output import WAVEFRONT_GROUP, OutputPass
from renderer.methods import open_renderer

from common import alternating_ms, machine, measured_line, parser, write_results   # benchmarks/common.py

SRGB = Transfer("srgb")
# (label, settings): each method at 1 and 8 bits; more methods add their rows here.
CASES = [(f"{dither} {bits}-bit", OutputSettings(transfer=SRGB, bits=bits, dither=dither))
         for dither in ("none", "bayer2", "bayer4", "bayer8", "blue-noise", *ERROR_DIFFUSION)
         for bits in (1, 8)]
CASES += [(f"half-tone {halftone}", OutputSettings(halftone=halftone))
          for halftone in (Halftone(6, 0), Halftone(6, 7.5))]
CASES += [("none 16-bit (png16)", OutputSettings(transfer=SRGB, format="png16")),
          ("float (exr)", OutputSettings(transfer=SRGB, format="exr"))]


def mask_ms(repeats: int) -> float:
    times = []
    for _ in range(repeats):
        blue_noise_ranks.cache_clear()
        start = time.perf_counter()
        blue_noise_ranks()
        times.append((time.perf_counter() - start) * 1000.0)
    return statistics.median(times)


def empty_wavefronts(stage: OutputPass, settings: OutputSettings, width: int, height: int):
    """A callable running error diffusion's dispatches with nothing to do (OutputPass._diffuse's
    loop, each wavefront's row range empty), and how many there are."""
    program = stage.program(settings)
    wavefront = program["u_wavefront"]
    fronts = list(wavefronts(width, height, KERNELS[settings.dither].skew))

    def run():
        for t, first, last in fronts:
            wavefront.value = (t, 1, 0)            # rows 1 .. 0: none
            program.run((last - first) // WAVEFRONT_GROUP + 1)
            stage.ctx.memory_barrier()
        stage.ctx.finish()
    return run, len(fronts)


def main() -> None:
    args = parser(__doc__, "frames", 15)
    args.add_argument("--scene", default="sphere")
    args = args.parse_args()
    width, height = args.size
    ctx = make_context(args.context)
    with open_renderer(load_scene(args.scene), (width, height), context=ctx) as gpu:
        linear = gpu.render(linear=True, depth=False).linear
    stage = OutputPass(ctx)
    print(machine())
    print(f"output stage, {args.scene} at {width}x{height}, {args.context}, median of {args.frames} frames")
    print(f"{'case':24s} {'GPU ms':>8s} {'twin ms':>8s} {'twin/GPU':>9s}")
    figures = {"scene": args.scene, "size": [width, height], "context": args.context,
               "frames": args.frames, "gl_renderer": ctx.info["GL_RENDERER"],
               "cases": [], "error_diffusion": []}
    for label, settings in CASES:
        stage.apply(linear, settings)
        reference.output.apply(linear, settings)
        gpu_ms, twin_ms = alternating_ms([lambda: stage.apply(linear, settings),
                                          lambda: reference.output.apply(linear, settings)], args.frames)
        print(f"{label:24s} {gpu_ms:8.2f} {twin_ms:8.2f} {twin_ms / gpu_ms:9.1f}")
        figures["cases"].append({"case": label, "gpu_ms": round(gpu_ms, 3), "twin_ms": round(twin_ms, 3)})
    for kernel in ERROR_DIFFUSION:
        settings = OutputSettings(transfer=SRGB, bits=1, dither=kernel)
        empty, count = empty_wavefronts(stage, settings, width, height)
        pass_ms, empty_ms = alternating_ms([lambda: stage.apply(linear, settings), empty], args.frames)
        print(f"{kernel}: {count} dispatches alone {empty_ms:.1f} ms ({1000 * empty_ms / count:.0f} us "
              f"each), {100 * empty_ms / pass_ms:.0f} % of the pass's {pass_ms:.1f} ms")
        figures["error_diffusion"].append({"kernel": kernel, "dispatches": count,
                                           "dispatches_ms": round(empty_ms, 3), "pass_ms": round(pass_ms, 3)})
    mask = mask_ms(args.frames // 5 + 1)
    print(f"blue-noise mask (void-and-cluster, 64 x 64): {mask:.0f} ms")
    figures["mask_ms"] = round(mask, 2)
    stage.release()
    print(f"wrote {write_results('output', figures, markdown)}")


def number(ms: float) -> str:
    """A time in ms: two decimals below 10, one below 100, none above."""
    return f"{ms:.2f}" if ms < 10 else f"{ms:.1f}" if ms < 100 else f"{ms:,.0f}"


def markdown(document: dict) -> str:
    """The tables docs/colour-and-output.md includes, made from a results document (write_results)."""
    f = document["figures"]
    width, height = f["size"]
    cases = {c["case"]: c for c in f["cases"]}
    lines = [f"The output stage alone on `{f['scene']}` at {width}×{height}, {f['context']} "
             f"({f['gl_renderer']}), the median of {f['frames']} frames, the GPU and the twin alternating:",
             "", "| case | GPU ms | twin ms | twin / GPU |", "| --- | ---: | ---: | ---: |"]
    for c in f["cases"]:
        ratio = c["twin_ms"] / c["gpu_ms"]
        lines.append(f"| {c['case']} | {number(c['gpu_ms'])} | {number(c['twin_ms'])} | "
                     + (f"{ratio:.2f} |" if ratio < 1 else f"{ratio:.1f} |"))
    bayer = cases.get("bayer4 1-bit")
    lines += ["", "Error diffusion at 1 bit on the GPU: its wavefronts' dispatches alone (every "
              "wavefront's rows empty) against the whole pass, the two alternating"
              + ("; and the 1-bit pass of the table above over a Bayer 4 pass at 1 bit, on each "
                 "backend" if bayer else "") + ":", "",
              "| kernel | dispatches | dispatches ms | µs each | share of the pass | pass ms |"
              + (" GPU / Bayer 4 | twin / Bayer 4 |" if bayer else ""),
              "| --- | ---: | ---: | ---: | ---: | ---: |" + (" ---: | ---: |" if bayer else "")]
    for e in f["error_diffusion"]:
        row = (f"| {e['kernel']} | {e['dispatches']:,} | {number(e['dispatches_ms'])} | "
               f"{1000 * e['dispatches_ms'] / e['dispatches']:.0f} | "
               f"{100 * e['dispatches_ms'] / e['pass_ms']:.0f} % | {number(e['pass_ms'])} |")
        whole = cases.get(f"{e['kernel']} 1-bit")
        if bayer and whole:
            row += (f" {whole['gpu_ms'] / bayer['gpu_ms']:.0f} | {whole['twin_ms'] / bayer['twin_ms']:.0f} |")
        elif bayer:
            row += " | |"
        lines.append(row)
    lines += ["", f"The blue-noise mask (void-and-cluster, 64×64), made afresh: {number(f['mask_ms'])} ms.",
              "", measured_line(document), ""]
    return "\n".join(lines)


if __name__ == "__main__":
    main()
