"""The report.md of `renderer report --method radiosity` (renderer/study/radiosity_report.py):
the scenes, the method, each knob's table, the slopes of the error against time and elements,
the cheapest settings and the plots (report_output.py's sections where they fit)."""

from __future__ import annotations



import numpy as np

from renderer.study.ground_truth import (PATH_TRUTH_DEPTH, PATH_TRUTH_PASSES, PATH_TRUTH_SAMPLES,
                                         RAY_TRUTH_SEED)
from renderer.study.report_output import cheapest_sections, errors_bullet, generated_line, plots_section
from renderer.checks.radiosity_vs_pathtrace import FOOTPRINT
from renderer.study.report_settings import SWEEP_FLAGS, TWIN_ACROSS


def slope(rows: list[dict], x: str) -> float | None:
    """The least-squares slope of log RMSE against log `x` over `rows` (None under 2 points)."""
    points = [(row[x], row["rmse"]) for row in rows if row[x] and row["rmse"] > 0]
    if len(points) < 2 or len({p[0] for p in points}) < 2:
        return None
    along, rmse = np.log(np.array(points, np.float64)).T
    return float(np.polyfit(along, rmse, 1)[0])


def _slope_cell(value: float | None) -> str:
    return "" if value is None else f"{value:.2f}"


def knob_tables(rows: list[dict], scenes: list[str]) -> list[str]:
    """Per scene and knob, each setting's elements, time and errors; the knob's slopes."""
    lines = []
    for scene in scenes:
        lines += [f"### {scene}", ""]
        for knob in dict.fromkeys(r["knob"] for r in rows if r["scene"] == scene):
            mine = [r for r in rows if r["scene"] == scene and r["knob"] == knob]
            lines += [f"{knob}:", "", "| setting | backend | elements | ms | RMSE | mismatched | PSNR |",
                      "| --- | --- | ---: | ---: | ---: | ---: | ---: |"]
            lines += [f"| {r['setting']} | {r['backend']} | {r['samples']:,.0f} | {r['median_ms']:.4g} | "
                      f"{r['rmse']:.4f} | {r['mismatched_fraction']:.1%} | {r['psnr']:.1f} |" for r in mine]
            lines.append("")
    return lines


def slope_lines(rows: list[dict], scenes: list[str]) -> list[str]:
    """The element size's and the hemicube's slopes of log RMSE, per scene, on the GPU."""
    lines = ["| scene | element size: in time | in elements | hemicube: in time |",
             "| --- | ---: | ---: | ---: |"]
    for scene in scenes:
        gpu = [r for r in rows if r["scene"] == scene and r["backend"] == "gpu"]
        sizes = [r for r in gpu if r["knob"] == "element_size"]
        cubes = [r for r in gpu if r["knob"] == "hemicube"]
        lines.append(f"| {scene} | {_slope_cell(slope(sizes, 'median_ms'))} | "
                     f"{_slope_cell(slope(sizes, 'samples'))} | {_slope_cell(slope(cubes, 'median_ms'))} |")
    return lines


def radiosity_report_markdown(result, plots: dict, size, sweep, name: str) -> str:
    rows = result.rows
    scenes = list(dict.fromkeys(r["scene"] for r in rows))
    lines = [
        "# Error against run time: radiosity",
        "",
        generated_line(result, size, sweep.runs,
                       f"renderer report --method radiosity{SWEEP_FLAGS[name]}"
                       + (f" --knobs {','.join(result.knobs)}" if result.knobs else "")),
        "",
        "## Scenes",
        "",
        "| scene | triangles | emitting objects | elements at the default size |",
        "| --- | ---: | ---: | ---: |",
        *(f"| {scene} | {' | '.join(f'{cell:,}' for cell in cells)} |"
          for scene, cells in result.scenes.items()),
        "",
        "## Method",
        "",
        f"- **Ground truth**: the path tracer (docs/pathtrace.md), which shares nothing with "
        f"radiosity but the scene: {PATH_TRUTH_PASSES * PATH_TRUTH_SAMPLES} jittered paths a "
        f"pixel ({PATH_TRUTH_PASSES} frames of {PATH_TRUTH_SAMPLES}, each new paths), up to "
        f"{PATH_TRUTH_DEPTH} bounces, seed {RAY_TRUTH_SEED}, on the GPU (whose paths are its "
        "twin's: tests/test_pathtrace.py), the average clamped to [0, 1]. Its own noise is in "
        "every error: its standard error is about 1.6e-3 on the Cornell box at 160x120 "
        "(benchmarks/results/pathtrace.md). Cached on disk by a hash of the scene's content, the "
        "size and these parameters.",
        errors_bullet() + " Each image is radiosity's displayed radiosity (B, linear) drawn at "
        f"{FOOTPRINT} times the size and each {FOOTPRINT} x {FOOTPRINT} block averaged, then "
        "clamped: the pixel's mean, as the truth's paths cover the pixel (a pixel-centre image "
        "would add its edges' aliasing to radiosity's error).",
        f"- **element_size**: the scene's diagonal cut into {', '.join(str(a) for a in sweep.across)} "
        "(`elements_across`; 12 is radiosity's default), hemicubes of 64, Gauss-Seidel to its "
        f"tolerance; the twin draws those of at most {TWIN_ACROSS} across (its hemicubes are O(E^2) "
        "NumPy). **hemicube**: "
        f"{', '.join(str(n) for n in sweep.hemicubes)} pixels across, the default elements. "
        "**iterations**: Gauss-Seidel's sweeps "
        f"{', '.join('to the tolerance' if k is None else str(k) for k in sweep.sweeps)}, the "
        "default elements and hemicubes.",
        "- Each time is a renderer made from nothing and drawn: elements, hemicubes, form "
        "factors, solution and display, as a first frame (the form factors are kept while only "
        "the camera moves, so later frames cost the display alone). `samples` in `results.csv` "
        "is the elements, one hemicube each.",
        "",
        "## Each knob",
        "",
        *knob_tables(rows, scenes),
        "## Convergence",
        "",
        "Slopes of log RMSE against log time and log elements (least squares, the GPU's rows). "
        "Finer elements follow the shading's gradients and shadows better; the form factors' cost "
        "grows up to the elements squared, so the error falls more slowly in time than in "
        "elements. Where the truth's noise is reached the error stops falling.",
        "",
        *slope_lines(rows, scenes),
        *cheapest_sections(rows, scenes, "none: radiosity has no anti-aliasing knob"),
        *plots_section(scenes, plots),
    ]
    return "\n".join(lines) + "\n"



