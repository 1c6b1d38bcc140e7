"""`renderer report --method raytrace`: the ray tracer's error against run time (issue 14).

Each scene is ray traced at a series of settings of three knobs, each setting on the GPU ray
tracer (renderer/gpu/raytracer.py) and the reference (reference/raytrace/pipeline.py) `runs`
times; the median time (timing.py) and the error of the image against the ray tracer's ground
truth (ground_truth.py: the reference in float64, 1024 jittered samples per pixel, depth
RAY_TRUTH_DEPTH) make one row of results.csv, with report.py's metrics.

    knob            settings                                            traced with
    antialiasing    regular / random / jittered / poisson at N          the truth's depth: the
                    samples per pixel; adaptive 4->N @T, a series       error is the sampling
                    per threshold T (in levels of 255)                  error alone
    max_depth       0 .. RAY_TRUTH_DEPTH bounces                        jittered, RAY_BASE_SAMPLES
    precision       float32, float64 (reference only)                   jittered, RAY_BASE_SAMPLES,
                                                                        the truth's depth
    light_samples, lens, time, glossy: the distributed effects' knobs, on the scenes that use
                    them (renderer/study/distributed_report.py)

A setting is one frame of the tracer: its N samples per pixel are looped in the shader (in the
reference, traced as one wavefront), so its time grows with the rays it traces, and the
adaptive pattern, which traces samples 5..N only where a pixel's first 4 disagree by more than
T (renderer/core/ray_sampling.py), can save time as well as samples; the report measures how
much. `samples` in results.csv is
the mean traced per pixel. Every setting builds its own RayTracer (the setting is compiled into
its shader); building it, and the scene's BVH, is not timed.
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np

from renderer.core.ray_options import RayOptions
from renderer.core.ray_sampling import FIRST_SET
from renderer.core.raytrace_scene import ray_scene
from renderer.core.sampling import DEFAULT_SEED, PATTERNS
from renderer.core.scene import Plane, Sphere
from renderer.study.distributed_report import (distributed_settings,
                                               settings_for_scene)
from renderer.study.metrics import metrics
from renderer.study.ground_truth import RAY_TRUTH_DEPTH, RAY_TRUTH_SAMPLES
from renderer.study.report_settings import (RAY_BASE_SAMPLES, RAY_CSV_COLUMNS, RAY_DEFAULT_SIZE,
                                            RAY_MAX_SIZE, RAY_QUICK_SIZE)
from renderer.study.supersample import clamped
from renderer.study.timing import median_timed

BACKENDS = ("gpu", "reference")


@dataclass(frozen=True)
class RaySweep:
    """Which settings a ray-tracing report traces."""
    sample_counts: tuple = (1, 4, 16, 64)            # per pattern; regular keeps the squares
    thresholds: tuple = (1, 4, 16)                   # adaptive, in levels of 255: a series each
    depths: tuple = (0, 1, 2, 3, 4, 8, 16, RAY_TRUTH_DEPTH)
    patterns: tuple = tuple(PATTERNS)
    light_counts: tuple = (1, 4, 16, 64)             # light samples per hit (light_samples)
    runs: int = 5                                    # as the rasteriser's: GPU times are noisy


RAY_EXHAUSTIVE = RaySweep()
RAY_STANDARD = RaySweep(sample_counts=(1, 4, 16), light_counts=(1, 4, 16), runs=3)   # the default
RAY_QUICK = RaySweep(sample_counts=(1, 4, 16), thresholds=(4,), depths=(0, 1, 4, RAY_TRUTH_DEPTH),
                     light_counts=(1, 4, 16))
RAY_SWEEPS = {"quick": RAY_QUICK, "standard": RAY_STANDARD, "exhaustive": RAY_EXHAUSTIVE}


@dataclass(frozen=True)
class RaySetting:
    """One row's recipe: the tracer's options, on which backend."""
    knob: str
    setting: str
    backend: str                     # "gpu" or "reference"
    pattern: str                     # a sampling pattern or "adaptive"
    samples: int                     # N; adaptive: the most a pixel gets
    max_depth: int
    threshold: float | None = None   # adaptive: the spread that refines a pixel
    dtype: str = "float32"           # the reference's (the GPU's is float32)
    light_samples: int = 1           # M per area light and hit

    def columns(self) -> dict:
        """The columns of results.csv that name this setting."""
        return {"knob": self.knob, "setting": self.setting, "backend": self.backend,
                "pattern": self.pattern, "light_samples": self.light_samples,
                "max_depth": self.max_depth, "threshold": self.threshold}

    def options(self) -> RayOptions:
        """The ray tracer's options (either backend)."""
        return RayOptions(samples=self.samples, pattern=self.pattern, max_depth=self.max_depth,
                          seed=DEFAULT_SEED, adaptive_threshold=self.threshold,
                          light_samples=self.light_samples)


def ray_settings(sweep: RaySweep) -> list[RaySetting]:
    """Every setting of every knob, each backend it runs on."""
    out = []
    for name in sweep.patterns:
        for n in sweep.sample_counts:
            if name != "regular" or math.isqrt(n) ** 2 == n:
                out += [RaySetting("antialiasing", f"{name} {n}", b, name, n, RAY_TRUTH_DEPTH)
                        for b in BACKENDS]
    for levels in sweep.thresholds:
        for n in (n for n in sweep.sample_counts if n >= FIRST_SET):
            out += [RaySetting("antialiasing", f"adaptive {FIRST_SET}->{n} @{levels:g}/255", b,
                               "adaptive", n, RAY_TRUTH_DEPTH, levels / 255.0) for b in BACKENDS]
    for depth in sweep.depths:
        out += [RaySetting("max_depth", f"depth {depth}", b, "jittered", RAY_BASE_SAMPLES, depth)
                for b in BACKENDS]
    out += [RaySetting("precision", dtype, "reference", "jittered", RAY_BASE_SAMPLES,
                       RAY_TRUTH_DEPTH, dtype=dtype) for dtype in ("float32", "float64")]
    return out + distributed_settings(RaySetting, sweep, RAY_TRUTH_DEPTH)


class RaySceneRun:
    """Traces one scene's settings; the scene's surfaces and BVH (ray_scene) are made once
    for the reference, each GPU setting's RayTracer once for its runs."""

    def __init__(self, scene, width: int, height: int, ctx):
        self.scene, self.width, self.height, self.ctx = scene, width, height, ctx
        self.rs = ray_scene(scene)

    def timed(self, setting: RaySetting, runs: int) -> tuple[np.ndarray, float, float]:
        """(image (H, W, 3) float64 in [0, 1], mean samples traced per pixel, median ms)."""
        from renderer.methods import open_renderer
        with open_renderer(self.scene, (self.width, self.height), method="raytrace",
                           backend=setting.backend, options=setting.options(), context=self.ctx,
                           precision=setting.dtype) as tracer:
            if setting.backend == "reference":
                tracer.ray_scene = self.rs             # the scene's BVH, made once for every setting
            # the GPU's first frame compiles; the reference's has nothing to warm
            frame, ms = median_timed(tracer.render, runs, warm_up=setting.backend == "gpu")
        return clamped(frame.linear[..., :3]), float(frame.samples.mean()), ms

    def errors(self, setting: RaySetting, image: np.ndarray, truth: np.ndarray) -> dict:
        return metrics(image, truth)

    def release(self) -> None:
        """Nothing to free: each RayTracer is released after its setting."""


class RayStudy:
    """The ray tracer's sweep (module docstring), as report.py's run_report drives it."""
    method = "raytrace"
    columns = RAY_CSV_COLUMNS
    knobs = ("antialiasing", "max_depth", "precision", "light_samples", "lens", "time", "glossy")

    def sweep(self, name: str) -> RaySweep:
        """The sweep called `name` (report_settings.SWEEP_NAMES)."""
        return RAY_SWEEPS[name]

    def size(self, name: str) -> tuple[int, int]:
        return RAY_QUICK_SIZE if name == "quick" else RAY_DEFAULT_SIZE

    def check(self, scenes: list, width: int, height: int) -> None:
        """A UserError, before any work: an image over RAY_MAX_SIZE, or a ground truth frame
        (float64: twice the float32 estimate) over the memory limit."""
        from renderer.core import memory
        from renderer.errors import UserError
        if width * height > math.prod(RAY_MAX_SIZE):
            raise UserError(f"{width}x{height} is too large for the ray tracer's ground truth "
                            f"({RAY_TRUTH_SAMPLES} samples per pixel per frame, at most "
                            f"{RAY_MAX_SIZE[0]}x{RAY_MAX_SIZE[1]} pixels)", key="--size")
        for scene in scenes:
            triangles = self.describe(scene)[2]
            memory.check(2 * memory.raytrace_reference_bytes(width, height, triangles,
                                                             samples=RAY_TRUTH_SAMPLES),
                         f"the ray-traced ground truth of {scene.name} at {width}x{height}")

    def settings(self, sweep: RaySweep, ctx) -> list[RaySetting]:
        return ray_settings(sweep)

    def scene_settings(self, plan: list[RaySetting], scene, width: int, height: int) -> list[RaySetting]:
        """Each distributed knob only where the scene uses its effect (distributed_report.py)."""
        return settings_for_scene(plan, scene)

    def needs_truth(self, plan: list[RaySetting]) -> bool:
        return bool(plan)

    def describe(self, scene) -> tuple:
        """The Scenes table's cells: spheres, planes, triangles, whether some material reflects
        or refracts (k_r or k_t > 0)."""
        shapes = [type(obj.shape) for obj in scene.objects]
        secondary = any(max(obj.material.kr + obj.material.kt) > 0 for obj in scene.objects)   # tuples
        return (shapes.count(Sphere), shapes.count(Plane),
                sum(obj.mesh.triangle_count for obj in scene.objects if obj.shape is None),
                "yes" if secondary else "no")

    def scene_run(self, scene, width: int, height: int, ctx) -> RaySceneRun:
        return RaySceneRun(scene, width, height, ctx)

    def markdown(self, result, plots: dict, size, sweep: RaySweep, name: str) -> str:
        from renderer.study.ray_report_output import ray_report_markdown
        return ray_report_markdown(result, plots, size, sweep, name)
