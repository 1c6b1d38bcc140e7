"""What `renderer report` writes: results.csv, one log-log plot per scene and knob, and
report.md (convergence slopes, cheapest settings, the plots). The sweep is renderer/study/report.py."""

from __future__ import annotations

import csv
import io
import math
import os
import platform
import time
from collections import defaultdict
from dataclasses import dataclass

import numpy as np

from renderer.core import sampling
from renderer.study.ground_truth import TRUTH_GRID
from renderer.study.report_settings import (BASE_SAMPLES, CSV_COLUMNS, MISMATCH_LEVELS,
                                            PATTERN_KNOBS, SWEEP_FLAGS, TARGETS_RMSE,
                                            TEXTBOOK_SLOPES)
from renderer.study import output_report, texture_report
from renderer.study.shadow_report import method_bullet, shadow_sections

BACKENDS = ("gpu", "reference")
STYLES = {"gpu": ("o", "-"), "reference": ("s", "--")}          # marker, line per backend
COLOURS = {name: f"C{i}" for i, name in
           enumerate(("regular", "random", "jittered", "poisson", "adaptive", "msaa"))}


def csv_text(rows: list[dict], columns=CSV_COLUMNS) -> str:
    buffer = io.StringIO()
    writer = csv.DictWriter(buffer, columns, lineterminator="\n")
    writer.writeheader()
    for row in rows:
        writer.writerow({key: (f"{value:.6g}" if isinstance(value, float) else value)
                         for key, value in row.items()})
    return buffer.getvalue()


def pareto_front(points: list[tuple[float, float]]) -> list[int]:
    """Indices of the points no other point beats in both time and error (ties kept),
    fastest first."""
    order = sorted(range(len(points)), key=lambda i: (points[i][0], points[i][1]))
    front, best = [], math.inf
    for i in order:
        if points[i][1] < best:
            front.append(i)
            best = points[i][1]
    return front


def series_name(row: dict) -> str:
    """An anti-aliasing row's series: its pattern, an adaptive one's with its threshold when the
    row has a `threshold` column (the ray tracer's: a series per threshold)."""
    threshold = row.get("threshold")
    if "pattern" not in row:                 # a study without patterns (radiosity's)
        return row["backend"]
    return row["pattern"] if threshold in (None, "") else f"{row['pattern']} @{threshold * 255:g}/255"


def series_key(row: dict) -> str:
    """The plot series a row belongs to: series_name and backend for anti-aliasing (and the
    distributed knobs, whose series are patterns too), else backend."""
    return f"{series_name(row)} ({row['backend']})" if row["knob"] in PATTERN_KNOBS else row["backend"]


def _colour(name: str, names: list[str]) -> str:
    """A series' colour: the pattern's own (COLOURS), else the next after them in `names`' order."""
    extra = [other for other in names if other not in COLOURS]
    return COLOURS.get(name) or f"C{len(COLOURS) + extra.index(name)}"


def plot_png(rows: list[dict], title: str, error: str = "rmse",
             label: str = "RMSE against the ground truth (0..1)", linear_below: float = 0.0) -> bytes:
    """PNG bytes of plot_figure (same arguments)."""
    figure = plot_figure(rows, title, error, label, linear_below)
    buffer = io.BytesIO()
    figure.savefig(buffer, format="png", metadata={"Software": None}, bbox_inches="tight")
    return buffer.getvalue()


def plot_figure(rows: list[dict], title: str, error: str = "rmse",
                label: str = "RMSE against the ground truth (0..1)", linear_below: float = 0.0):
    """`error` (a column) against median milliseconds, log-log, a line per series, the Pareto
    front drawn as a dashed staircase through circled points, the legend beside the axes (it
    covered the points inside them), the points named where they fit (plot_labels).
    `linear_below` > 0: the error axis is linear below it (symlog), so that errors of 0 are
    drawn too. A matplotlib Figure on the Agg canvas."""
    from matplotlib.backends.backend_agg import FigureCanvasAgg
    from matplotlib.figure import Figure

    from renderer.study.plot_labels import place_labels

    figure = Figure(figsize=(7.5, 5.0), dpi=100)
    FigureCanvasAgg(figure)
    axes = figure.add_subplot()
    series = defaultdict(list)
    for row in rows:
        if row[error] > 0 or linear_below:
            series[series_key(row)].append(row)
    names = list(dict.fromkeys(series_name(row) for row in rows))
    named = []                               # (text, (x, y), colour): placed once the axes are set
    for index, (name, members) in enumerate(series.items()):
        first = members[0]
        if first["knob"] in PATTERN_KNOBS:          # along the samples; other knobs as swept
            members.sort(key=lambda r: (r["samples"], r.get("max_depth", 0), r["median_ms"]))
        marker, line = STYLES[first["backend"]]
        colour = (_colour(series_name(first), names) if first["knob"] in PATTERN_KNOBS
                  else f"C{index}")
        axes.plot([r["median_ms"] for r in members], [r[error] for r in members], marker=marker,
                  linestyle=line, markersize=4, linewidth=1, color=colour, label=name)
        if first["knob"] not in PATTERN_KNOBS:          # few points: name each one
            for r in members:
                acne = f" (acne {r['acne_pixels']})" if r.get("acne_pixels") else ""
                named.append((r["setting"] + acne, (r["median_ms"], r[error]), colour))
    points = [row for members in series.values() for row in members]
    front = [points[i] for i in pareto_front([(r["median_ms"], r[error]) for r in points])]
    if front:
        axes.step([r["median_ms"] for r in front], [r[error] for r in front], where="post",
                  color="black", linestyle="--", linewidth=0.8)
        axes.scatter([r["median_ms"] for r in front], [r[error] for r in front], s=90,
                     facecolors="none", edgecolors="black", label="Pareto front", zorder=3)
        for r in front if front[0]["knob"] in PATTERN_KNOBS else ():
            named.append((f"{r['setting']} ({r['backend'][:3]})", (r["median_ms"], r[error]), "black"))
    axes.set_xscale("log")
    if linear_below:                       # errors are >= 0: no negative decades, room above
        axes.set_yscale("symlog", linthresh=linear_below)
        axes.set_ylim(0.0, 2.0 * max([linear_below, *(r[error] for r in rows)]))
    else:
        axes.set_yscale("log")
    axes.set_xlabel("median time per image (ms)")
    axes.set_ylabel(label)
    axes.set_title(title)
    axes.grid(True, which="both", linewidth=0.3)
    axes.legend(fontsize=7, loc="upper left", bbox_to_anchor=(1.02, 1.0), borderaxespad=0.0)
    figure.subplots_adjust(right=0.68)
    figure.canvas.draw()                     # the limits the labels are placed against
    for colour in dict.fromkeys(c for _, _, c in named):
        place_labels(axes, [(text, xy) for text, xy, c in named if c == colour], fontsize=6,
                     color=colour)
    return figure


@dataclass
class Slope:
    """A series' convergence on one backend: log RMSE against log N or log time."""
    slope: float                     # least squares over all scenes, each its own intercept
    points: int
    samples: tuple                   # (smallest N, largest N), samples per pixel spent
    per_scene: list                  # each scene's own least-squares slope


def _fit(x: np.ndarray, y: np.ndarray) -> float:
    """Least-squares slope of already centred data."""
    return float(np.sum(x * y) / np.sum(x * x))


def convergence_slopes(rows: list[dict], series=tuple(sampling.PATTERNS), x: str = "samples",
                       knob: str = "antialiasing") -> dict:
    """(series, backend) -> Slope of log RMSE against log `x` ("samples", "light_samples" or
    "median_ms"), for the rows of `knob` (the anti-aliasing rows by default) of each of
    `series` (series_name)."""
    slopes = {}
    for name in series:
        for backend in BACKENDS:
            by_scene = defaultdict(list)
            for row in rows:
                if row["knob"] == knob and series_name(row) == name \
                        and row["backend"] == backend and row["rmse"] > 0:
                    by_scene[row["scene"]].append((row[x], math.log(row["rmse"]), row["samples"]))
            centred = []
            for points in by_scene.values():
                along, log_rmse, n = np.array(points).T
                if np.ptp(along) > 0:
                    centred.append((np.log(along) - np.log(along).mean(),
                                    log_rmse - log_rmse.mean(), n))
            if centred:
                cx, cy, n = (np.concatenate(parts) for parts in zip(*centred))
                slopes[(name, backend)] = Slope(_fit(cx, cy), len(cx), (n.min(), n.max()),
                                                [_fit(px, py) for px, py, _ in centred])
    return slopes


def cheapest(rows: list[dict], scene: str, backend: str, target: float) -> dict | None:
    """The fastest row of `scene` on `backend` whose RMSE is at most `target`, or None (a row
    without an RMSE, a shadow knob's, never)."""
    good = [r for r in rows if r["scene"] == scene and r["backend"] == backend
            and r.get("rmse") is not None and r["rmse"] <= target]
    return min(good, key=lambda r: r["median_ms"]) if good else None


def _ms(value: float) -> str:
    return f"{value:.3g}"


def cheapest_sections(rows: list[dict], scenes: list[str], antialiasing: str) -> list[str]:
    """The markdown lines naming, per scene and backend, the cheapest setting reaching each of
    TARGETS_RMSE; `antialiasing` says in parentheses what the anti-aliasing settings draw (their
    table is left out when no row is theirs)."""
    return [line for target in TARGETS_RMSE
            for line in _cheapest_section(rows, scenes, target, antialiasing)]


def _cheapest_section(rows: list[dict], scenes: list[str], target: float,
                      antialiasing: str) -> list[str]:
    tables = [("Any knob", None)]
    if any(r["knob"] == "antialiasing" for r in rows):
        tables.append(("Anti-aliasing only", "antialiasing"))
    lines = [
        "",
        f"## Cheapest setting reaching RMSE <= {target:g} (about {target * 255:.1f}/255)",
        "",
        "The fastest setting (median time per image) whose RMSE against the ground truth is at "
        "most the target" + (", first over every knob's settings, then among the anti-aliasing "
                             f"settings alone ({antialiasing})." if len(tables) > 1 else "."),
        "",
    ]
    for title, knob in tables:
        lines += [f"{title}:", "",
                  "| scene | GPU | ms | RMSE | reference | ms | RMSE |",
                  "| --- | --- | ---: | ---: | --- | ---: | ---: |"]
        for scene in scenes:
            cells = [scene]
            for backend in BACKENDS:
                best = cheapest([r for r in rows if knob in (None, r["knob"])], scene, backend, target)
                cells += (["none reaches it", "", ""] if best is None else
                          [f"{best['knob']}: {best['setting']}", _ms(best["median_ms"]),
                           f"{best['rmse']:.4f}"])
            lines.append("| " + " | ".join(cells) + " |")
        lines.append("")
    return lines


def generated_line(result, size, runs: int, command: str) -> str:
    """The paragraph saying how, when and where the report was made."""
    width, height = size
    scenes = len(dict.fromkeys(r["scene"] for r in result.rows))
    return (f"Generated by `{command}` on {time.strftime('%Y-%m-%d', time.gmtime())} at "
            f"{width}x{height} pixels on {platform.machine()} with {os.cpu_count()} CPUs, GL "
            f"renderer `{result.gl_renderer}`; {scenes} scene(s), {len(result.rows)} rows, "
            f"{result.seconds / 60:.1f} minutes ({result.truth_hits} ground truth(s) from the "
            f"cache). Where the settings ran: {result.where}. Every time is the median of {runs} "
            "runs of the whole setting (all its passes) in the process named in the `worker` "
            "column of `results.csv`, which has every figure.")


def errors_bullet() -> str:
    """The Method section's line on what the errors are."""
    return ("- **Errors** are on the float image in [0, 1]: `rmse`, `max_abs`, `psnr` (dB, peak "
            "1), `flip_mean` (ꟻLIP, LDR, both images quantised to 8 bits) and "
            f"`mismatched_fraction` (pixels more than {MISMATCH_LEVELS}/255 off in some channel "
            "after 8-bit quantisation).")


def spread(fit: Slope) -> str:
    """A fit's per-scene slopes: median (range)."""
    return (f"{np.median(fit.per_scene):.2f} ({min(fit.per_scene):.2f} to "
            f"{max(fit.per_scene):.2f})")


def plots_section(scenes: list[str], plots: dict) -> list[str]:
    lines = ["## Plots", "",
             "RMSE against the median time per image, log-log (the shadow knobs: the fraction "
             "of pixels wrong outside the 1-texel band, linear below 0.01 %, so that 0 shows); "
             "circled points joined by the dashed staircase are the Pareto front (no other "
             "setting is both faster and more accurate). The output knob's plots are its "
             "errors and times against the bits per channel, a line per method.", ""]
    for scene in scenes:
        lines += [f"### {scene}", ""]
        for (plot_scene, knob), path in plots.items():
            if plot_scene == scene:
                lines += [f"![{scene}: {knob}]({path})", ""]
    return lines


def truth_bullets(result, sweep, families: set) -> list[str]:
    """The Method section's lines on the ground truth and the errors against it."""
    return [
        f"- **Ground truth**: the NumPy reference in float64, Phong shading on every object, every "
        f"curved primitive at the finest tessellation (x{sweep.levels[-1]:g} of the authored "
        f"segment counts), {TRUTH_GRID}x{TRUTH_GRID} regular-grid supersampling per pixel "
        "(rendered once at 16W x 16H and box-filtered), clamped linear colour in [0, 1]. It is "
        "cached on disk by a hash of the scene's content, the size and these parameters.",
        *([texture_report.truth_bullet()] if any(textures for *_, textures in result.scenes.values()) else []),
        errors_bullet() + (" MSAA resolves into an 8-bit buffer, so its error has a 1/255 "
                           "quantisation floor (RMSE about 0.001) that the float accumulation "
                           "does not." if "antialiasing" in families else ""),
    ]


def report_markdown(result, plots: dict, size, sweep, name: str) -> str:
    """report.md: the Method bullets and the sections of the knob families in the rows."""
    rows = result.rows
    scenes = list(dict.fromkeys(r["scene"] for r in rows))
    families = {r["knob"].split("-")[0] for r in rows}
    lines = [
        "# Error against run time",
        "",
        generated_line(result, size, sweep.runs, f"renderer report{SWEEP_FLAGS[name]}"
                       + (f" --knobs {','.join(result.knobs)}" if result.knobs else "")),
        "",
        "## Scenes",
        "",
        "| scene | triangles as authored | at the finest tessellation (ground truth, anti-aliasing) "
        "| textures (as authored) |",
        "| --- | ---: | ---: | --- |",
        *(f"| {name} | {authored} | {finest} | {textures or 'none'} |"
          for name, (authored, finest, textures) in result.scenes.items()),
        "",
        "## Method",
        "",
        *(truth_bullets(result, sweep, families)
          if families - {"shadows", output_report.KNOB} else []),   # some knob against the truth
    ]
    if "antialiasing" in families:
        lines += [
            "- **antialiasing** draws the truth's scene (Phong, finest tessellation), so its error is "
            "the sampling error alone. Supersampling accumulates one full-frame pass per sample, "
            "each pass the projection moved by the sample's offset (every pixel uses the same "
            "pattern), and averages the clamped linear colour; the GPU and the reference use the "
            "same offsets. Patterns (`renderer/core/sampling.py`): `regular` k x k grid, `random` "
            "uniform, `jittered` one sample per stratum, `poisson` dart throwing (fixed seeds). "
            "`msaa N` is GL's multisampling (GPU only; the sample counts the context offers for an "
            "RGBA8 buffer, which on llvmpipe are 1 and 4 (GL_MAX_SAMPLES = 4; a request for 2 gets 4); "
            "`msaa 1` is one sample at the pixel centre).",
            "- **adaptive FIRST->TOTAL @T**: FIRST jittered samples; a pixel whose samples' range "
            "(max - min, largest channel) exceeds T gets TOTAL - FIRST more. `samples` in "
            "`results.csv` is the mean spent per pixel. The extra samples are paid in full: each is a "
            "full-frame pass on both backends (no scissor or stencil), whose result is used only at "
            "the flagged pixels, so adaptive sampling saves samples per pixel but not time here."]
    if families & {"tessellation", "shading", "precision"}:
        lines.append(
            f"- **tessellation** (levels x{', x'.join(f'{l:g}' for l in sweep.levels)} of the "
            f"authored segment counts; icospheres +-log2 subdivisions), **shading** (each mode at "
            f"the authored tessellation) and **precision** (reference in float32 and float64, the "
            f"truth's scene) are sampled with a {BASE_SAMPLES}-sample regular grid, the same for "
            "every setting of a knob, so the differences between settings are the knob's.")
    if "shadows" in families:
        lines.append(method_bullet())
    if families & set(texture_report.KNOBS):
        lines.append(texture_report.method_bullet())
    if output_report.KNOB in families:
        lines.append(output_report.method_bullet())
    if "antialiasing" in families:
        lines += [
            "",
            "## Convergence of the sampling patterns",
            "",
            "Least-squares slope of log RMSE against log N (samples per pixel) over all scenes, each "
            "scene with its own intercept, beside the textbook rate (Mitchell 1996). The textbook "
            "rates are asymptotic and for edge pixels; a scene's RMSE also holds smooth shading, "
            "which every pattern resolves at N = 1 already, and the fitted range starts at N = 1. "
            "Each N is one realisation of its pattern (fixed seeds; at N = 1 random, jittered and "
            "Poisson are the same single uniform sample), so a slope carries that pattern's noise.",
            "",
            "| pattern | backend | fitted slope | per scene: median (range) | points | N | textbook | why |",
            "| --- | --- | ---: | --- | ---: | --- | --- | --- |",
        ]
        for (pattern, backend), fit in convergence_slopes(rows).items():
            rate, why = TEXTBOOK_SLOPES[pattern]
            lines.append(f"| {pattern} | {backend} | {fit.slope:.2f} | {spread(fit)} | {fit.points} | "
                         f"{fit.samples[0]:g}-{fit.samples[1]:g} | {rate} | {why} |")
    if any(r.get("rmse") is not None for r in rows):
        lines += cheapest_sections(rows, scenes, "which draw the truth's geometry and shading")
    lines += texture_sections(rows)
    lines += output_report.output_sections(rows)
    lines += shadow_sections(rows, scenes) + [""]
    lines += plots_section(scenes, plots)
    return "\n".join(lines)


def texture_sections(rows: list[dict]) -> list[str]:
    """The section on the texture knobs present in `rows` (renderer/study/texture_report.py),
    per scene: every setting's time and error on both backends, and the settings on each
    backend's Pareto front of time and RMSE."""
    rows = [r for r in rows if r["knob"] in texture_report.KNOBS]
    if not rows:
        return []
    lines = ["", "## Textures: filter and resolution", "",
             "Per textured scene, each setting's median frame time and its error against the "
             "truth (RMSE, and ꟻLIP on the GPU's image) on the GPU and in the reference, then the "
             "settings on each backend's Pareto front (no other setting both faster and more "
             "accurate)."]
    for name in dict.fromkeys(r["scene"] for r in rows):
        scene_rows = [r for r in rows if r["scene"] == name]
        lines += ["", f"### {name}", "",
                  "| knob | setting | GPU ms | GPU RMSE | GPU ꟻLIP | reference ms | reference RMSE |",
                  "| --- | --- | ---: | ---: | ---: | ---: | ---: |"]
        for knob, setting in dict.fromkeys((r["knob"], r["setting"]) for r in scene_rows):
            cells = {r["backend"]: r for r in scene_rows if (r["knob"], r["setting"]) == (knob, setting)}
            gpu, ref = cells.get("gpu"), cells.get("reference")
            figures = ([_ms(gpu["median_ms"]), f"{gpu['rmse']:.4f}", f"{gpu['flip_mean']:.4f}"]
                       if gpu else ["", "", ""])
            figures += [_ms(ref["median_ms"]), f"{ref['rmse']:.4f}"] if ref else ["", ""]
            lines.append(f"| {knob} | {setting} | " + " | ".join(figures) + " |")
        for backend in BACKENDS:
            members = [r for r in scene_rows if r["backend"] == backend]
            front = [members[i] for i in pareto_front([(r["median_ms"], r["rmse"]) for r in members])]
            lines += ["", f"Pareto front, {backend} (fastest first): " + ", ".join(
                f"{r['knob']} {r['setting']} ({_ms(r['median_ms'])} ms, RMSE {r['rmse']:.4f})"
                for r in front) + "."]
    return lines
