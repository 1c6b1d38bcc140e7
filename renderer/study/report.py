"""`renderer report`: error against run time over quality settings (issue 4, part 1).

Each scene is rendered at a series of settings of four knobs, each setting on each backend
(the GPU path and the NumPy reference) `runs` times; the median time and the error of the
image against the ground truth (renderer/study/ground_truth.py) make one row of results.csv.

    knob            settings                                          scene drawn
    antialiasing    regular / random / jittered / poisson at N        the truth's (Phong,
                    samples, adaptive FIRST->TOTAL at a threshold,    finest tessellation):
                    msaa N (GPU only: the counts the context          the error is the
                    offers, gpu.multisample_counts)                   sampling error alone
    tessellation    levels x0.25 .. x4 of the authored segments       Phong, 4-sample grid
    shading         flat, gouraud, phong                              authored tessellation,
                                                                      4-sample grid
    precision       float32, float64 (reference only)                 the truth's, 4-sample grid
    shadows-*       map resolution, filter, bias rule (shadow_report.py;  as authored, one
                    scenes with shadow maps): error against ray-cast      sample per pixel
                    truth, not the image's
    filter,         the texture filter; the textures resampled to R       as authored, one
    texture_        texels on their long side (texture_report.py;         sample per pixel
    resolution      textured scenes)
    output          the output stage's methods at 1 to 8 bits per         as authored, one
                    channel (output_report.py): against the undithered    sample per pixel
                    linear image, not the truth; the stage's time alone

Errors are on the float image in [0, 1] (renderer/study/supersample.py) against the float truth:
rmse, max_abs, psnr (dB, peak 1), flip_mean (ꟻLIP on both images quantised to 8 bits) and
mismatched_fraction (pixels whose 8-bit value differs from the truth's by more than 2/255 in
some channel). report.md, results.csv and plots/SCENE-KNOB.png are written when the sweep
has finished, each atomically.

run_report drives a study: RasterStudy, this sweep, or (method="raytrace") renderer/study/
ray_report.py's RayStudy, the ray tracer's knobs against its own ground truth, or
(method="radiosity") renderer/study/radiosity_report.py's RadiosityStudy, radiosity's knobs
against a path-traced truth, with the same metrics, plots and tables. `knobs` (the command's --knobs) keeps only some knob families.
The rows run in this process or on Ray workers (--address, --workers: renderer/study/
report_units.py), with the same results.csv but for the times and the `worker` that took them.
"""

from __future__ import annotations

import math
import sys
import time
from dataclasses import dataclass, field
from pathlib import Path

import numpy as np

from renderer.core import sampling
from renderer.core.drawn import triangle_bound
from renderer.core.shadow_settings import BIAS_RULES, FILTERS
from renderer.study.report_output import csv_text, plot_png, report_markdown
from renderer.study.ground_truth import (MAX_TRUTH_PIXELS, TRUTH_GRID, cache_path,
                                         default_cache_dir, ground_truths, truth_scene)
from renderer.core.imageio import outputs
from renderer.study.supersample import (adaptive_supersample, gpu_pass, msaa_image, reference_pass,
                                  supersample)
from renderer.study.metrics import metrics
from renderer.study.report_units import SceneWork, gl_facts, run_units, truth_cost, unit_cost
from renderer.study import output_report
from renderer.study.report_settings import (BASE_SAMPLES, CSV_COLUMNS, DEFAULT_SIZE, QUICK_SIZE,
                                            SHADOW_RESOLUTIONS)
from renderer.study.shadow_report import (fits, plot_axis, shadow_errors, shadow_variants,
                                          with_shadow_setting)
from renderer.study.tessellation import FINEST, LEVELS, scene_at_level
from renderer.study.texture_report import (FILTER_SETTINGS, TEXTURE_RESOLUTIONS, is_textured,
                                           texture_line, texture_variants, with_texture_setting)
from renderer.study.timing import median_timed

@dataclass(frozen=True)
class Sweep:
    """Which settings a report renders."""
    sample_counts: tuple = (1, 4, 16, 64)          # per pattern; regular keeps the squares
    adaptive: tuple = ((4, 16, 0.05), (4, 64, 0.05))   # (first, total, threshold)
    levels: tuple = LEVELS
    shadow_resolutions: tuple = SHADOW_RESOLUTIONS
    shadow_filters: tuple = tuple(FILTERS)
    shadow_biases: tuple = BIAS_RULES
    texture_filters: tuple = FILTER_SETTINGS
    texture_resolutions: tuple = TEXTURE_RESOLUTIONS
    output_methods: tuple = output_report.METHODS
    output_bits: tuple = output_report.BITS
    output_halftone: bool = True
    output_code_value: tuple = output_report.CODE_VALUE
    runs: int = 5


EXHAUSTIVE = Sweep()
# The default: every knob's settings but 64 samples a pixel, 3 runs a setting. The reference's
# 64-sample rows at 5 runs were most of the exhaustive sweep's time: its passes at the truth's
# tessellation take 1.8 s for the 20 built-in raster scenes at 160x120, and the antialiasing
# knob draws 380 of them a run (about 57 minutes in all) where this sweep's draws 92 at 3 runs.
STANDARD = Sweep(sample_counts=(1, 4, 16), adaptive=((4, 16, 0.05),), runs=3)
# --quick (CI's sweep, under 90 s): fewer settings of every knob, two small scenes at 64x48.
QUICK = Sweep(sample_counts=(1, 4, 16), runs=3,
              adaptive=((4, 16, 0.05),), levels=(0.25, 1.0, FINEST), shadow_resolutions=(256, 1024),
              shadow_filters=("hard", "pcf2x2"), shadow_biases=("auto", "none"),
              texture_filters=(("nearest", 1), ("trilinear", 1), ("anisotropic", 16)),
              texture_resolutions=(64, 256),
              output_methods=("none", "bayer4", "blue-noise", "floyd-steinberg"), output_bits=(1, 8))
SWEEPS = {"quick": QUICK, "standard": STANDARD, "exhaustive": EXHAUSTIVE}
KNOB_FAMILIES = ("antialiasing", "tessellation", "shading", "precision", "shadows", "filter",
                 "texture_resolution", output_report.KNOB)


@dataclass(frozen=True)
class Setting:
    """One row's recipe: what to draw (`variant`) and how to sample it, on which backend."""
    knob: str
    setting: str
    backend: str                     # "gpu" or "reference"
    pattern: str                     # a sampling pattern, "adaptive", "msaa", or "regular"
    variant: tuple                   # ("truth",) | ("level", L) | ("shading", mode) |
                                     # ("shadow", field, value): shadow_report.py |
                                     # ("texture", field, value): texture_report.py |
                                     # ("output", kind, method, bits): output_report.py
    sampling: tuple                  # ("pattern", name, N) | ("adaptive", first, total, t) | ("msaa", N)
    dtype: str = "float64"

    def columns(self) -> dict:
        """The columns of results.csv that name this setting."""
        return {"knob": self.knob, "setting": self.setting, "backend": self.backend,
                "pattern": self.pattern}


def settings(sweep: Sweep, msaa_counts: list[int]) -> list[Setting]:
    """Every setting of every knob, each backend it runs on."""
    both = ("gpu", "reference")
    out = []
    for name in sampling.PATTERNS:
        for n in sweep.sample_counts:
            if name == "regular" and math.isqrt(n) ** 2 != n:
                continue
            out += [Setting("antialiasing", f"{name} {n}", b, name, ("truth",), ("pattern", name, n))
                    for b in both]
    for first, total, threshold in sweep.adaptive:
        out += [Setting("antialiasing", f"adaptive {first}->{total} @{threshold:g}", b, "adaptive",
                        ("truth",), ("adaptive", first, total, threshold)) for b in both]
    out += [Setting("antialiasing", f"msaa {n}", "gpu", "msaa", ("truth",), ("msaa", n))
            for n in msaa_counts]
    base = ("pattern", "regular", BASE_SAMPLES)
    for level in sweep.levels:
        out += [Setting("tessellation", f"x{level:g}", b, "regular", ("level", level), base)
                for b in both]
    for mode in ("flat", "gouraud", "phong"):
        out += [Setting("shading", mode, b, "regular", ("shading", mode), base) for b in both]
    out += [Setting("precision", dtype, "reference", "regular", ("truth",), base, dtype)
            for dtype in ("float32", "float64")]
    for knob, name, variant in shadow_variants(sweep.shadow_resolutions, sweep.shadow_filters,
                                               sweep.shadow_biases):
        out += [Setting(knob, name, b, "regular", variant, ("pattern", "regular", 1)) for b in both]
    for knob, name, variant in texture_variants(sweep.texture_filters, sweep.texture_resolutions):
        out += [Setting(knob, name, b, "regular", variant, ("pattern", "regular", 1)) for b in both]
    for name, variant, backends in output_report.output_variants(
            sweep.output_methods, sweep.output_bits, sweep.output_halftone, sweep.output_code_value):
        out += [Setting(output_report.KNOB, name, b, "regular", variant, ("pattern", "regular", 1))
                for b in backends]
    return out


class SceneRun:
    """Renders one scene's settings; GL renderers are made once per drawn variant and reused
    by every run of every setting that draws it."""

    def __init__(self, scene, width: int, height: int, ctx):
        self.scene, self.width, self.height, self.ctx = scene, width, height, ctx
        self.subpixel_bits = int(ctx.info["GL_SUBPIXEL_BITS"])      # the reference snaps as GL does
        self._scenes: dict[tuple, object] = {}
        self._gpus: dict[tuple, object] = {}
        self._shadow_errors: dict[tuple, dict] = {}
        self._output = None                       # output_report.OutputRun, made on first use

    def drawn(self, variant: tuple):
        if variant not in self._scenes:
            kind = variant[0]
            self._scenes[variant] = (
                truth_scene(self.scene) if kind == "truth" else
                scene_at_level(self.scene.with_shading("phong"), variant[1]) if kind == "level" else
                with_shadow_setting(self.scene, *variant[1:]) if kind == "shadow" else
                with_texture_setting(self.scene, *variant[1:]) if kind == "texture" else
                self.scene if kind == "output" else
                self.scene.with_shading(variant[1]))
        return self._scenes[variant]

    def gpu(self, variant: tuple):
        if variant not in self._gpus:
            from renderer.methods import open_renderer
            self._gpus[variant] = open_renderer(self.drawn(variant), (self.width, self.height),
                                                context=self.ctx)
        return self._gpus[variant]

    def output(self) -> output_report.OutputRun:
        """The output settings' frame and stage: the scene as authored, drawn once."""
        if self._output is None:
            self._output = output_report.OutputRun(self.gpu(("output",)))
        return self._output

    def render(self, setting: Setting) -> tuple[np.ndarray, float]:
        """(image (H, W, 3) float64 in [0, 1], samples per pixel spent); an output setting's
        (H, W, 4) codes of its stage alone, the frame drawn before."""
        if setting.variant[0] == output_report.KNOB:
            return self.output().codes(setting.variant, setting.backend), 1.0
        kind, *args = setting.sampling
        if kind == "msaa":
            return msaa_image(self.gpu(setting.variant), args[0]), float(args[0])
        if setting.backend == "gpu":
            pass_ = gpu_pass(self.gpu(setting.variant))
        else:
            pass_ = reference_pass(self.drawn(setting.variant), self.width, self.height,
                                   dtype=np.dtype(setting.dtype), subpixel_bits=self.subpixel_bits)
        if kind == "adaptive":
            return adaptive_supersample(pass_, *args)
        name, n = args
        return supersample(pass_, sampling.pattern(name, n)), float(n)

    def timed(self, setting: Setting, runs: int) -> tuple[np.ndarray, float, float]:
        """(image, samples per pixel, median ms of `runs` runs of the whole setting; timing.py).
        An output setting's first run (its frame, tables, masks, program) is not timed either."""
        (image, samples), ms = median_timed(lambda: self.render(setting), runs, warm_up=(
            setting.backend == "gpu" or setting.variant[0] == output_report.KNOB))
        return image, samples, ms

    def errors(self, setting: Setting, image: np.ndarray, truth: np.ndarray | None) -> dict:
        """A row's errors: a shadow setting's against ray-cast truth (one measurement for both
        backends: shadow_report.py), an output setting's against the linear frame it shows
        (output_report.py), any other's image against the ground truth (metrics)."""
        if setting.variant[0] == output_report.KNOB:
            return self.output().errors(setting.variant, image)
        if setting.variant[0] != "shadow":
            return metrics(image, truth)
        if setting.variant not in self._shadow_errors:
            self._shadow_errors[setting.variant] = shadow_errors(self.drawn(setting.variant),
                                                                 self.width, self.height)
        return self._shadow_errors[setting.variant]

    def release(self) -> None:
        if self._output is not None:
            self._output.release()
            self._output = None
        for gpu in self._gpus.values():
            gpu.release()
        self._gpus.clear()


class RasterStudy:
    """The rasteriser's sweep (module docstring), as run_report drives it; renderer/study/
    ray_report.py's RayStudy is the ray tracer's, with the same methods."""
    method = "raster"
    columns = CSV_COLUMNS
    knobs = KNOB_FAMILIES

    def sweep(self, name: str) -> Sweep:
        """The sweep called `name` (report_settings.SWEEP_NAMES)."""
        return SWEEPS[name]

    def size(self, name: str) -> tuple[int, int]:
        return QUICK_SIZE if name == "quick" else DEFAULT_SIZE

    def check(self, scenes: list, width: int, height: int) -> None:
        """A UserError, before any work, for what the sweep cannot do."""
        from renderer.errors import UserError
        if width * height * TRUTH_GRID ** 2 > MAX_TRUTH_PIXELS:
            raise UserError(f"{width}x{height} is too large for the ground truth ({TRUTH_GRID}x"
                            f"{TRUTH_GRID} samples per pixel, at most 320x240 pixels)", key="--size")

    def settings(self, sweep: Sweep, ctx) -> list[Setting]:
        from renderer.gpu.pipeline import multisample_counts
        return settings(sweep, multisample_counts(ctx))

    def scene_settings(self, plan: list[Setting], scene, width: int, height: int) -> list[Setting]:
        """The settings `scene` gets: the shadow knobs only where it has shadow maps that fit,
        the texture knobs only where some material is textured."""
        return [s for s in plan if (s.variant[0] != "shadow" or fits(scene, s.variant, width, height))
                and (s.variant[0] != "texture" or is_textured(scene))]

    def needs_truth(self, plan: list[Setting]) -> bool:
        """Whether some setting's error is against the ground truth image (not a shadow or an
        output knob's)."""
        return any(s.variant[0] not in ("shadow", output_report.KNOB) for s in plan)

    def describe(self, scene) -> tuple:
        """The Scenes table's cells: triangles as authored, at the finest tessellation (the most
        the camera pass draws: an analytic plane's polygon at most MAX_POLYGON_TRIANGLES); the
        textures as authored."""
        return (*(sum(triangle_bound(obj) for obj in drawn.objects)
                  for drawn in (scene, truth_scene(scene))), texture_line(scene))

    def scene_run(self, scene, width: int, height: int, ctx) -> SceneRun:
        return SceneRun(scene, width, height, ctx)

    def markdown(self, result, plots: dict, size, sweep: Sweep, name: str) -> str:
        return report_markdown(result, plots, size, sweep, name)


def _ray_study():
    from renderer.study.ray_report import RayStudy      # (it imports this module)
    return RayStudy()


def _radiosity_study():
    from renderer.study.radiosity_report import RadiosityStudy
    return RadiosityStudy()


# Each method's sweep, by the name renderer/methods registers it under.
STUDIES = {"raster": RasterStudy, "raytrace": _ray_study, "radiosity": _radiosity_study}


def study(method: str):
    """The sweep of `method` (a key of STUDIES)."""
    if method not in STUDIES:
        raise ValueError(f"no report is made for method {method!r}; one of {', '.join(STUDIES)}")
    return STUDIES[method]()


@dataclass
class ReportResult:
    rows: list = field(default_factory=list)
    seconds: float = 0.0
    truth_hits: int = 0
    scenes: dict = field(default_factory=dict)        # scene -> the study's describe(scene)
    gl_renderer: str = ""
    files: list = field(default_factory=list)
    knobs: tuple = ()                                 # the families swept, when not all
    where: str = "in this process"                    # the executor's describe()


def run_report(scenes: list, out: Path, *, method: str = "raster", sweep_name: str = "standard",
               size=None, cache_dir=None, context_kind: str = "auto", sweep=None,
               knobs=None, address: str | None = None, workers: int | None = None) -> ReportResult:
    """Sweep `scenes` (Scene objects) with `method`'s study (study()), write results.csv,
    plots/ and report.md under `out`. `sweep_name`: quick, standard or exhaustive
    (report_settings.SWEEP_NAMES; `sweep`, if given, replaces its settings but not its
    size). `knobs`: the knob families to sweep (default all of the
    study's `knobs`; a setting's family is its knob up to a "-"). `address`, `workers`: the
    settings and the ground truths missing from the cache run on Ray (renderer/cluster/
    executor.py open_executor; report_units.py), else in this process; the cache is here."""
    from tqdm import tqdm

    from renderer.cluster.executor import open_executor
    from renderer.errors import UserError
    from renderer.gpu.context import make_context, release_context
    runner = study(method)
    result = ReportResult(knobs=tuple(knobs or ()))
    knobs = tuple(knobs or runner.knobs)
    unknown = [k for k in knobs if k not in runner.knobs]
    if unknown:
        raise UserError(f"{', '.join(unknown)}: no such knob for --method {method} (one of "
                        f"{', '.join(runner.knobs)})", key="--knobs")
    width, height = size or runner.size(sweep_name)
    runner.check(scenes, width, height)
    sweep = sweep or runner.sweep(sweep_name)
    cache_dir = Path(cache_dir) if cache_dir else default_cache_dir()
    start = time.perf_counter()
    # An --address nobody answers is one line before any work (open_executor checks it).
    with open_executor(address, workers, use_ray=address is not None or workers is not None) \
            as executor:
        result.where = executor.describe()
        ctx = make_context(context_kind)            # the plan's GL facts: the workers' must match
        try:
            result.gl_renderer = ctx.info["GL_RENDERER"]
            facts = gl_facts(ctx)
            plan = [s for s in runner.settings(sweep, ctx) if s.knob.split("-")[0] in knobs]
        finally:
            release_context(ctx)
        plans = [runner.scene_settings(plan, scene, width, height) for scene in scenes]
        result.scenes = {scene.name: runner.describe(scene) for scene in scenes}
        traced = [i for i, scene_plan in enumerate(plans) if runner.needs_truth(scene_plan)]
        truths = [None] * len(scenes)
        # The bar moves by estimated cost (report_units.py unit_cost, truth_cost), not by rows,
        # whose costs differ a thousandfold: its remaining time is then an estimate worth
        # reading. A truth already in the cache costs nothing.
        truth_costs = {scenes[i].name: truth_cost(runner.method, scenes[i]) for i in traced
                       if not cache_path(scenes[i], width, height, cache_dir, runner.method).is_file()}
        total = (sum(truth_costs.values())
                 + sweep.runs * sum(unit_cost(s) for plan in plans for s in plan))
        with tqdm(total=total, file=sys.stderr, mininterval=0.5, dynamic_ncols=True,
                  bar_format="{desc}{percentage:3.0f}%|{bar}| {elapsed} elapsed, about "
                             "{remaining} left") as bar:
            bar.set_description(f"ground truths (0 of {len(traced)} made)")
            made, shares = [], {}

            def truth_step(scene, share):        # inside a truth made here: minutes apiece
                cost = truth_costs.get(scene.name, 0.0)
                bar.update(cost * (share - shares.get(scene.name, 0.0)))
                shares[scene.name] = share
                bar.set_description(f"ground truths ({len(made)} of {len(traced)} made; "
                                    f"{scene.name} {share:.0%})")

            def truth_done(scene):
                truth_step(scene, 1.0)
                made.append(scene.name)
                bar.set_description(f"ground truths ({len(made)} of {len(traced)} made: {scene.name})")
            for i, (truth, hit) in zip(traced, ground_truths(
                    [scenes[i] for i in traced], width, height, cache_dir, runner.method,
                    tasks=None if executor.kind == "in-process" else executor.tasks, done=truth_done,
                    step=truth_step)):
                truths[i] = truth
                result.truth_hits += hit
            work = [SceneWork(i, scene, tuple(plans[i]), truths[i]) for i, scene in enumerate(scenes)]
            result.rows = run_units(executor, runner, work, sweep.runs, facts, (width, height),
                                    context_kind, bar)
    result.seconds = time.perf_counter() - start
    write_outputs(result, Path(out), runner, (width, height), sweep, sweep_name)
    return result


# ------------------------------------------------------------------------------- outputs

def write_outputs(result: ReportResult, out: Path, runner, size, sweep, sweep_name: str) -> None:
    plots = {}
    with outputs() as written:               # the whole report or none of it
        for scene in dict.fromkeys(row["scene"] for row in result.rows):
            for knob in dict.fromkeys(row["knob"] for row in result.rows if row["scene"] == scene):
                rows = [row for row in result.rows if row["scene"] == scene and row["knob"] == knob]
                plots[(scene, knob)] = f"plots/{scene}-{knob}.png"
                png = (output_report.output_plot_png(rows, f"{scene}: {knob}")
                       if knob == output_report.KNOB else
                       plot_png(rows, f"{scene}: {knob}", **plot_axis(knob)))
                written.bytes(out / plots[(scene, knob)], png)
        written.text(out / "results.csv", csv_text(result.rows, runner.columns))
        written.text(out / "report.md", runner.markdown(result, plots, size, sweep, sweep_name))
    result.files = ["report.md", "results.csv", *plots.values()]
