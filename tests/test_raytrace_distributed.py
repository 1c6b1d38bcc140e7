"""The distributed dimensions' sampling layer (renderer/core/ray_sampling.py; glsl/raytrace/
sampling.glsl `permute`, `distributed_2d`, `distributed_1d` and their twins in reference/raytrace/
sampling.py; docs/conventions.md, "Distributed sampling"): Kensler's permutation is a bijection
for every length; each pattern's points of one dimension over a pixel's samples are stratified
as the pattern says (one per cell, the centres for regular, the pixel's table for poisson);
dimensions are decorrelated (another dimension or slot gives another permutation); table
patterns repeat from frame to frame and the others do not; the GLSL draws the twin's points bit
for bit on EGL and OSMesa."""

import re
from pathlib import Path

import numpy as np
import pytest
from glsl_harness import ShaderProbe

from reference.raytrace.sampling import distributed_1d, distributed_2d, permute
import renderer.core.ray_sampling as ray_sampling_module
from renderer.core.ray_sampling import (FIRST_SET, LENS_DIMENSION, MAX_LIGHT_SAMPLES, MAX_SAMPLES,
                                        MAX_STRATA_SIDE, TIME_DIMENSION, ray_sampling)
from renderer.gpu.defines import sampling_defines


def test_permute_is_a_bijection_of_every_length():
    for length in [1, 2, 3, 4, 5, 7, 16, 17, 31, 100, 255, 256, 4096, 16384]:
        for key in [0, 1, 0x7FFFFFFF, 0x80000000, 0xFFFFFFFF, 0xFFFFFFFE, 123456789]:
            image = permute(np.arange(length), length, key)
            assert sorted(image.tolist()) == list(range(length)), (length, key)


def test_permute_keeps_its_bijection_where_the_memos_rotation_would_wrap():
    # (i + p) mod 2^32 mod l is not a rotation when p + l passes 2^32 and l does not divide
    # 2^32: with l = 3 and p = 2^32 - 1, the memo's sum sends 0 and 1 to 2 and 0, and 2 to
    # 1 mod 2^32 mod 3 = 1: still fine here, but l = 5, p = 2^32 - 2 sends 2 to 0 and 0 to
    # (2^32 - 2) mod 5 = 4, 1 to 0: two values onto 0.
    assert sorted(permute(np.arange(5), 5, 2 ** 32 - 2).tolist()) == [0, 1, 2, 3, 4]
    with np.errstate(over="ignore"):
        memo = (np.arange(5, dtype=np.uint32) + np.uint32(2 ** 32 - 2)) % np.uint32(5)
    assert len(set(memo.tolist())) < 5


def cells_of(points, columns, rows):
    """The (column, row) of each point's cell of a columns x rows grid of [0, 1)^2."""
    return [(int(np.floor(x * columns)), int(np.floor(y * rows))) for x, y in points]


@pytest.mark.parametrize("pattern, samples, per_sample", [("jittered", 16, 1), ("jittered", 6, 4),
                                                          ("regular", 9, 1), ("random", 4, 1),
                                                          ("poisson", 8, 1), ("poisson", 8, 2)])
def test_a_dimensions_points_fill_the_strata_of_the_pixels_samples(pattern, samples, per_sample):
    sampling = ray_sampling(pattern, samples, seed=11, light_samples=per_sample)
    columns, rows = sampling.dimension_grid(0, per_sample)
    assert columns * rows == samples * per_sample
    for x, y, slot in [(0, 0, 0), (5, 3, 1), (2, 7, 12345)]:
        points = np.array([distributed_2d(x, y, k, 0, sampling, slot, LENS_DIMENSION, m, per_sample)
                           for k in range(samples) for m in range(per_sample)]).reshape(-1, 2)
        assert points.dtype == np.float32 and (points >= 0).all() and (points < 1).all()
        if pattern == "random":
            continue                              # no cells: the stream's numbers themselves
        if pattern == "poisson" and per_sample == 1:
            expected = np.sort(np.minimum(sampling.table + np.float32(0.5), np.float32(1 - 2 ** -24)), 0)
            assert np.array_equal(np.sort(points, 0), expected)        # the table, shuffled
            continue
        assert sorted(cells_of(points, columns, rows)) == sorted((a, b) for b in range(rows) for a in range(columns))
        if pattern == "regular":                  # each cell's centre
            assert set(np.round(points[:, 0] * columns * 2).astype(int) % 2) == {1}


def test_one_dimensional_points_fill_n_strata_and_adaptive_sets_each_their_own():
    for pattern in ("jittered", "regular", "poisson"):
        sampling = ray_sampling(pattern, 16)
        t = np.array([distributed_1d(4, 1, k, 0, sampling, 0, TIME_DIMENSION) for k in range(16)]).ravel()
        assert sorted(np.floor(t * 16).astype(int).tolist()) == list(range(16)), pattern
    sampling = ray_sampling("adaptive", 10)                     # sets of 4 and 6
    t = np.array([distributed_1d(4, 1, k, 0, sampling, 0, TIME_DIMENSION) for k in range(10)]).ravel()
    assert sorted(np.floor(t[:4] * 4).astype(int).tolist()) == [0, 1, 2, 3]
    assert sorted(np.floor(t[4:] * 6).astype(int).tolist()) == [0, 1, 2, 3, 4, 5]


def test_dimensions_slots_and_pixels_are_shuffled_apart():
    sampling = ray_sampling("jittered", 16, seed=3)
    def cells(dimension, slot, x=1):
        p = np.array([distributed_2d(x, 2, k, 0, sampling, slot, dimension) for k in range(16)]).reshape(-1, 2)
        return cells_of(p, 4, 4)
    # the pixel offsets themselves (sample_offset) put sample k in cell k; the lens does not
    assert cells(LENS_DIMENSION, 0) != [(k % 4, k // 4) for k in range(16)]
    assert len({tuple(cells(d, s, x)) for d in (1, 2) for s in (0, 1, 2) for x in (0, 1)}) == 12


def test_table_patterns_repeat_each_frame_and_the_others_draw_new_points():
    for pattern, repeats in [("regular", True), ("poisson", True), ("jittered", False), ("random", False)]:
        sampling = ray_sampling(pattern, 4)
        frame0 = distributed_2d(3, 3, np.arange(4), 0, sampling, 0, LENS_DIMENSION)
        frame1 = distributed_2d(3, 3, np.arange(4), 4, sampling, 0, LENS_DIMENSION)
        assert np.array_equal(frame0, frame1) == repeats, pattern


def test_the_glsl_dimensions_and_stream_layout_are_the_pythons():
    """sampling.glsl's constants, each the one renderer/core/ray_sampling.py names."""
    text = (Path(__file__).resolve().parents[1] / "glsl" / "raytrace" / "sampling.glsl").read_text()
    found = {name: int(value, 0) for name, value in
             re.findall(r"const uint ([A-Z_]+) = (0x[0-9A-Fa-f]+|\d+)u;", text)}
    names = ["PIXEL_DIMENSION", "LENS_DIMENSION", "TIME_DIMENSION", "GLOSSY_DIMENSION",
             "LIGHT_DIMENSION", "DIMENSION_STRIDE", "PERMUTATION_SALT"]
    assert {name: found[name] for name in names} == {name: getattr(ray_sampling_module, name) for name in names}


def test_every_allowed_count_makes_strata_grids_stratum_offset_can_hold():
    """stratum_coordinate needs at most MAX_STRATA_SIDE columns and rows (its numerators stay
    below 2^32): every N and M ray_sampling accepts, in every set, keeps to it."""
    widest = 0
    for pattern in ("jittered", "adaptive"):
        for n in range(FIRST_SET if pattern == "adaptive" else 1, MAX_SAMPLES + 1):
            for m in range(1, MAX_LIGHT_SAMPLES + 1):
                sampling = ray_sampling(pattern, n, light_samples=m)
                for which in (0, 1):
                    for per_sample in (1, m):
                        widest = max(widest, *sampling.dimension_grid(which, per_sample))
    assert 0 < widest <= MAX_STRATA_SIDE


def test_light_samples_are_refused_outside_their_range():
    for bad in (0, MAX_LIGHT_SAMPLES + 1, 1.5):
        with pytest.raises(ValueError, match="light samples"):
            ray_sampling("jittered", 4, light_samples=bad)


def test_glsl_distributed_points_are_the_twin_bit_for_bit(gl_contexts):
    width, height = 19, 13
    y, x = np.mgrid[0:height, 0:width].astype(np.uint32)
    cases = [(ray_sampling("random", 3, seed=0), [0, 2], 0),
             (ray_sampling("jittered", 6, seed=0xFFFFFFFF, light_samples=4), [0, 5], 77),
             (ray_sampling("adaptive", 16, light_samples=3), [0, 3, 4, 15], 16),
             (ray_sampling("regular", 4, light_samples=2), [0, 3], 5),
             (ray_sampling("poisson", 5, light_samples=2), [1, 4], 9)]
    for kind, ctx in gl_contexts.items():
        for sampling, ks, first in cases:
            with ShaderProbe(ctx, "raytrace_distributed.frag", sampling_defines(sampling), (width, height), 4) as shader:
                shader.write(sampling.uniforms())
                for k in ks:
                    for slot, dimension, m, per_sample in [(0, 1, 0, 1), (9, 2, 1, sampling.light_samples),
                                                           (2 ** 32 - 1, 3, sampling.light_samples - 1,
                                                            sampling.light_samples)]:
                        got = shader.run(u_first_sample=first, u_k=k, u_slot=slot, u_dimension=dimension,
                                         u_m=m, u_per_sample=per_sample, u_length=7)
                        point = distributed_2d(x, y, k, first, sampling, slot, dimension, m, per_sample)
                        line = distributed_1d(x, y, k, first, sampling, slot, dimension)
                        with np.errstate(over="ignore"):
                            key = x * np.uint32(7919) + y
                        label = (kind, sampling.pattern, k, slot)
                        assert np.array_equal(got[..., :2], point.view(np.uint32)), label
                        assert np.array_equal(got[..., 2], line.view(np.uint32)), label
                        assert np.array_equal(got[..., 3], permute(k % 7, 7, key)), label
