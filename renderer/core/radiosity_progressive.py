"""Radiosity solved a step at a time, for a viewer that shows it converging (issue 33; the
notes' progressive refinement, Cohen, Chen, Wallace and Greenberg, SIGGRAPH 1988): one
definition for the GPU path (renderer/gpu/radiosity.py RadiosityRenderer.progressive) and its
twin (renderer/methods/radiosity.py), which differ only in their item buffers.

    for progress in progressive_solution(old, elements, lighting, options, open_drawer):
        draw(progress.solution)            # what to show now; progress.line says where it is

The steps, each yielding a Progress whose solution the display draws as any other:
1. the lights' buffers (renderer/core/light_buffers.py): the direct light E + rho H, and the
   ambient term (radiosity_solve.ambient) standing in for every bounce yet to come;
2. the hemicubes, `hemicubes_per_step` at a time (form_factors.RowsDrawn), the picture as in 1
   (the form factors of the old solution kept where only the camera, the materials or the
   lights changed, radiosity.what_changed; none drawn where light cannot bounce,
   radiosity.interreflects: then the first step is the exact answer);
3. shooting (radiosity_solve.Shooter), `shots_per_step` at a time: B + rho ambient, the
   ambient term shrinking with the unshot power, until it is at most `tolerance` times the
   emitted power (or 100 shots an element): the last Progress is `done`, its solution the
   progressive solver's (the same shots as `--solver progressive`, to the viewer's tolerance).

Refinement (`options.refine`) is not made here: the viewer shows the scene's own elements.
"""

from __future__ import annotations

from dataclasses import dataclass
from typing import Iterator

import numpy as np

from renderer.core import memory
from renderer.core.form_factors import FormFactors, RowsDrawn
from renderer.core.radiosity import (Lighting, RadiositySolution, corner_values, direct_light, interreflects,
                                     solve, source_emission, what_changed)
from renderer.core.radiosity_elements import Elements
from renderer.core.radiosity_options import RadiosityOptions
from renderer.core.radiosity_solve import Shooter, Solution, ambient

# The viewer's: stop when the unshot power is this share of the emitted (invisible by then).
VIEW_TOLERANCE = 1e-5
HEMICUBES_PER_STEP = 64
SHOTS_PER_STEP_SHARE = 0.05        # of the element count, at least one


@dataclass
class Progress:
    solution: RadiositySolution        # what to show now
    phase: str                         # "lights", "hemicubes", "shooting" or "converged"
    line: str                          # where it is, in a few words
    done: bool = False


def _showing(elements: Elements, shown: np.ndarray, irradiance, lighting: Lighting, surfaces,
             matrix: FormFactors | None = None) -> RadiositySolution:
    """A solution to draw whose radiosity is `shown` (an estimate on the way)."""
    matrix = FormFactors.none(len(elements)) if matrix is None else matrix
    solution = RadiositySolution(elements, matrix, Solution(shown), corner_values(elements, shown),
                                 irradiance, lighting)
    solution.light_surfaces = surfaces
    return solution


def progressive_solution(old: RadiositySolution | None, elements: Elements, lighting: Lighting,
                         options: RadiosityOptions, open_drawer, backend: str, name: str, *,
                         hemicubes_per_step: int = HEMICUBES_PER_STEP, shots_per_step: int | None = None,
                         tolerance: float = VIEW_TOLERANCE) -> Iterator[Progress]:
    """The steps of the module docstring; `open_drawer` as radiosity.refreshed's."""
    change = what_changed(old, elements, lighting)
    if change == "nothing":
        yield Progress(old, "converged", "radiosity: converged", done=True)
        return
    h, surfaces = direct_light(old, change, elements, lighting, open_drawer, keep_surfaces=True)
    matrix = None if change == "geometry" else old.form_factors
    if not interreflects(elements, h, lighting.sky):
        solution = solve(elements, options, matrix, h, lighting)    # exact: no bounce to wait for
        solution.light_surfaces = surfaces
        yield Progress(solution, "converged", "radiosity: direct light only, exact", done=True)
        return
    rho = elements.reflectance
    direct = elements.emission if h is None else elements.emission + rho * h
    first_look = direct + rho * ambient(elements.areas, rho, direct)      # nothing shot yet
    yield Progress(_showing(elements, first_look, h, lighting, surfaces), "lights",
                   "radiosity: direct light, bounces by the ambient term")
    if matrix is None or not matrix.drawn:
        memory.check_radiosity(len(elements), options.hemicube, backend, name, direct=False)
        rows = RowsDrawn(len(elements), options.hemicube)
        with open_drawer(elements, options.hemicube, "hemicubes") as drawer:
            while rows.done < len(elements):
                rows.add(drawer.draw(rows.next_indices(min(drawer.batch, hemicubes_per_step))))
                yield Progress(_showing(elements, first_look, h, lighting, surfaces), "hemicubes",
                               f"radiosity: hemicubes {rows.done:,} of {len(elements):,}")
        matrix = rows.matrix()
    emission = source_emission(elements, h, matrix, lighting)
    shooter = Shooter(matrix, elements.areas, rho, emission, tolerance=tolerance)
    step = shots_per_step or max(1, int(SHOTS_PER_STEP_SHARE * len(elements)))
    limit = 100 * len(elements)
    while not shooter.shoot(min(step, limit - shooter.solution.iterations)):
        if shooter.solution.iterations >= limit:
            break
        yield Progress(_showing(elements, shooter.shown(), h, lighting, surfaces, matrix), "shooting",
                       f"radiosity: {shooter.solution.iterations:,} shots, "
                       f"unshot {shooter.unshot_fraction:.3%} of the light")
    final = RadiositySolution(elements, matrix, shooter.solution,
                              corner_values(elements, shooter.solution.radiosity), h, lighting, source=emission)
    final.light_surfaces = surfaces
    how = "converged" if shooter.solution.converged else "stopped (100 shots an element)"
    yield Progress(final, "converged", f"radiosity: {how} after {shooter.solution.iterations:,} shots",
                   done=True)
