"""`renderer report --method radiosity`: radiosity's error against run time (issue 33), against
a truth it shares nothing with but the scene: the path tracer's (renderer/study/ground_truth.py,
docs/pathtrace.md).

    knob            settings                                        the others at
    element_size    the scene's diagonal over 3, 6, 12, 24           hemicubes of 64, Gauss-Seidel
                    (elements_across; 12 is the default)             to the default tolerance
    hemicube        16, 32, 64, 128, 256 pixels across its top       the default elements
    iterations      Gauss-Seidel sweeps 1, 2, 4, 8, and to the       the default elements,
                    default tolerance (1e-6)                         hemicubes of 64

Each run times a setting from nothing: a new renderer (its elements, hemicubes, solution and
display), as a user's first frame, so the element size's time is its form factors' O(E^2). The
display is drawn at FOOTPRINT times the size and box-filtered (FOOTPRINT^2 samples a pixel, as
the truth's jittered paths cover the pixel): what is measured is radiosity's error, not the
aliasing of a pixel-centre image against a pixel's mean. The
GPU runs every setting; the twin (reference/radiosity/, whose hemicubes are O(E^2) NumPy) only
the element sizes of at most TWIN_ACROSS across. `samples` in results.csv is the elements (one
hemicube each). The errors are report.py's metrics of the clamped image against the truth.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from renderer.core.radiosity import elements_for
from renderer.core.radiosity_options import DEFAULT_ELEMENTS_ACROSS, RadiosityOptions
from renderer.study.metrics import metrics
from renderer.checks.radiosity_vs_pathtrace import FOOTPRINT, footprint_image
from renderer.study.report_settings import (RADIOSITY_CSV_COLUMNS, RADIOSITY_DEFAULT_SIZE, RADIOSITY_MAX_SIZE,
                                            RADIOSITY_QUICK_SIZE, TWIN_ACROSS)
from renderer.study.timing import median_timed





@dataclass(frozen=True)
class RadiositySweep:
    """Which settings a radiosity report draws."""
    across: tuple = (3, 6, 12, 24)                   # elements across the scene's diagonal
    hemicubes: tuple = (16, 32, 64, 128, 256)
    sweeps: tuple = (1, 2, 4, 8, None)               # Gauss-Seidel's; None: to the tolerance
    runs: int = 3


RADIOSITY_STANDARD = RadiositySweep()
RADIOSITY_SWEEPS = {"quick": RadiositySweep(across=(3, 6, 12), hemicubes=(16, 64), sweeps=(1, 4, None)),
                    "standard": RADIOSITY_STANDARD,
                    "exhaustive": RadiositySweep(across=(3, 6, 12, 24, 48), hemicubes=(16, 32, 64, 128, 256, 512),
                                                 sweeps=(1, 2, 4, 8, 16, None), runs=5)}


@dataclass(frozen=True)
class RadiositySetting:
    """One row's recipe: radiosity's options, on which backend."""
    knob: str
    setting: str
    backend: str
    across: int = DEFAULT_ELEMENTS_ACROSS
    hemicube: int = 64
    sweeps: int | None = None

    def columns(self) -> dict:
        return {"knob": self.knob, "setting": self.setting, "backend": self.backend,
                "elements_across": self.across, "hemicube": self.hemicube,
                "iterations": "" if self.sweeps is None else self.sweeps}

    def options(self) -> RadiosityOptions:
        return RadiosityOptions(elements_across=self.across, hemicube=self.hemicube,
                                max_iterations=self.sweeps)

    @property
    def cost(self) -> float:
        """A rough relative cost (report_units.unit_cost): hemicubes times elements, each hemicube
        drawn over its pixels; the twin's weighted as the other studies' reference."""
        elements = self.across ** 2
        return (30.0 if self.backend == "reference" else 1.0) * elements * (elements + self.hemicube ** 2 / 64)


def radiosity_settings(sweep: RadiositySweep) -> list[RadiositySetting]:
    out = []
    for across in sweep.across:
        backends = ("gpu", "reference") if across <= TWIN_ACROSS else ("gpu",)
        out += [RadiositySetting("element_size", f"diagonal / {across}", b, across=across) for b in backends]
    out += [RadiositySetting("hemicube", f"{n} px", "gpu", hemicube=n) for n in sweep.hemicubes]
    out += [RadiositySetting("iterations", "converged" if k is None else f"{k} sweep{'s' * (k > 1)}",
                             "gpu", sweeps=k) for k in sweep.sweeps]
    return out


class RadiositySceneRun:
    """Draws one scene's settings, a new renderer per run (module docstring)."""

    def __init__(self, scene, width: int, height: int, ctx):
        self.scene, self.width, self.height, self.ctx = scene, width, height, ctx

    def timed(self, setting: RadiositySetting, runs: int) -> tuple[np.ndarray, float, float]:
        """(image (H, W, 3) float64 in [0, 1], elements, median ms of a renderer made and drawn)."""
        from renderer.methods import open_renderer

        def drawn():
            with open_renderer(self.scene, (FOOTPRINT * self.width, FOOTPRINT * self.height),
                               method="radiosity", backend=setting.backend, options=setting.options(),
                               context=self.ctx) as renderer:
                image = footprint_image(renderer.render(linear=True), self.width, self.height)
                return image, len(renderer.solution.elements)
        # the GPU's first compiles its programs; the twin has nothing to warm
        (image, elements), ms = median_timed(drawn, runs, warm_up=setting.backend == "gpu")
        return image, float(elements), ms

    def errors(self, setting, image: np.ndarray, truth: np.ndarray) -> dict:
        return metrics(image, truth)

    def release(self) -> None:
        """Nothing to free: each renderer is released after its run."""


class RadiosityStudy:
    """Radiosity's sweep (module docstring), as report.py's run_report drives it."""
    method = "radiosity"
    columns = RADIOSITY_CSV_COLUMNS
    knobs = ("element_size", "hemicube", "iterations")

    def sweep(self, name: str) -> RadiositySweep:
        return RADIOSITY_SWEEPS[name]

    def size(self, name: str) -> tuple[int, int]:
        return RADIOSITY_QUICK_SIZE if name == "quick" else RADIOSITY_DEFAULT_SIZE

    def check(self, scenes: list, width: int, height: int) -> None:
        """A UserError, before any work: an image over RADIOSITY_MAX_SIZE (its path-traced truth
        draws 4096 paths a pixel)."""
        from renderer.errors import UserError
        if width * height > RADIOSITY_MAX_SIZE[0] * RADIOSITY_MAX_SIZE[1]:
            raise UserError(f"{width}x{height} is too large for radiosity's path-traced truth (at "
                            f"most {RADIOSITY_MAX_SIZE[0]}x{RADIOSITY_MAX_SIZE[1]} pixels)", key="--size")

    def settings(self, sweep: RadiositySweep, ctx) -> list[RadiositySetting]:
        return radiosity_settings(sweep)

    def scene_settings(self, plan: list, scene, width: int, height: int) -> list:
        return plan

    def needs_truth(self, plan: list) -> bool:
        return bool(plan)

    def describe(self, scene) -> tuple:
        """The Scenes table's cells: triangles, emitting objects, the default elements."""
        emitting = sum(any(e > 0 for e in obj.material.emission) for obj in scene.objects)
        return (sum(obj.mesh.triangle_count for obj in scene.objects), emitting,
                len(elements_for(scene, RadiosityOptions())))

    def scene_run(self, scene, width: int, height: int, ctx) -> RadiositySceneRun:
        return RadiositySceneRun(scene, width, height, ctx)

    def markdown(self, result, plots: dict, size, sweep: RadiositySweep, name: str) -> str:
        from renderer.study.radiosity_report_output import radiosity_report_markdown
        return radiosity_report_markdown(result, plots, size, sweep, name)
