"""Radiosity's options (issue 33; renderer/methods/radiosity.py): how finely the surfaces are cut,
how finely each hemicube sees, and how the equation is solved. Every range is checked here, once,
as an OptionError naming the field."""

from __future__ import annotations

import dataclasses
import math
from dataclasses import dataclass, fields
from typing import ClassVar

from renderer.errors import OptionError

SOLVERS = ("gauss-seidel", "progressive", "direct")
MAX_HEMICUBE = 1024
MAX_LIGHT_BUFFER = 2048
MAX_AREA_SAMPLES = 16
MAX_REFINE = 6
# Without an element size the scene's bounding box's diagonal is cut in this many.
DEFAULT_ELEMENTS_ACROSS = 12


@dataclass(frozen=True)
class RadiosityOptions:
    """`element_size`: the longest edge of an element, scene units (None: the scene's diagonal
    over DEFAULT_ELEMENTS_ACROSS); `hemicube`: pixels across a hemicube's top face, a power of
    two from 4 to MAX_HEMICUBE (so that GL's viewport scale N / 2 is exact: the twin's window
    coordinates are GL's bit for bit); `solver`: one of SOLVERS; `tolerance`: the residual to
    reach, relative to the largest emission (Gauss-Seidel) or the emitted power (progressive);
    `max_iterations`: sweeps or shots (None: the solver's default); `elements_across`: without an
    element size, the scene's diagonal over this many (the report's element-size knob);
    `light_buffer`: pixels across each view a light sees the elements through (a point light's
    cube face, a directional light's square; renderer/core/light_buffers.py), a power of two
    from 4 to MAX_LIGHT_BUFFER; `area_samples`: k, an area light seen from k x k points;
    `refine`: times the elements where radiosity changes fast are cut in four, 0 to MAX_REFINE
    (renderer/core/radiosity.py needs_refining), those whose Gouraud display differs from their
    own radiosity by more than `refine_threshold` levels of 255."""
    element_size: float | None = None
    hemicube: int = 64
    solver: str = "gauss-seidel"
    tolerance: float = 1e-6
    max_iterations: int | None = None
    elements_across: int = DEFAULT_ELEMENTS_ACROSS
    light_buffer: int = 512
    area_samples: int = 4
    refine: int = 0
    refine_threshold: float = 4.0
    SETTING_FIELDS: ClassVar[tuple[str, ...]] = ("element_size", "hemicube", "solver", "light_buffer", "refine")

    def __post_init__(self):
        size = self.element_size
        if size is not None and not (isinstance(size, (int, float)) and math.isfinite(size) and size > 0):
            raise OptionError("element_size", f"must be a number > 0 (scene units), got {size!r}")
        n = self.hemicube
        if not (isinstance(n, int) and 4 <= n <= MAX_HEMICUBE and n & (n - 1) == 0):
            raise OptionError("hemicube", f"must be a power of two from 4 to {MAX_HEMICUBE}, got {n!r}")
        if self.solver not in SOLVERS:
            raise OptionError("solver", f"unknown solver {self.solver!r}; one of {', '.join(SOLVERS)}")
        if not (isinstance(self.tolerance, (int, float)) and 0 < self.tolerance < 1):
            raise OptionError("tolerance", f"must be a number between 0 and 1, got {self.tolerance!r}")
        m = self.max_iterations
        if m is not None and not (isinstance(m, int) and m >= 1):
            raise OptionError("max_iterations", f"must be an integer >= 1, got {m!r}")
        a = self.elements_across
        if isinstance(a, bool) or not (isinstance(a, int) and a >= 1):
            raise OptionError("elements_across", f"must be an integer >= 1, got {a!r}")
        n = self.light_buffer
        if isinstance(n, bool) or not (isinstance(n, int) and 4 <= n <= MAX_LIGHT_BUFFER and n & (n - 1) == 0):
            raise OptionError("light_buffer", f"must be a power of two from 4 to {MAX_LIGHT_BUFFER}, got {n!r}")
        k = self.area_samples
        if isinstance(k, bool) or not (isinstance(k, int) and 1 <= k <= MAX_AREA_SAMPLES):
            raise OptionError("area_samples", f"must be an integer from 1 to {MAX_AREA_SAMPLES}, got {k!r}")
        r = self.refine
        if isinstance(r, bool) or not (isinstance(r, int) and 0 <= r <= MAX_REFINE):
            raise OptionError("refine", f"must be an integer from 0 to {MAX_REFINE}, got {r!r}")
        t = self.refine_threshold
        if isinstance(t, bool) or not (isinstance(t, (int, float)) and math.isfinite(t) and t > 0):
            raise OptionError("refine_threshold", f"must be a number > 0 (levels of 255), got {t!r}")

    def size_for(self, diameter: float) -> float:
        """The element size for a scene whose bounding box's diagonal is `diameter`."""
        return self.element_size if self.element_size is not None else diameter / self.elements_across

    def scene_for(self, scene):
        """The scene as radiosity draws it: as given (a pinhole camera, as the rasteriser's); a
        physical one in exitance units (renderer/core/physical.py)."""
        from renderer.core.physical import for_method
        return for_method(scene, "radiosity")

    def replace(self, **changes) -> "RadiosityOptions":
        return dataclasses.replace(self, **changes)

    def as_dict(self) -> dict:
        return {f.name: getattr(self, f.name) for f in fields(self)}
