"""The ray tracer's sample positions (renderer/core/ray_sampling.py; glsl/raytrace/sampling.glsl
and reference/raytrace/sampling.py): each pattern's rule checked by hand (a jittered sample's
stratum, random offsets in [-0.5, 0.5), the tables), the GLSL bit for bit against the twin,
progressive frames (first_sample), adaptive refinement exactly where the first samples
disagree, and the GPU against the reference with each pattern."""

from fractions import Fraction

import numpy as np
import pytest
from glsl_harness import ShaderProbe

from reference.raytrace.camera import camera_ray
from reference.raytrace.pipeline import DECISION_MARGIN, render as reference_raytrace
from reference.raytrace.random import random_float, random_stream
from reference.raytrace.sampling import sample_offset, stratum_offset
from reference.raytrace.trace import trace
from reference.lighting import Lights
from renderer.checks.compare import compare_frames
from renderer.checks.tolerance import PIPELINE_TOLERANCE
from renderer.core.camera_rays import camera_ray_uniforms
from renderer.core.ray_sampling import (DEFAULT_ADAPTIVE_THRESHOLD, MAX_SAMPLES, check_first_sample,
                                        ray_sampling)
from renderer.core.raytrace_scene import ray_scene
from renderer.core.sampling import poisson_disk, regular_grid
from renderer.core.scene_file import scene_from_dict
from renderer.gpu.defines import sampling_defines

F32 = np.float32
Y, X = np.mgrid[0:6, 0:8].astype(np.uint32)          # a few pixels (x, y), row 0 at the bottom


def cells(offsets, columns, rows):
    """The (column, row) of the cell of a columns x rows grid that each offset lies in,
    computed exactly (Fractions), and whether each lies in [-0.5, 0.5)."""
    u = [[Fraction(float(v)) + Fraction(1, 2) for v in o] for o in offsets.reshape(-1, 2)]
    inside = all(0 <= a < 1 and 0 <= b < 1 for a, b in u)
    return {(int(a * columns), int(b * rows)) for a, b in u}, inside


def test_stratum_offset_by_hand():
    # one cell: (h >> 8) 2^-24 - 0.5, the random float minus a half
    assert stratum_offset(np.uint32(0), 0, 1) == -0.5
    assert stratum_offset(np.uint32(0xFFFFFFFF), 0, 1) == F32(0.5 - 2.0 ** -24)
    # cell 1 of 3 at h = 0: floor(2^24 / 3) = 5592405 would lie below 1/3; ceil(2^24 / 3) = 5592406
    assert Fraction(float(stratum_offset(np.uint32(0), 1, 3))) + Fraction(1, 2) == Fraction(5592406, 2 ** 24)
    assert Fraction(5592405, 2 ** 24) < Fraction(1, 3) <= Fraction(5592406, 2 ** 24)
    # the last cell of 256 at the largest h: no 32-bit overflow, still below 1
    top = stratum_offset(np.uint32(0xFFFFFFFF), 255, 256)
    assert Fraction(255, 256) <= Fraction(float(top)) + Fraction(1, 2) < 1


def test_stratum_offset_stays_in_its_cell_for_every_grid():
    h = np.concatenate([np.array([0, 255, 256, 0x7FFFFFFF, 0xFFFFFF00, 0xFFFFFFFF], np.uint32),
                        random_stream(np.arange(200), 0, 0, 0, 5)])
    for c in list(range(1, 17)) + [101, 251, 256]:
        for a in {0, min(1, c - 1), c // 2, c - 1}:
            n = ((stratum_offset(h, a, c).astype(np.float64) + 0.5) * 2 ** 24)
            assert (n == np.round(n)).all()                                 # 24-bit fixed point, exact
            n = n.astype(np.int64)
            assert (n * c >= a * 2 ** 24).all() and (n * c < (a + 1) * 2 ** 24).all(), (a, c)


def test_random_offsets_are_the_pcg_numbers_minus_a_half():
    sampling = ray_sampling("random", 3, seed=77)
    for k, first in [(0, 0), (2, 0), (1, 1000)]:
        got = sample_offset(X, Y, k, first, sampling)
        stream = random_stream(X, Y, first + k, 0, 77)
        assert got.dtype == F32 and got.shape == (6, 8, 2)
        assert np.array_equal(got[..., 0], random_float(stream, 0) - F32(0.5))
        assert np.array_equal(got[..., 1], random_float(stream, 1) - F32(0.5))
        assert (got >= -0.5).all() and (got < 0.5).all()
    # the sample index, not k alone: sample 2 of frame 0 is sample 1 of the frame from 1
    assert np.array_equal(sample_offset(X, Y, 2, 0, sampling), sample_offset(X, Y, 1, 1, sampling))


def test_a_jittered_sample_lies_in_its_stratum():
    sampling = ray_sampling("jittered", 6)                  # strata(6): 3 columns x 2 rows
    assert sampling.first_strata == (3, 2)
    for k in range(6):
        found, inside = cells(sample_offset(X, Y, k, 12345, sampling), 3, 2)
        assert inside and found == {(k % 3, k // 3)}, k            # sample 4: column 1, row 1
    # every pixel's six samples differ from the next pixel's: the positions are per pixel
    assert not np.array_equal(sample_offset(X, Y, 0, 0, sampling)[0, 0], sample_offset(X, Y, 0, 0, sampling)[0, 1])


def test_adaptive_first_set_is_2x2_and_the_rest_fills_strata_of_n_minus_4():
    sampling = ray_sampling("adaptive", 16)
    assert (sampling.first_set, sampling.first_strata, sampling.rest_strata) == (4, (2, 2), (4, 3))
    for k in range(16):
        j, (columns, rows) = (k, (2, 2)) if k < 4 else (k - 4, (4, 3))
        found, inside = cells(sample_offset(X, Y, k, 0, sampling), columns, rows)
        assert inside and found == {(j % columns, j // columns)}, k    # sample 9: column 1, row 1 of 4 x 3


def test_regular_and_poisson_are_tables_the_same_everywhere():
    for name, table in [("regular", regular_grid(9)), ("poisson", poisson_disk(9, seed=3))]:
        sampling = ray_sampling(name, 9, seed=3)
        for k in (0, 4, 8):
            for first in (0, 9, 1000):
                got = sample_offset(X, Y, k, first, sampling)
                assert (got == table[k].astype(F32)).all(), (name, k, first)


def test_glsl_sample_offsets_are_the_twin_bit_for_bit(gl_contexts):
    width, height = 37, 23
    y, x = np.mgrid[0:height, 0:width].astype(np.uint32)
    cases = [(ray_sampling("random", 3, seed=0), [0, 2], [0, 2 ** 32 - 3]),
             (ray_sampling("jittered", 6, seed=0xFFFFFFFF), [0, 4, 5], [0, 77]),
             (ray_sampling("adaptive", 16), [0, 3, 4, 15], [0, 16]),
             (ray_sampling("adaptive", 7, seed=5), [6], [3]),
             (ray_sampling("regular", 4), [0, 3], [0]),
             (ray_sampling("poisson", 5), [1, 4], [0])]
    for kind, ctx in gl_contexts.items():
        for sampling, ks, firsts in cases:
            with ShaderProbe(ctx, "raytrace_sampling.frag", sampling_defines(sampling), (width, height), 2) as shader:
                shader.write(sampling.uniforms())
                for k in ks:
                    for first in firsts:
                        got = shader.run(u_k=k, u_first_sample=first)
                        expected = sample_offset(x, y, k, first, sampling).view(np.uint32)
                        assert np.array_equal(got, expected), (kind, sampling.pattern, k, first)


def test_ray_sampling_refuses_what_it_cannot_do():
    for args, reason in [(("stratified", 4), "must be one of"), (("random", 0), "between 1 and"),
                         (("random", MAX_SAMPLES + 1), "between 1 and"), (("regular", 2), "perfect square"),
                         (("adaptive", 3), "at least 4"), (("random", 1, -1), "seed"),
                         (("random", 1, 2 ** 32), "seed"), (("random", 1, 1.5), "seed")]:
        with pytest.raises(ValueError, match=reason):
            ray_sampling(*args)
    with pytest.raises(ValueError, match="adaptive pattern"):
        ray_sampling("jittered", 4, adaptive_threshold=0.1)
    for bad in (-0.1, float("nan"), float("inf")):
        with pytest.raises(ValueError, match="finite"):
            ray_sampling("adaptive", 4, adaptive_threshold=bad)
    assert ray_sampling("adaptive", 4).threshold == DEFAULT_ADAPTIVE_THRESHOLD == 2 / 255
    assert check_first_sample(2 ** 32 - 16, 16) == 2 ** 32 - 16
    for bad in (-1, 2 ** 32 - 15, 0.5):
        with pytest.raises(ValueError, match="first_sample"):
            check_first_sample(bad, 16)


# A parallel camera one scene unit per pixel at 8 x 8: a white box (ambient only, no lights)
# fills x < -0.5, whose edge runs down the middle of pixel column 3; black elsewhere.
EDGE = {"background": [0, 0, 0], "ambient": [1, 1, 1],
        "camera": {"projection": "parallel", "eye": [0, 0, 5], "look": [0, 0, 0], "height": 8.0},
        "materials": {"white": {"ka": [1, 1, 1], "kd": [0, 0, 0]}},
        "objects": [{"name": "box", "mesh": {"primitive": "cube", "size": 1.0}, "material": "white",
                     "scale": [4, 20, 1], "translate": [-2.5, 0, 0]}]}


def test_adaptive_refines_the_half_covered_edge_pixel_only():
    """Column 3's first four samples lie two left of its centre (on the box) and two right
    (off it): they disagree, so it takes all 16, of which the strata put 8 on the box: 0.5
    exactly. A pixel inside the box and one of background see one colour four times (spread
    0, not more than even a threshold of 0) and stop at 4."""
    s = scene_from_dict(EDGE)
    for threshold in (0.0, DEFAULT_ADAPTIVE_THRESHOLD, 0.99):
        frame = reference_raytrace(s, 8, 8, samples=16, pattern="adaptive", adaptive_threshold=threshold)
        assert (frame.samples == [4, 4, 4, 16, 4, 4, 4, 4]).all(), threshold
        assert (frame.linear[:, :3, :3] == 1).all() and (frame.linear[:, 4:, :3] == 0).all()
        assert (frame.linear[:, 3, :3] == 0.5).all()
    # the same pixel under jittered 16: the same 8 of 16
    assert (reference_raytrace(s, 8, 8, samples=16, pattern="jittered").linear[:, 3, :3] == 0.5).all()
    # a threshold of 1 (a spread cannot exceed it): nothing refined, the first set's 2 of 4
    frame = reference_raytrace(s, 8, 8, samples=16, pattern="adaptive", adaptive_threshold=1.0)
    assert (frame.samples == 4).all() and (frame.linear[:, 3, :3] == 0.5).all()


SHAPES = {"background": [0.1, 0.2, 0.3], "ambient": [0.1, 0.1, 0.1],
          "camera": {"eye": [0, 1, 6], "look": [0, 0, 0], "fov_y": 40.0},
          "materials": {"red": {"ka": [0.8, 0.2, 0.1], "kd": [0.8, 0.2, 0.1], "ks": [0.5, 0.5, 0.5], "n": 20.0},
                        "mirror": {"kd": [0, 0, 0], "ka": [0, 0, 0], "kr": [0.9, 0.9, 0.9]},
                        "floor": {"kd": [0.6, 0.6, 0.6], "ka": [0.6, 0.6, 0.6], "two_sided": True}},
          "lights": [{"type": "directional", "direction": [0.3, -1, -0.4]}],
          "objects": [{"name": "a", "shape": {"type": "sphere", "radius": 0.8}, "material": "red", "translate": [-1, 0, 0]},
                      {"name": "b", "shape": {"type": "sphere", "radius": 0.8}, "material": "mirror", "translate": [1, 0, 0]},
                      {"name": "f", "shape": {"type": "plane", "normal": [0, 1, 0], "offset": 0.8}, "material": "floor"},
                      {"name": "m", "mesh": {"primitive": "icosphere", "radius": 0.4, "subdivisions": 1},
                       "material": "red", "translate": [0, 1.2, 0]}]}


def first_set_spread(s, width, height, first_sample=0):
    """Per pixel (row 0 at the top), the spread of the adaptive first set's clamped colours,
    traced here sample by sample through the twin's stages."""
    sampling = ray_sampling("adaptive", 16)
    matrices = s.matrices(width, height)
    uniforms = {k: v.astype(F32) for k, v in camera_ray_uniforms(matrices.view, matrices.projection,
                                                                  width, height).items()}
    y, x = np.mgrid[0:height, 0:width].astype(np.uint32)
    colours = []
    for k in range(4):
        windows = np.stack([x, y], -1).astype(F32) + F32(0.5) + sample_offset(x, y, k, first_sample, sampling)
        O, D = camera_ray(windows.reshape(-1, 2), uniforms)
        colour, _, _ = trace(ray_scene(s), Lights.from_scene(s, F32, origin=matrices.origin), O, D,
                             s.camera.near, s.camera.far, s.background, 4)
        colours.append(np.clip(colour, 0, 1))
    colours = np.stack(colours)
    return (colours.max(0) - colours.min(0)).max(-1).reshape(height, width)[::-1]


def test_adaptive_refines_exactly_where_the_first_samples_spread_beyond_the_threshold():
    s = scene_from_dict(SHAPES)
    spread = first_set_spread(s, 40, 30, first_sample=8)
    for threshold in (DEFAULT_ADAPTIVE_THRESHOLD, 0.05):
        frame = reference_raytrace(s, 40, 30, samples=8, pattern="adaptive", adaptive_threshold=threshold,
                                   first_sample=8)
        assert np.array_equal(frame.samples, np.where(spread > F32(threshold), 8, 4))
        assert 0.05 < (frame.samples == 8).mean() < 0.6         # edges, the mirror: some, not all


def test_first_sample_draws_new_stochastic_samples_and_the_same_regular_ones():
    s = scene_from_dict(SHAPES)
    for pattern, n in [("random", 4), ("jittered", 4), ("adaptive", 8)]:
        a, b = (reference_raytrace(s, 24, 18, samples=n, pattern=pattern, first_sample=f).linear for f in (0, n))
        assert not np.array_equal(a, b), pattern
    for pattern, n in [("regular", 4), ("poisson", 4)]:
        a, b = (reference_raytrace(s, 24, 18, samples=n, pattern=pattern, first_sample=f).linear for f in (0, n))
        assert np.array_equal(a, b), pattern
    # progressive: two frames of 4 random samples average to the frame of those 8
    frames = [reference_raytrace(s, 24, 18, samples=4, pattern="random", first_sample=f).linear for f in (0, 4)]
    eight = reference_raytrace(s, 24, 18, samples=8, pattern="random").linear
    assert np.allclose((frames[0][..., :3] + frames[1][..., :3]) / 2, eight[..., :3], atol=1e-6)


def assert_within_tolerance(result, reference):
    comparison = compare_frames(result.rgba8, reference.rgba8, result.depth, reference.depth,
                                PIPELINE_TOLERANCE.threshold, PIPELINE_TOLERANCE.deviation,
                                reference_tie=reference.rgba8_tie)
    assert PIPELINE_TOLERANCE.passes(comparison), PIPELINE_TOLERANCE.failures(comparison)


def gpu_against_reference(gl_contexts, pattern, samples, first_sample=3):
    from renderer.gpu.raytracer import RayTracer
    s = scene_from_dict(SHAPES)
    reference = reference_raytrace(s, 64, 48, samples=samples, pattern=pattern, first_sample=first_sample)
    # an adaptive pixel whose spread is within the decision margin may be decided either way
    tie = np.zeros((48, 64), bool)
    if pattern == "adaptive":
        spread = first_set_spread(s, 64, 48, first_sample)
        tie = np.abs(spread.astype(np.float64) - F32(DEFAULT_ADAPTIVE_THRESHOLD)) <= DECISION_MARGIN
    for kind, ctx in gl_contexts.items():
        with RayTracer(s, 64, 48, context=ctx, samples=samples, pattern=pattern) as tracer:
            frame = tracer.render(first_sample=first_sample)
        assert_within_tolerance(frame, reference)
        assert np.array_equal(frame.samples[~tie], reference.samples[~tie]), kind


def test_gpu_adaptive_against_the_reference(gl_contexts):
    gpu_against_reference(gl_contexts, "adaptive", 8)


@pytest.mark.slow
@pytest.mark.parametrize("pattern,samples", [("regular", 4), ("random", 3), ("jittered", 6), ("poisson", 5),
                                             ("adaptive", 16)])
def test_gpu_against_the_reference_with_each_pattern(gl_contexts, pattern, samples):
    gpu_against_reference(gl_contexts, pattern, samples)


def test_command_line_adaptive(tmp_path, capsys):
    """`renderer render --pattern adaptive` says what it traced; the refusals are one line."""
    from renderer.cli import main
    out = tmp_path / "a.png"
    assert main(["render", "sphere", "--method", "raytrace", "--spp", "8", "--pattern", "adaptive",
                 "--adaptive-threshold", "0.02", "--size", "24x18", "--backend", "reference", "-o", str(out)]) == 0
    assert "raytrace adaptive up to 8 spp: mean " in capsys.readouterr().err and out.is_file()
    for bad, reason in [(["--pattern", "adaptive", "--spp", "2"], "--spp 2 --pattern adaptive: adaptive sampling "
                                                                  "needs at least 4"),
                        (["--pattern", "jittered", "--adaptive-threshold", "0.1"],
                         "--adaptive-threshold 0.1 --pattern jittered: an adaptive threshold is for the "
                         "adaptive pattern, not jittered"),
                        (["--pattern", "adaptive", "--spp", "4", "--adaptive-threshold", "-1"], "finite"),
                        (["--seed", "-3"], "--seed -3: the seed must be"),
                        (["--pattern", "sobol"], "--pattern sobol: sample pattern must be one of")]:
        assert main(["render", "sphere", "--method", "raytrace", "--size", "8x8", "-o", str(tmp_path / "x.png"),
                     *bad]) == 2, bad
        assert reason in capsys.readouterr().err, bad
    assert not (tmp_path / "x.png").exists()
