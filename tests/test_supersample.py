"""Supersampling (renderer/study/supersample.py): the projection jitter, GPU and reference
accumulating the same offsets, adaptive supersampling and MSAA."""

import functools

import numpy as np
import pytest

import reference
from renderer.core import transforms
from renderer.core.gl_rules import to_unorm8
from renderer.core.builtin import builtin_scenes
from renderer.checks.compare import compare_frames
from renderer.checks.tolerance import PIPELINE_TOLERANCE
from renderer.gpu import GpuRenderer, multisample_counts
from renderer.core.sampling import jittered, regular_grid
from renderer.core.scene_file import load_scene
from renderer.study.supersample import (adaptive_supersample, gpu_pass, msaa_image, reference_pass,
                                  supersample)

SIZE = (48, 36)


@functools.lru_cache(maxsize=None)
def scene_named(name):
    return load_scene(builtin_scenes()[name])


def window_xy(projection, point, width, height):
    """Window coordinates of a camera-space point (docs/conventions.md, viewport transform)."""
    clip = projection @ np.append(point, 1.0)
    ndc = clip[:2] / clip[3]
    return (ndc + 1.0) * np.array([width, height]) / 2.0


def test_jitter_is_a_clip_space_translation_by_the_offset_in_pixels():
    # W = 100, H = 50, offset (0.25, -0.5): x -= 2 * 0.25 / 100 * w, y -= 2 * -0.5 / 50 * w.
    expected = np.eye(4)
    expected[0, 3], expected[1, 3] = -0.005, 0.02
    assert np.allclose(transforms.jitter(0.25, -0.5, 100, 50), expected)


def test_a_jittered_pixel_centre_sees_the_point_at_centre_plus_offset():
    projection = transforms.perspective(np.radians(50.0), 4 / 3, 0.1, 100.0)
    point = np.array([0.3, -0.2, -4.0])
    before = window_xy(projection, point, 64, 48)
    after = window_xy(transforms.jitter(0.3, 0.1, 64, 48) @ projection, point, 64, 48)
    # The image moves by (-dx, -dy): what lay at centre + offset now lies at the centre.
    assert np.allclose(after, before - [0.3, 0.1])


def test_scene_matrices_jitter_only_the_projection():
    scene = scene_named("hierarchy")
    plain, moved = scene.matrices(64, 48), scene.matrices(64, 48, sample_offset=(0.25, -0.125))
    assert np.allclose(moved.projection, transforms.jitter(0.25, -0.125, 64, 48) @ plain.projection)
    assert np.array_equal(moved.view, plain.view)
    assert all(np.array_equal(a.model, b.model) for a, b in zip(moved.objects, plain.objects))


def test_gpu_restores_the_projection_after_a_jittered_pass(gl_contexts):
    with GpuRenderer(scene_named("sphere"), *SIZE, context=gl_contexts["egl"]) as gpu:
        plain = gpu.render().rgba8.copy()
        moved = gpu.render(sample_offset=(0.5 - 2 ** -8, 0.25)).rgba8.copy()
        again = gpu.render(sample_offset=(0.0, 0.0)).rgba8
    assert not np.array_equal(plain, moved)
    assert np.array_equal(plain, again)


def as_rgba8(image):
    return np.dstack([to_unorm8(image), np.full(image.shape[:2], 255, np.uint8)])


# The default run holds the rule with hierarchy on EGL (every shading variant, shadow maps);
# the full run (--all) adds coloured_lights and OSMesa, the same llvmpipe.
@pytest.mark.parametrize("context_kind", ("egl", pytest.param("osmesa", marks=pytest.mark.slow)))
@pytest.mark.parametrize("name", (pytest.param("coloured_lights", marks=pytest.mark.slow),
                                  "hierarchy"))
def test_gpu_and_reference_accumulate_the_same_samples(name, context_kind, gl_contexts):
    scene = scene_named(name)
    offsets = jittered(8, seed=3)
    with GpuRenderer(scene, *SIZE, context=gl_contexts[context_kind]) as gpu:
        on_gpu = supersample(gpu_pass(gpu), offsets)
        on_reference = supersample(reference_pass(scene, *SIZE, subpixel_bits=gpu.subpixel_bits),
                                   offsets)
    result = compare_frames(as_rgba8(on_gpu), as_rgba8(on_reference))
    assert PIPELINE_TOLERANCE.passes(result), (PIPELINE_TOLERANCE.failures(result), result.as_dict())
    # And the samples did something: the image differs from one sample at the centre.
    assert np.abs(on_reference - supersample(reference_pass(scene, *SIZE), [(0.0, 0.0)])).max() > 0.1


def test_supersample_averages_clamped_colour():
    # Two passes, 2.0 and 0.0: clamping first gives 0.5, not 1.0.
    colours = {(0.0, 0.0): 2.0, (0.25, 0.0): 0.0}
    image = supersample(lambda offset: np.full((1, 1, 3), colours[tuple(offset)]), list(colours))
    assert image.tolist() == [[[0.5, 0.5, 0.5]]]


class Counted:
    """A pass function (offset -> (H, W, 3) image) that counts its calls."""

    def __init__(self, image_of):
        self.image_of, self.calls = image_of, 0

    def __call__(self, offset):
        self.calls += 1
        return self.image_of(offset)


def edge_image(offset):
    """A 4x6 image, 0 everywhere but column 3, which an edge at the pixel's centre line
    x = 3.5 covers where the sample lies left of the centre."""
    image = np.zeros((4, 6, 3))
    image[:, 3] = 1.0 if offset[0] < 0.0 else 0.0
    return image


def test_adaptive_adds_samples_only_where_the_first_pass_varies():
    edge_pass = Counted(edge_image)
    image, samples = adaptive_supersample(edge_pass, first=4, total=16, threshold=0.05)
    assert edge_pass.calls == 16                    # 4 first-pass passes and 12 more
    assert samples == pytest.approx(4 + 12 * (4 / 24))   # one column of six gets them
    assert np.all(image[:, [0, 1, 2, 4, 5]] == 0.0)
    # The edge column: the fraction of all 16 samples left of the pixel centre.
    left = np.count_nonzero(np.concatenate([jittered(4)[:, 0], jittered(12, seed=1997)[:, 0]]) < 0)
    assert np.all(image[:, 3] == left / 16)


def test_adaptive_spends_nothing_more_where_nothing_varies():
    flat_pass = Counted(lambda offset: np.zeros((2, 2, 3)))
    image, samples = adaptive_supersample(flat_pass, first=4, total=64, threshold=0.05)
    assert (samples, flat_pass.calls) == (4.0, 4)


# The full run's (--all): the default run holds its parts, the adaptive rule by hand (the two
# tests above) and GPU and reference accumulating the same samples to within the tolerance.
@pytest.mark.slow
def test_adaptive_agrees_between_gpu_and_reference(gl_contexts):
    scene = scene_named("coloured_lights")
    with GpuRenderer(scene, *SIZE, context=gl_contexts["egl"]) as gpu:
        on_gpu, gpu_samples = adaptive_supersample(gpu_pass(gpu), 4, 16, 0.05)
    on_reference, reference_samples = adaptive_supersample(reference_pass(scene, *SIZE), 4, 16, 0.05)
    assert 4 < reference_samples < 16
    assert abs(gpu_samples - reference_samples) * SIZE[0] * SIZE[1] <= 12 * 2   # <= 2 decisions differ
    assert compare_frames(as_rgba8(on_gpu), as_rgba8(on_reference)).mismatched_pixels == 0


def test_msaa_uses_the_counts_the_context_offers_and_changes_only_edges(gl_contexts):
    counts = multisample_counts(gl_contexts["egl"])
    assert counts[0] == 1 and counts[-1] == 4           # llvmpipe: GL_MAX_SAMPLES = 4
    with GpuRenderer(scene_named("sphere"), *SIZE, context=gl_contexts["egl"]) as gpu:
        single, multi = msaa_image(gpu, 1), msaa_image(gpu, counts[-1])
        with pytest.raises(ValueError, match="not 3"):
            gpu.render(samples=3)
    changed = np.any(single != multi, axis=-1)
    assert changed.any()
    # A pixel MSAA changes has a neighbour of another colour in the one-sample image: an edge.
    padded = np.pad(single, ((1, 1), (1, 1), (0, 0)), mode="edge")
    neighbours = [padded[1 + dy:1 + dy + SIZE[1], 1 + dx:1 + dx + SIZE[0]]
                  for dy in (-1, 0, 1) for dx in (-1, 0, 1)]
    at_edge = np.any([np.any(n != single, axis=-1) for n in neighbours], axis=0)
    assert np.all(at_edge[changed])


def test_regular_grid_of_16_by_16_is_the_box_filtered_16x_image():
    # Why the ground truth renders once at 16W x 16H: block (i, j) of the big image holds
    # the samples at ((a + 0.5) / 16 - 0.5, (b + 0.5) / 16 - 0.5) of pixel (i, j).
    # Checked with a 4x4 grid at a tiny size: 16 passes against one 4W x 4H frame.
    scene = scene_named("point_light_plane")
    width, height = 8, 6
    passes = supersample(reference_pass(scene, width, height), regular_grid(16))
    big = reference.render(scene, 4 * width, 4 * height, linear=True, depth=False).linear[..., :3]
    boxed = np.clip(big, 0, 1).reshape(height, 4, width, 4, 3).mean(axis=(1, 3))
    assert np.abs(passes - boxed).max() < 1e-4
