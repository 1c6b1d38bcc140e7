"""The report.md of `renderer report --method raytrace` (renderer/study/ray_report.py): the
rasteriser's sections (report_output.py) with the ray tracer's scenes, method and a
convergence table in samples and in time."""

from __future__ import annotations

from renderer.study.ground_truth import (RAY_TRUTH_DEPTH, RAY_TRUTH_PASSES, RAY_TRUTH_SAMPLES,
                                         RAY_TRUTH_SEED)
from renderer.study.distributed_report import distributed_sections
from renderer.study.report_output import (cheapest_sections, convergence_slopes, errors_bullet,
                                          generated_line, plots_section, series_name, spread)
from renderer.study.report_settings import RAY_BASE_SAMPLES, RAY_TEXTBOOK_SLOPES, SWEEP_FLAGS


def _slope_lines(rows: list[dict]) -> list[str]:
    """The convergence table: each series' slope of log RMSE in log N and in log time."""
    series = list(dict.fromkeys(series_name(r) for r in rows if r["knob"] == "antialiasing"))
    in_samples = convergence_slopes(rows, series)
    in_time = convergence_slopes(rows, series, x="median_ms")
    lines = ["| series | backend | slope in N | per scene: median (range) | slope in time | "
             "per scene: median (range) | points | N | textbook (in N) | why |",
             "| --- | --- | ---: | --- | ---: | --- | ---: | --- | --- | --- |"]
    for (name, backend), fit in in_samples.items():
        rate, why = RAY_TEXTBOOK_SLOPES[name.split(" @")[0]]
        timed = in_time.get((name, backend))
        time_cells = (f"{timed.slope:.2f} | {spread(timed)}" if timed else "| ")
        lines.append(f"| {name} | {backend} | {fit.slope:.2f} | {spread(fit)} | {time_cells} | "
                     f"{fit.points} | {fit.samples[0]:.3g}-{fit.samples[1]:.3g} | {rate} | {why} |")
    return lines


def ray_report_markdown(result, plots: dict, size, sweep, name: str) -> str:
    rows = result.rows
    scenes = list(dict.fromkeys(r["scene"] for r in rows))
    lines = [
        "# Error against run time: the ray tracer",
        "",
        generated_line(result, size, sweep.runs,
                       f"renderer report --method raytrace{SWEEP_FLAGS[name]}"
                       + (f" --knobs {','.join(result.knobs)}" if result.knobs else "")),
        "",
        "## Scenes",
        "",
        "| scene | spheres | planes | triangles | reflects or refracts |",
        "| --- | ---: | ---: | ---: | --- |",
        *(f"| {name} | {' | '.join(str(cell) for cell in cells)} |"
          for name, cells in result.scenes.items()),
        "",
        "## Method",
        "",
        f"- **Ground truth**: the reference ray tracer in float64 at max depth {RAY_TRUTH_DEPTH}, "
        f"{RAY_TRUTH_PASSES * RAY_TRUTH_SAMPLES} jittered samples per pixel ({RAY_TRUTH_PASSES} "
        f"frames of {RAY_TRUTH_SAMPLES}, each frame's sample indices following the last's, so "
        f"each draws new strata; seed {RAY_TRUTH_SEED}, not the sweep's), the frames' average "
        "linear colour clamped to [0, 1]. It is cached on disk by a hash of the scene's "
        "content, the size and these parameters.",
        errors_bullet() + " Each image is the tracer's average linear colour, clamped, as the "
        "truth.",
        "- **antialiasing** traces at the truth's depth, so its error is the sampling error "
        "alone. One frame traces every sample of every pixel (looped in the shader; one "
        "wavefront in the reference), so time grows with the rays traced. Patterns "
        "(`renderer/core/ray_sampling.py`): `regular` k x k grid and `poisson` dart throwing, "
        "the same offsets in every pixel; `random` uniform and `jittered` one sample per "
        "stratum, new in every pixel (a PCG hash of pixel, sample index and seed). The GPU and "
        "the reference trace the same rays.",
        "- **adaptive 4->N @T/255**: the first 4 samples in the strata of a 2 x 2 grid; a pixel "
        "whose 4 clamped colours spread (max - min, largest channel) more than T/255 gets "
        "samples 5 to N, jittered; `samples` in `results.csv` is the mean traced per pixel, the "
        "x of the adaptive series in N. Unlike the rasteriser's adaptive supersampling (a "
        "full-frame pass per sample), only the refined pixels trace the extra rays, so it can "
        "save time as well as samples: in the reference as far as its rays outweigh its fixed "
        "cost per bounce, on the GPU as far as the fragment shader's lockstep groups let it "
        "(a group waits for its slowest pixel).",
        f"- **max_depth** (depths {', '.join(str(d) for d in sweep.depths)}: bounces of "
        f"reflection and refraction) and **precision** (the reference in float32 and float64, "
        f"at the truth's depth) are sampled with {RAY_BASE_SAMPLES} jittered samples, the same "
        "for every setting of a knob, so the differences between settings are the knob's; at "
        f"depth {RAY_TRUTH_DEPTH} (the truth's) only that sampling error is left, so a depth "
        "as close to it adds nothing visible by going deeper.",
        "",
        "## Convergence of the sampling patterns",
        "",
        "Least-squares slope of log RMSE against log N (samples per pixel; for adaptive, the "
        "mean traced) and against log time (the median ms of a frame), over all scenes, each "
        "scene with its own intercept. The slope in time is what a user pays for: -0.5 means "
        "four times the time halves the error. Where a frame's fixed cost (a GPU frame's "
        "launch and read-back, the reference's set-up of each bounce) outweighs its rays, time "
        "grows slower than N and the slope in time is the steeper. Each N is one realisation "
        "of its pattern (fixed seeds).",
        "",
        *_slope_lines(rows),
        *distributed_sections(rows),
    ]
    lines += cheapest_sections(rows, scenes, "which trace at the truth's depth")
    lines += plots_section(scenes, plots)
    return "\n".join(lines)
