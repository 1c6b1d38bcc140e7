"""Write docs/images/pathtrace-vs-radiosity.png (docs/pathtrace.md): radiosity and the path tracer
held against the path-traced truth on the Cornell box, from benchmarks/results/pathtrace.json
(benchmarks/bench_pathtrace.py; no figure here is measured anew): the mean difference in 8-bit
levels against the time of each setting, log-log, a line per method, radiosity's points named by
their elements, the 2/255 bar drawn. Deterministic (matplotlib's Agg canvas, the file's figures).

    PYTHONPATH=. .venv/bin/python tools/make_pathtrace_figure.py [--out PATH.png]
"""

from __future__ import annotations

import io
import json
from pathlib import Path

from contact_sheet import out_option, write_figure

ROOT = Path(__file__).resolve().parent.parent
OUT = ROOT / "docs" / "images" / "pathtrace-vs-radiosity.png"
RESULTS = ROOT / "benchmarks" / "results" / "pathtrace.json"
BAR_LEVELS = 2.0                     # the bar: radiosity within 2/255 of the truth


def figure_png(document: dict) -> bytes:
    from matplotlib.backends.backend_agg import FigureCanvasAgg
    from matplotlib.figure import Figure

    figures = document["figures"]
    figure = Figure(figsize=(6.4, 4.2), dpi=100)
    FigureCanvasAgg(figure)
    axes = figure.add_subplot()
    paths, radiosity = figures["pathtrace"], figures["radiosity"]
    axes.plot([r["seconds"] for r in paths], [r["mean_levels"] for r in paths], "o-", color="C0",
              label="path tracing (16, 64, 256 paths a pixel)")
    axes.plot([r["seconds"] for r in radiosity], [r["mean_levels"] for r in radiosity], "s-", color="C3",
              label=f"radiosity (hemicubes of {figures['hemicube']})")
    for r in radiosity:
        axes.annotate(f"{r['elements']:,}", (r["seconds"], r["mean_levels"]), textcoords="offset points",
                      xytext=(4, 4), fontsize=7, color="C3")
    axes.axhline(BAR_LEVELS, color="black", linestyle=":", linewidth=0.8, label="2/255")
    axes.set_xscale("log")
    axes.set_yscale("log")
    axes.set_xlabel("time per image (s, llvmpipe)")
    axes.set_ylabel("mean |difference| from the truth (8-bit levels)")
    width, height = figures["size"]
    axes.set_title(f"Cornell box {width}x{height}: against {figures['truth_paths']:,} paths a pixel",
                   fontsize=10)
    axes.grid(True, which="both", linewidth=0.3)
    axes.legend(fontsize=7)
    buffer = io.BytesIO()
    figure.savefig(buffer, format="png", metadata={"Software": None}, bbox_inches="tight")
    return buffer.getvalue()


def main(argv: list[str] | None = None) -> None:
    out = out_option(OUT, argv, "Write docs/images/pathtrace-vs-radiosity.png.")
    write_figure(out, figure_png(json.loads(RESULTS.read_text())), ROOT)


if __name__ == "__main__":
    main()
