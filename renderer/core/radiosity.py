"""Radiosity's plan for a scene (issue 33), shared by the GPU path (renderer/methods/radiosity.py,
renderer/gpu/item_buffers.py) and its twin (reference/radiosity/): what a radiosity frame is
drawn from, step by step.

1. Elements: every object's surface cut into triangles of at most the options' element size
   (renderer/core/radiosity_elements.py), each with its material's reflectance rho = k_d and
   emitted radiosity E = `emission` (exitance, linear RGB, shown as is).
2. Form factors: each element's hemicube drawn (the GPU's item buffers or the twin's, the one
   `draw` given) and summed (renderer/core/form_factors.py).
3. The solution B = E + rho F B (renderer/core/radiosity_solve.py, the options' solver).
4. The display: Gouraud interpolation as in the notes: each element corner's value is the
   area-weighted mean of B over the elements of the same object meeting at that point (so a
   surface shades smoothly, and a crease between two objects stays sharp); the display pass
   (glsl/radiosity/display.*, twin reference/radiosity/display.py) interpolates them across
   each element.

What a radiosity frame shows is B: the scene's point and directional lights and its ambient
term take no part (the light comes from emitting surfaces), nor do specular, mirror and glass
terms (docs/radiosity.md).
"""

from __future__ import annotations

from dataclasses import dataclass
from typing import Callable

import numpy as np

from renderer.core import memory
from renderer.core.form_factors import FormFactors, form_factors
from renderer.core.meshio import DEFAULT_CREASE_ANGLE
from renderer.core.radiosity_elements import Elements, scene_elements
from renderer.core.radiosity_options import RadiosityOptions
from renderer.core.radiosity_solve import Solution, direct, gauss_seidel, progressive

# Element corners closer than this fraction of the scene's diagonal are one point of the
# display's mesh (corners of neighbouring source triangles are computed apart and may differ
# in their last bits).
WELD_FRACTION = 1e-9
# Elements meeting at a corner are averaged there only if their normals are within this angle:
# the crease angle mesh files' normals are made with (renderer/core/meshio.py).
CREASE_DEGREES = DEFAULT_CREASE_ANGLE
CREASE_COSINE = float(np.cos(np.radians(CREASE_DEGREES)))


@dataclass
class RadiositySolution:
    elements: Elements
    form_factors: FormFactors
    solution: Solution
    corner_radiosity: np.ndarray        # (E, 3, C): each element corner's displayed value


def elements_for(scene, options: RadiosityOptions) -> Elements:
    """The scene's elements at the options' size, with the materials' k_d and emission."""
    emission = np.array([o.material.emission for o in scene.objects], np.float64).reshape(-1, 3)
    return scene_elements(scene, options.size_for, emission=emission)


def interreflects(elements: Elements) -> bool:
    """Whether light bounces at all: some element emits and some element reflects. When not,
    B = E exactly (the light reaching a surface that reflects nothing, or no light at all), and
    no hemicube is drawn (the rule of leaving out what a scene does not need)."""
    return bool((elements.emission > 0).any() and (elements.reflectance > 0).any())


def what_changed(old: RadiositySolution | None, elements: Elements) -> str:
    """What a new scene's `elements` need, given the solution `old` was made for: "nothing"
    (only the camera moved: the solution stands), "materials" (the same triangles with other
    reflectances or emissions: solve again with the same form factors) or "geometry" (draw the
    hemicubes again)."""
    if old is None or not (np.array_equal(old.elements.corners, elements.corners)
                           and np.array_equal(old.elements.obj, elements.obj)):
        return "geometry"
    if not old.form_factors.drawn and interreflects(elements):
        return "geometry"                     # light bounces now: the hemicubes are needed
    if (np.array_equal(old.elements.reflectance, elements.reflectance)
            and np.array_equal(old.elements.emission, elements.emission)):
        return "nothing"
    return "materials"


def refreshed(old: RadiositySolution | None, elements: Elements, options: RadiosityOptions,
              open_drawer, backend: str, name: str) -> RadiositySolution | None:
    """The solution for a scene's new `elements`, or None where `old` stands (what_changed):
    the same form factors for new materials; B = E without a hemicube where light cannot bounce;
    else the memory checked (memory.check_radiosity) and the hemicubes drawn by
    `open_drawer(elements)`, a context manager giving (draw, batch): the GPU's item buffers or
    the twin's. One rule for both backends."""
    change = what_changed(old, elements)
    if change == "nothing":
        return None
    if change == "materials":
        return solve(elements, options, matrix=old.form_factors)
    if not interreflects(elements):
        return solve(elements, options)
    memory.check_radiosity(len(elements), options.hemicube, backend, name,
                           direct=options.solver == "direct")
    with open_drawer(elements) as (draw, batch):
        return solve(elements, options, draw, batch)


def solve(elements: Elements, options: RadiosityOptions, draw: Callable[[np.ndarray], np.ndarray] | None = None,
          batch: int = 1, matrix: FormFactors | None = None) -> RadiositySolution:
    """Form factors from `draw` (item buffers of the given elements' hemicubes, `batch` at a
    time; or `matrix`, those of the same elements kept from before), the options' solver, the
    corners' display values."""
    if matrix is None:
        matrix = (form_factors(len(elements), options.hemicube, draw, batch) if interreflects(elements)
                  else FormFactors.none(len(elements)))
    limit = {} if options.max_iterations is None else (
        {"max_sweeps": options.max_iterations} if options.solver == "gauss-seidel"
        else {"max_shots": options.max_iterations})
    if options.solver == "gauss-seidel":
        solution = gauss_seidel(matrix, elements.reflectance, elements.emission,
                                tolerance=options.tolerance, **limit)
    elif options.solver == "direct":
        solution = direct(matrix, elements.reflectance, elements.emission)
    else:
        solution = progressive(matrix, elements.areas, elements.reflectance, elements.emission,
                               tolerance=options.tolerance, **limit)
    return RadiositySolution(elements, matrix, solution, corner_values(elements, solution.radiosity))


def corner_values(elements: Elements, radiosity: np.ndarray) -> np.ndarray:
    """(E, 3, C): at each element corner, the area-weighted mean radiosity of the elements of
    its object that meet there on the same side of a crease: those whose normals are within
    CREASE_DEGREES of this element's (corners welded within WELD_FRACTION of the elements'
    extent). A box's faces keep their own shading; a tessellated sphere's is smooth."""
    count = len(elements)
    if count == 0:
        return np.zeros((0, 3, radiosity.shape[1]))
    _, diameter = elements.extent()
    step = max(diameter, np.finfo(float).tiny) * WELD_FRACTION
    snapped = np.round(elements.corners.reshape(-1, 3) / step).astype(np.int64)
    keys = np.concatenate([np.repeat(elements.obj, 3)[:, None], snapped], axis=1)
    _, point = np.unique(keys, axis=0, return_inverse=True)
    point = point.ravel()
    # every pair (corner, corner) at one point, the pairs across a crease left out
    order = np.argsort(point, kind="stable")
    starts = np.flatnonzero(np.r_[True, np.diff(point[order]) != 0])
    sizes = np.diff(np.r_[starts, len(order)])
    size_of = np.repeat(sizes, sizes)                 # per sorted corner: its point's corner count
    start_of = np.repeat(starts, sizes)
    first = np.repeat(order, size_of)                 # corner c, once per corner m at its point
    offsets = np.arange(len(first)) - np.repeat(np.cumsum(size_of) - size_of, size_of)
    second = order[np.repeat(start_of, size_of) + offsets]
    element = np.arange(count * 3) // 3
    normals = elements.normals
    same_side = (normals[element[first]] * normals[element[second]]).sum(axis=1) >= CREASE_COSINE
    first, second = first[same_side], second[same_side]
    weight = elements.areas[element[second]]
    totals = np.zeros((count * 3, radiosity.shape[1]))
    np.add.at(totals, first, weight[:, None] * radiosity[element[second]])
    return (totals / np.bincount(first, weights=weight, minlength=count * 3)[:, None]).reshape(count, 3, -1)
