"""Radiosity held against the path tracer, `renderer compare --radiosity-vs-pathtrace` (issue 33;
docs/pathtrace.md): two answers to one diffuse scene that share nothing but the scene.

The truth: TRUTH_FRAMES frames of TRUTH_SAMPLES jittered paths a pixel on the GPU path tracer
(each frame new paths, sample indices from TRUTH_FIRST), their mean linear colour. Radiosity at
three element sizes, each half the last (the given element size, or the scene's diagonal over
COARSEST_ACROSS), each display drawn at FOOTPRINT times the size and averaged over each pixel,
as the truth's paths cover it (a pixel-centre image would add its edges' aliasing to radiosity's
error). Per size: the elements, the seconds (form factors, solution and display), and the mean
and 95th percentile of |radiosity - truth| in 8-bit levels of the clamped colour, the largest
channel; the image: the finest size's difference as compare.heat_map draws it (white at 8
levels, magenta where more than IMAGE_LEVELS off with no neighbour within it).

    result = radiosity_vs_pathtrace(scene, 160, 120)
    result.rows, result.image(), result.line(), result.as_dict()
"""

from __future__ import annotations

import time
from dataclasses import dataclass, field

import numpy as np

FOOTPRINT = 4                  # radiosity's display at 4x the size, each 4 x 4 block averaged
TRUTH_SAMPLES = 256
TRUTH_FRAMES = 16              # 4096 paths a pixel
TRUTH_FIRST = 1 << 24          # the truth's sample indices (the rows' own never reach them)
COARSEST_ACROSS = 6            # without an element size: the diagonal over 6, 12, 24
LEVELS = 255.0
IMAGE_LEVELS = 8               # the image's magenta: beyond the ramp's white (the truth's noise
                               # alone puts many pixels 2 levels off)


def footprint_image(frame, width: int, height: int) -> np.ndarray:
    """(H, W, 3) float64: a frame drawn at FOOTPRINT times (width, height), each block's mean
    linear colour, clamped to [0, 1] (the mean, then the clamp, as the truth's)."""
    linear = frame.linear[..., :3].astype(np.float64)
    return np.clip(linear.reshape(height, FOOTPRINT, width, FOOTPRINT, 3).mean(axis=(1, 3)), 0.0, 1.0)


def path_traced(scene, size, options, frames: int, *, first: int = 0, context=None, progress=None):
    """(the mean linear colour (H, W, 3) float64 of `frames` path-traced frames with PathOptions
    `options`, each new paths (sample indices from `first` on), the seconds taken, the mean
    standard error of that mean from the frames' spread (nan for one frame)); on `context` (None:
    a new one); `progress(share done)` after each frame. The truth of this comparison, of the
    radiosity report (renderer/study/ground_truth.py) and of benchmarks/bench_pathtrace.py."""
    from renderer.methods import open_renderer
    start, each = time.perf_counter(), []
    with open_renderer(scene, size, method="pathtrace", options=options, context=context) as tracer:
        for k in range(frames):
            each.append(tracer.render(first_sample=first + k * options.samples).linear[..., :3].astype(np.float64))
            if progress is not None:
                progress((k + 1) / frames)
    error = float(np.std(each, axis=0, ddof=1).mean() / np.sqrt(frames)) if frames > 1 else float("nan")
    return np.mean(each, axis=0), time.perf_counter() - start, error


def _rgba8(image: np.ndarray) -> np.ndarray:
    from renderer.core.gl_rules import to_unorm8
    return to_unorm8(np.concatenate([image, np.ones(image.shape[:2] + (1,))], -1).astype(np.float32))


@dataclass
class RadiosityVsPathtrace:
    scene: str
    size: tuple
    truth_paths: int
    truth_seconds: float
    truth_standard_error: float
    rows: list = field(default_factory=list)     # per size: element_size, elements, seconds, mean, p95
    _truth: np.ndarray | None = None
    _finest: np.ndarray | None = None

    def as_dict(self) -> dict:
        return {"scene": self.scene, "size": list(self.size), "truth_paths": self.truth_paths,
                "truth_seconds": self.truth_seconds, "truth_standard_error": self.truth_standard_error,
                "rows": self.rows}

    def image(self) -> np.ndarray:
        from renderer.checks.compare import heat_map
        return heat_map(_rgba8(self._finest), _rgba8(self._truth), IMAGE_LEVELS, 1)

    def line(self) -> str:
        steps = ", ".join(f"{r['elements']:,} elements {r['mean_levels']:.2f}" for r in self.rows)
        return (f"radiosity against {self.truth_paths:,} paths a pixel (standard error "
                f"{self.truth_standard_error:.1e}): mean |difference| in levels {steps}")


def radiosity_vs_pathtrace(scene, width: int, height: int, element_size: float | None = None,
                           hemicube: int = 64, context_kind: str = "auto",
                           truth_frames: int = TRUTH_FRAMES) -> RadiosityVsPathtrace:
    """The comparison (module docstring) on a GL context of `context_kind`; `truth_frames` of
    TRUTH_SAMPLES paths (tests take fewer)."""
    from renderer.core.path_options import PathOptions
    from renderer.core.radiosity_options import RadiosityOptions
    from renderer.gpu.context import make_context, release_context
    from renderer.methods import open_renderer
    ctx = make_context(context_kind)
    try:
        mean, seconds, error = path_traced(scene, (width, height), PathOptions(samples=TRUTH_SAMPLES),
                                           truth_frames, first=TRUTH_FIRST, context=ctx)
        truth = np.clip(mean, 0.0, 1.0)
        result = RadiosityVsPathtrace(scene.name, (width, height), TRUTH_SAMPLES * truth_frames,
                                      seconds, error, _truth=truth)
        for step in range(3):                   # each element size half the last
            options = (RadiosityOptions(element_size=element_size / 2 ** step, hemicube=hemicube)
                       if element_size is not None else
                       RadiosityOptions(elements_across=COARSEST_ACROSS << step, hemicube=hemicube))
            start = time.perf_counter()
            with open_renderer(scene, (FOOTPRINT * width, FOOTPRINT * height), method="radiosity",
                               options=options, context=ctx) as radiosity:
                image = footprint_image(radiosity.render(linear=True), width, height)
                elements = len(radiosity.solution.elements)
            seconds = time.perf_counter() - start
            difference = np.abs(image - truth).max(axis=-1) * LEVELS
            result.rows.append({"element_size": options.element_size,
                                "elements_across": None if element_size is not None else options.elements_across,
                                "elements": elements, "seconds": seconds,
                                "mean_levels": float(difference.mean()),
                                "p95_levels": float(np.percentile(difference, 95))})
            result._finest = image
        return result
    finally:
        release_context(ctx)
