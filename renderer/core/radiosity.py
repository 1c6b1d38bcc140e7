"""Radiosity's plan for a scene (issue 33), shared by the GPU path (renderer/methods/radiosity.py,
renderer/gpu/item_buffers.py) and its twin (reference/radiosity/): what a radiosity frame is
drawn from, step by step.

1. Elements: every object's surface cut into triangles of at most the options' element size
   (renderer/core/radiosity_elements.py), each with its material's reflectance rho = k_d and
   emitted radiosity E = `emission` (exitance, linear RGB, shown as is).
2. Direct light: the scene's point and directional lights' mean irradiance H on each element,
   from item buffers drawn at the lights (renderer/core/light_buffers.py), shadows included.
3. Form factors: each element's hemicube drawn (the GPU's item buffers or the twin's, the one
   `open_drawer` gives) and summed (renderer/core/form_factors.py).
4. The solution B = E + rho (H + F B) (renderer/core/radiosity_solve.py, the options' solver).
5. The display: Gouraud interpolation as in the notes: each element corner's value is the
   area-weighted mean of B over the elements of the same object meeting at that point (so a
   surface shades smoothly, and a crease between two objects stays sharp); the display pass
   (glsl/radiosity/display.*, twin reference/radiosity/display.py) interpolates them across
   each element.

What a radiosity frame shows is B, plus the direct specular term where a material has one (the
lighting equation's k_s term of each light-buffer source, shadowed by what that source's light
buffer saw: Lighting.specular, RadiositySolution.light_surfaces; glsl/radiosity/specular.glsl):
the scene's ambient term takes no part (interreflection is what it stands for), nor do mirror
and glass terms, nor light that reaches the eye by a specular bounce from another surface
(docs/radiosity.md).
"""

from __future__ import annotations

import dataclasses
from dataclasses import dataclass, field
from functools import cached_property

import numpy as np

from renderer.core import light_buffers, memory
from renderer.core.form_factors import FormFactors, form_factors
from renderer.core.meshio import DEFAULT_CREASE_ANGLE
from renderer.core.radiosity_elements import Elements, refined, scene_elements
from renderer.core.radiosity_options import MAX_LIGHT_BUFFER, RadiosityOptions
from renderer.core.radiosity_solve import Solution, direct, gauss_seidel, progressive

# Element corners closer than this fraction of the scene's diagonal are one point of the
# display's mesh (corners of neighbouring source triangles are computed apart and may differ
# in their last bits).
WELD_FRACTION = 1e-9
# Elements meeting at a corner are averaged there only if their normals are within this angle:
# the crease angle mesh files' normals are made with (renderer/core/meshio.py).
CREASE_DEGREES = DEFAULT_CREASE_ANGLE
CREASE_COSINE = float(np.cos(np.radians(CREASE_DEGREES)))


@dataclass(frozen=True)
class Lighting:
    """What lights a radiosity solution besides its emitting surfaces (lighting_for): the
    lights' sources (renderer/core/light_buffers.py) with the light buffer's resolution, and
    the sky: the scene's background, a uniform surround whose light reaches an element through
    what its hemicube sees of nothing (FormFactors.unseen), as a path that leaves the scene
    brings the background back in the path tracer. `specular`: some object has a specular term
    and some source lights it, so the display adds the direct specular term, shadowed by the
    sources' light buffers (kept: RadiositySolution.light_surfaces)."""
    sources: tuple = ()
    resolution: int = 0
    sky: tuple = (0.0, 0.0, 0.0)
    specular: bool = False

    def finer(self, level: int) -> "Lighting":
        """The light buffer 2^level times as fine (at most MAX_LIGHT_BUFFER): refinement's."""
        return dataclasses.replace(self, resolution=min(MAX_LIGHT_BUFFER, self.resolution << level))


@dataclass
class RadiositySolution:
    elements: Elements
    form_factors: FormFactors
    solution: Solution
    corner_radiosity: np.ndarray        # (E, 3, C): each element corner's displayed value
    irradiance: np.ndarray | None = None   # (E, 3): the lights' direct H (None: no light drawn)
    lighting: Lighting = field(default_factory=lambda: Lighting())   # what it was lit by
    base: Elements | None = None        # the scene's elements before refinement (None: `elements`)
    levels: int = 0                     # the refinements made (options.refine at most)
    source: np.ndarray | None = None    # (E, 3) what the solver took as emission: E + rho (H + S)
    # what the lights' buffers saw at lighting.resolution, for the specular term's shadows
    # (None: the scene has no specular term to shadow, Lighting.specular)
    light_surfaces: light_buffers.LightSurfaces | None = None

    @property
    def unrefined(self) -> Elements:
        return self.elements if self.base is None else self.base

    @cached_property
    def corner_normals(self) -> np.ndarray:
        """(E, 3, 3): each corner's normal for the specular term, the crease-angle mean of its
        elements' as its radiosity is (corner_values); once per solution, not per frame."""
        return corner_values(self.elements, self.elements.normals)


def elements_for(scene, options: RadiosityOptions) -> Elements:
    """The scene's elements at the options' size, with the materials' k_d and emission."""
    emission = np.array([o.material.emission for o in scene.objects], np.float64).reshape(-1, 3)
    return scene_elements(scene, options.size_for, emission=emission)


def lighting_for(scene, options: RadiosityOptions) -> Lighting:
    """The scene's Lighting: its lights' sources at the options' light buffer, its sky."""
    sources = light_buffers.light_sources(scene, options.area_samples)
    return Lighting(sources, options.light_buffer if sources else 0,
                    tuple(float(c) for c in scene.background[:3]),
                    specular=bool(sources) and any(o.material.has_specular for o in scene.objects))


def interreflects(elements: Elements, irradiance: np.ndarray | None = None, sky=(0.0, 0.0, 0.0)) -> bool:
    """Whether the hemicubes are needed: some element reflects, elements can see each other
    (not one convex solid seen from outside: Elements.see_each_other), and light comes from
    somewhere (an element emits or reflects some of the lights' irradiance, or the sky shines).
    When not, B = E + rho (H + sky) exactly (a convex solid's hemicubes see nothing but sky) or
    B = E + rho H, and no hemicube is drawn (the rule of leaving out what a scene does not need)."""
    sends = (elements.emission > 0).any() or (
        irradiance is not None and (elements.reflectance * irradiance > 0).any()) or any(c > 0 for c in sky)
    return bool(sends and (elements.reflectance > 0).any() and elements.see_each_other)


def what_changed(old: RadiositySolution | None, elements: Elements, lighting: Lighting = Lighting()) -> str:
    """What a new scene's `elements` and `lighting` (lighting_for) need, given the solution `old`
    was made for: "nothing" (only the camera moved: the solution stands), "materials" (the same
    triangles and lights with other reflectances, emissions or sky: solve again with the same
    form factors and irradiance), "lights" (draw the lights' buffers again, keep the form
    factors) or "geometry" (draw everything again)."""
    if old is None:
        return "geometry"
    change = change_between(old.unrefined, old.lighting, elements, lighting)
    if change in ("materials", "nothing") and not old.form_factors.drawn \
            and interreflects(elements, old.irradiance, lighting.sky):
        return "geometry"                     # light bounces now: the hemicubes are needed
    return change


def change_between(before: Elements, lighting_before: Lighting, elements: Elements, lighting: Lighting) -> str:
    """"geometry", "lights", "materials" or "nothing": what differs between two radiosity
    problems, their elements and lighting alone (what_changed adds what a solution drew)."""
    if not (np.array_equal(before.corners, elements.corners) and np.array_equal(before.obj, elements.obj)):
        return "geometry"
    if (lighting_before.sources, lighting_before.resolution, lighting_before.specular) != (
            lighting.sources, lighting.resolution, lighting.specular):
        return "lights"
    if (np.array_equal(before.reflectance, elements.reflectance)
            and np.array_equal(before.emission, elements.emission) and lighting_before.sky == lighting.sky):
        return "nothing"
    return "materials"


def direct_light(old, change: str, elements: Elements, lighting: Lighting, open_drawer,
                 keep_surfaces: bool) -> tuple:
    """(H (E, 3) or None, LightSurfaces or None): the lights' direct irradiance on `elements`,
    old's where only the materials changed, else drawn from the lights' buffers (`open_drawer`
    as refreshed's); with `keep_surfaces` and a specular scene, the buffers' surfaces from the
    same draws (the specular term's shadows)."""
    kept = [] if keep_surfaces and lighting.specular else None
    if change == "materials":
        return old.irradiance, old.light_surfaces if kept is not None else None
    if not (lighting.sources and len(elements)):
        return None, None
    with open_drawer(elements, lighting.resolution, "lights") as drawer:
        h = light_buffers.irradiance(elements, lighting.sources, drawer.views, keep=kept)
    return h, kept[0] if kept else None


def source_emission(elements: Elements, irradiance, matrix: FormFactors, lighting: Lighting) -> np.ndarray:
    """(E, 3): what the solvers take as emission, E + rho (H + S), S the sky's radiosity times
    what each hemicube saw of nothing (matrix.unseen)."""
    emission = elements.emission if irradiance is None else elements.emission + elements.reflectance * irradiance
    sky = np.asarray(lighting.sky, np.float64)
    if sky.any():
        emission = emission + elements.reflectance * matrix.unseen[:, None] * sky
    return emission


def refreshed(old: RadiositySolution | None, elements: Elements, lighting: Lighting, options: RadiosityOptions,
              open_drawer, backend: str, name: str) -> RadiositySolution | None:
    """The solution for a scene's new `elements` and `lighting` (lighting_for), or None where `old`
    stands (what_changed): the same form factors for new materials or lights; no hemicube where
    light cannot bounce; else the memory checked (memory.check_radiosity) and the hemicubes
    drawn. `open_drawer(elements, resolution, what)` ("lights" or "hemicubes") is a context
    manager giving the item buffers, the GPU's or the twin's (`draw(indices)` hemicubes `batch`
    at a time, `views(matrices)` a light's). One rule for both backends.

    With `options.refine` levels, each solution's elements where the display would differ from
    their radiosity by more than the threshold (needs_refining) are cut in four
    (radiosity_elements.refined) and everything drawn and solved again, the light buffer twice
    as fine at each level (at most MAX_LIGHT_BUFFER); the refinement follows the solution, so
    that anything but the camera changing starts again from the scene's elements."""
    change = what_changed(old, elements, lighting)
    if change == "nothing":
        return None
    if options.refine:
        change, old = "geometry", None
    solution = _solved(old, change, elements, lighting, options, open_drawer, backend, name,
                       keep_surfaces=not options.refine)
    for level in range(1, options.refine + 1):
        split = needs_refining(solution, options.refine_threshold)
        if not split.any():
            break
        # the light buffer doubles with each level, so that an element keeps its pixels
        solution = _solved(None, "geometry", refined(solution.elements, split), lighting.finer(level),
                           options, open_drawer, backend, name)
        solution.levels = level
    if lighting.specular and solution.light_surfaces is None and len(solution.elements):
        # the specular term's shadows at the options' light buffer, not the finest level's
        with open_drawer(solution.elements, lighting.resolution, "lights") as drawer:
            solution.light_surfaces = light_buffers.light_surfaces(solution.elements, lighting.sources,
                                                                   drawer.views)
    solution.base, solution.lighting = elements, lighting
    return solution


def needs_refining(solution: RadiositySolution, threshold_levels: float) -> np.ndarray:
    """(E,) bool: the elements whose display (Gouraud from the corners' values, each channel
    clamped to [0, 1] as the frame shows it) differs from their own radiosity by more than
    `threshold_levels` / 255 at some corner: where radiosity changes fast (across a shadow's
    edge, near an emitter), which a finer mesh draws better (Cohen, Greenberg, Immel and
    Brock, "An Efficient Radiosity Approach for Realistic Image Synthesis", IEEE CG&A 1986)."""
    shown = np.minimum(solution.solution.radiosity, 1.0)
    corners = np.minimum(solution.corner_radiosity, 1.0)
    return np.abs(corners - shown[:, None, :]).max(axis=(1, 2)) > threshold_levels / 255.0


def _solved(old, change: str, elements: Elements, lighting: Lighting, options: RadiosityOptions,
            open_drawer, backend: str, name: str, keep_surfaces: bool = False) -> RadiositySolution:
    """The solution for `elements` given what `change`d since `old`'s (refreshed); with
    `keep_surfaces` and a specular scene, the light buffers' surfaces kept from the same draws."""
    h, surfaces = direct_light(old, change, elements, lighting, open_drawer, keep_surfaces)
    matrix = None if change == "geometry" else old.form_factors
    if interreflects(elements, h, lighting.sky) and (matrix is None or not matrix.drawn):
        memory.check_radiosity(len(elements), options.hemicube, backend, name,
                               direct=options.solver == "direct")
        with open_drawer(elements, options.hemicube, "hemicubes") as drawer:
            matrix = form_factors(len(elements), options.hemicube, drawer.draw, drawer.batch)
    solution = solve(elements, options, matrix, h, lighting)
    solution.light_surfaces = surfaces
    return solution


def solve(elements: Elements, options: RadiosityOptions, matrix: FormFactors | None = None,
          irradiance: np.ndarray | None = None, lighting: Lighting = Lighting()) -> RadiositySolution:
    """The options' solver with form factors `matrix` (None: none drawn, FormFactors.none) and
    the lights' `irradiance` H (None: no light), and the corners' display values:
    B = E + rho (H + S + F B), S the sky's light, its radiosity times what each hemicube saw of
    nothing (all of it for one convex solid seen from outside, whose hemicubes would see nothing
    else): the solver's emission is E + rho (H + S)."""
    if matrix is None:
        matrix = FormFactors.none(len(elements), unseen=0.0 if elements.see_each_other else 1.0)
    emission = source_emission(elements, irradiance, matrix, lighting)
    limit = {} if options.max_iterations is None else (
        {"max_sweeps": options.max_iterations} if options.solver == "gauss-seidel"
        else {"max_shots": options.max_iterations})
    if options.solver == "gauss-seidel":
        solution = gauss_seidel(matrix, elements.reflectance, emission, tolerance=options.tolerance, **limit)
    elif options.solver == "direct":
        solution = direct(matrix, elements.reflectance, emission)
    else:
        solution = progressive(matrix, elements.areas, elements.reflectance, emission,
                               tolerance=options.tolerance, **limit)
    return RadiositySolution(elements, matrix, solution, corner_values(elements, solution.radiosity),
                             irradiance, lighting, source=emission)


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


@dataclass(frozen=True)
class SpecularDisplay:
    """What radiosity's display needs for the direct specular term (Lighting.specular), in the
    frame's camera-relative coordinates (positions minus the eye, as the display's corners),
    one layout for the GPU's uniforms and vertex attributes (glsl/radiosity/specular.glsl) and
    the twin (reference/radiosity/specular.py):

    per element corner, `normals` (E, 3, 3): the area-weighted mean of the element normals of
    its object meeting there within the crease angle (corner_values), unnormalised (the
    fragment renormalises, as Phong shading does); per element `ks` (E, 3), `shininess` (E,),
    `obj` (E,) its material's k_s, n and its object; per source (light_buffers.LightSource,
    in Lighting.sources' order) `where` (S, 4): a point's position and 1, or a directional
    light's unit direction of travel and 0; `intensity` (S, 3); `attenuation` (S, 3) (c, l, q);
    `emitter` (S, 4): an area point's emitting normal and scale (scale 0: isotropic); per view
    `views` (V, 4, 4) clip_from_camera-relative world and `surfaces` (V, N, N) uint32, row 0 at
    the top (light_buffers.LightSurfaces)."""
    normals: np.ndarray
    ks: np.ndarray
    shininess: np.ndarray
    obj: np.ndarray
    where: np.ndarray
    intensity: np.ndarray
    attenuation: np.ndarray
    emitter: np.ndarray
    views: np.ndarray
    surfaces: np.ndarray
    counts: tuple

    @staticmethod
    def materials(scene) -> tuple:
        """Each object's (k_s, n): what the display reads of the scene's materials besides the
        solution, so that a new k_s or n redraws the frame without solving again."""
        return tuple((tuple(float(c) for c in o.material.ks), float(o.material.n)) for o in scene.objects)


def specular_display(solution: RadiositySolution, scene, origin) -> SpecularDisplay | None:
    """The SpecularDisplay of `solution` for `scene`'s materials, relative to the frame's
    `origin` (the eye); None where the scene has no specular term (Lighting.specular)."""
    surfaces = solution.light_surfaces
    if not solution.lighting.specular or surfaces is None:
        return None
    elements = solution.elements
    origin = np.asarray(origin, np.float64)
    table = SpecularDisplay.materials(scene)
    ks = np.array([k for k, _ in table], np.float64).reshape(-1, 3)[elements.obj]
    shininess = np.array([n for _, n in table], np.float64)[elements.obj]
    sources = solution.lighting.sources
    point = np.array([s.kind == "point" for s in sources])
    where = np.array([s.where for s in sources], np.float64).reshape(-1, 3)
    where = np.concatenate([np.where(point[:, None], where - origin, where), point[:, None].astype(float)], axis=1)
    emitter = np.array([(0.0, 0.0, 0.0, 0.0) if s.emitter is None else (*s.emitter, s.emitter_scale)
                        for s in sources], np.float64).reshape(-1, 4)
    to_surfaces = np.eye(4)
    to_surfaces[:3, 3] = origin - surfaces.origin           # camera-relative to the views' relative
    return SpecularDisplay(solution.corner_normals, ks, shininess, elements.obj,
                           where, np.array([s.intensity for s in sources], np.float64).reshape(-1, 3),
                           np.array([s.attenuation for s in sources], np.float64).reshape(-1, 3), emitter,
                           surfaces.matrices @ to_surfaces, surfaces.surfaces, surfaces.counts)
