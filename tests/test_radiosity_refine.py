"""Refinement where radiosity changes fast (issue 33; renderer/core/radiosity.py needs_refining,
renderer/core/radiosity_elements.py refined): elements whose Gouraud display would differ from
their own radiosity by more than a threshold are cut in four, their neighbours kept conforming.

By hand: refinement keeps the mesh conforming (every inner edge shared by exactly two elements,
no T-junction, the area and the winding kept); the elements it cuts in the window room are
those across the sun's patch's edge; the image has no crack (no background pixel where the
room's surfaces are). GPU against twin: the same refined elements and solution, 0 mismatched
pixels. Against the path tracer (sharing nothing with it): the difference falls as it refines."""

import numpy as np
import pytest

from renderer.checks.compare import compare_frames
from renderer.checks.tolerance import PIPELINE_TOLERANCE
from renderer.core.builtin import builtin_scenes
from renderer.core.path_options import PathOptions
from renderer.core.radiosity import needs_refining
from renderer.core.radiosity_elements import refined
from renderer.core.radiosity_options import RadiosityOptions
from renderer.core.scene_file import load_scene
from renderer.errors import OptionError
from renderer.methods import open_renderer
from tests.radiosity_scenes import elements_of, quad


def window():
    return load_scene(builtin_scenes()["radiosity_window"])


def edge_counts(elements):
    """(edges (K, 2) of vertex indices, how many elements have each, the vertices' positions),
    vertices by exact position."""
    points, vertex = np.unique(elements.corners.reshape(-1, 3), axis=0, return_inverse=True)
    vertex = vertex.reshape(-1, 3)
    ends = np.sort(np.stack([vertex, np.roll(vertex, -1, axis=1)], -1), axis=-1).reshape(-1, 2)
    keys, counts = np.unique(ends, axis=0, return_counts=True)
    return keys, counts, points


def test_refinement_keeps_the_mesh_conforming():
    """Three rounds of random cuts on a unit floor: the area and the front kept; every edge
    either inside (two elements share it, end to end: no T-junction, so no crack) or on the
    square's border; a cut element's pieces in its place."""
    elements = elements_of(quad((0, 0, 0), (1, 0, 0), (0, 1, 0)), np.array([0, 0]), 0.25)
    rng = np.random.default_rng(50)
    for _ in range(3):
        split = rng.random(len(elements)) < 0.2
        finer = refined(elements, split)
        assert len(finer) >= len(elements) + 3 * split.sum()
        assert abs(finer.areas.sum() - 1.0) < 1e-12
        assert np.allclose(finer.normals, (0, 0, 1))
        keys, counts, points = edge_counts(finer)
        assert set(counts.tolist()) <= {1, 2}
        border = points[keys[counts == 1]]                             # (B, 2, 3) ends
        on_border = ((np.abs(border[..., :2]) < 1e-12) | (np.abs(border[..., :2] - 1) < 1e-12))
        assert np.all((on_border[:, 0] & on_border[:, 1]).any(axis=-1))   # both ends on one side
        elements = finer
    untouched = refined(elements, np.zeros(len(elements), bool))
    assert np.allclose(untouched.corners, elements.corners, rtol=0, atol=1e-15)


def test_it_cuts_across_the_suns_edge_and_not_inside_the_patch(gl_contexts):
    """radiosity_window at one level: the floor's elements cut are those partly in the sun
    (some of their light buffer's pixels lit), none of those wholly in shade far from it."""
    options = RadiosityOptions(element_size=0.5, hemicube=16, light_buffer=512)
    with open_renderer(window(), (32, 24), method="radiosity", options=options,
                       context=gl_contexts["egl"]) as renderer:
        solution = renderer.solution
    split = needs_refining(solution, options.refine_threshold)
    floor = solution.elements.obj == 0
    h = solution.irradiance[:, 0]
    top = h[floor].max()
    partly = floor & (h > 0.05 * top) & (h < 0.9 * top)
    assert partly.sum() > 10 and split[partly].mean() > 0.9
    dark = floor & (h == 0)
    assert dark.sum() > 100 and split[dark].mean() < split[partly].mean()


@pytest.mark.parametrize("kind, levels", [("egl", 1), pytest.param("osmesa", 1, marks=pytest.mark.slow)])
def test_the_gpu_and_the_twin_refine_alike(gl_contexts, kind, levels):
    """The same elements cut, the same lights' irradiance, the same solution to within the few
    item-buffer pixels a depth tie may give either surface (docs/radiosity.md, "GPU against
    twin"; slivers of green cuts seen edge on), the same image."""
    options = RadiosityOptions(element_size=1.0, hemicube=8, light_buffer=64, refine=levels)
    with open_renderer(window(), (48, 36), method="radiosity", options=options,
                       context=gl_contexts[kind]) as gpu:
        gpu_frame = gpu.render(linear=True)
        gpu_solution = gpu.solution
    with open_renderer(window(), (48, 36), method="radiosity", options=options, backend="reference") as twin:
        twin_frame = twin.render(linear=True)
        twin_solution = twin.solution
    assert gpu_solution.levels == twin_solution.levels == levels
    assert len(gpu_solution.elements) > 1.3 * len(gpu_solution.base)
    assert np.array_equal(gpu_solution.elements.corners, twin_solution.elements.corners)
    assert np.array_equal(gpu_solution.irradiance, twin_solution.irradiance)
    # a quarter of a level (measured: 1.2e-4 at most, a few tied item-buffer pixels among the
    # hundreds of thousands of the form factors' pixels)
    assert np.abs(gpu_solution.solution.radiosity - twin_solution.solution.radiosity).max() < 1e-3
    result = compare_frames(gpu_frame.rgba8, twin_frame.rgba8, gpu_frame.depth, twin_frame.depth,
                            reference_tie=twin_frame.rgba8_tie)
    assert PIPELINE_TOLERANCE.passes(result) and result.mismatched_pixels == 0


@pytest.mark.slow
def test_the_refined_image_has_no_crack(gl_contexts):
    """Every pixel that shows the background in the refined radiosity image (a crack would)
    lies within a pixel of one that shows it in the rasteriser's image of the same room: the
    window."""
    size = (160, 120)
    options = RadiosityOptions(element_size=0.8, hemicube=8, light_buffer=256, refine=2)
    with open_renderer(window(), size, method="radiosity", options=options, context=gl_contexts["egl"]) as r:
        radiosity = r.render()
        assert r.solution.levels == 2
    with open_renderer(window(), size, method="raster", context=gl_contexts["egl"]) as r:
        raster = r.render()
    sky = radiosity.rgba8[..., 3] == 0
    window_pixels = raster.rgba8[..., 3] == 0
    near = window_pixels.copy()
    for axis in (0, 1):
        for step in (-1, 1):
            near |= np.roll(window_pixels, step, axis=axis)
    assert window_pixels.sum() > 100 and not (sky & ~near).any()


@pytest.mark.slow
def test_refining_brings_radiosity_closer_to_the_path_tracer(gl_contexts):
    """radiosity_window at 32 x 24 against 512 paths a pixel: the mean difference in levels
    falls with each level of refinement (benchmarks/bench_radiosity_refine.py measures it at
    80 x 60 and the default options)."""
    from renderer.checks.radiosity_vs_pathtrace import path_traced
    size = (32, 24)
    truth, _, _ = path_traced(window(), size, PathOptions(samples=256), 2, context=gl_contexts["egl"])
    means = []
    for refine in (0, 1, 2):
        options = RadiosityOptions(hemicube=16, light_buffer=256, refine=refine)
        with open_renderer(window(), size, method="radiosity", options=options, context=gl_contexts["egl"]) as r:
            image = r.render(linear=True).linear[..., :3]
        means.append(float(np.abs(np.clip(image, 0, 1) - np.clip(truth, 0, 1)).mean() * 255))
    assert means[0] > means[1] > means[2], means
    assert means[2] < 0.5 * means[0], means


def test_the_refine_options_are_checked_by_name():
    for field, value, words in (("refine", 7, "an integer from 0 to 6"),
                                ("refine_threshold", 0.0, "a number > 0")):
        with pytest.raises(OptionError, match=words) as refused:
            RadiosityOptions(**{field: value})
        assert refused.value.fields == (field,)
