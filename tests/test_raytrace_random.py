"""The ray tracer's counter-based hash (glsl/raytrace/random.glsl, reference/raytrace/random.py):
values worked out by hand and by an independent integer implementation, and the GLSL on
llvmpipe (EGL and OSMesa) bit for bit against the NumPy twin."""

from pathlib import Path

import numpy as np
import pytest

from reference.raytrace.random import (pcg_hash, random_float, random_stream, random_uint,
                                       uint_to_unit_float)
from renderer.gpu.shaders import shader_source

GLSL = Path(__file__).parent / "glsl"
MASK = 0xFFFFFFFF


def pcg_python(v: int) -> int:
    """The PCG hash in Python integers, masked by hand: independent of NumPy's uint32."""
    state = (v * 747796405 + 2891336453) & MASK
    word = (((state >> ((state >> 28) + 4)) ^ state) * 277803737) & MASK
    return (word >> 22) ^ word


def stream_python(x, y, sample, bounce, seed) -> int:
    h = pcg_python(seed)
    for value in (bounce, sample, y, x):
        h = pcg_python((h + value) & MASK)
    return h


def test_pcg_hash_of_zero_by_hand():
    # state = 0 * 747796405 + 2891336453 = 2891336453; state >> 28 = 10, so shift by 14:
    # state >> 14 = 176473; 176473 ^ 2891336453 = 2891250268; * 277803737 mod 2^32 = 129708028;
    # 129708028 >> 22 = 30; 30 ^ 129708028 = 129708002.
    assert pcg_python(0) == 129708002
    assert pcg_hash(0) == 129708002 and pcg_hash(0).dtype == np.uint32


def test_pcg_hash_known_values_and_wrap_around():
    known = {0: 129708002, 1: 2831084092, 2: 2055130248, 123456789: 4272394698,
             0xFFFFFFFF: 3861530882}
    for v, h in known.items():
        assert pcg_python(v) == h
    with np.errstate(all="raise"):           # wrap-around is not an overflow error
        got = pcg_hash(np.array(list(known), dtype=np.uint32))
        assert pcg_hash(0xFFFFFFFF) == 3861530882
    assert got.dtype == np.uint32 and got.tolist() == list(known.values())
    with pytest.raises(ValueError):
        pcg_hash(-1)


def test_stream_is_the_chained_hash_vectorised():
    rng = np.random.default_rng(14)
    values = rng.integers(0, 2**32, size=(5, 40), dtype=np.uint64)
    got = random_stream(*values)
    assert got.dtype == np.uint32 and got.shape == (40,)
    assert got.tolist() == [stream_python(*map(int, column)) for column in values.T]
    h = int(got[0])
    assert random_uint(h, 3) == pcg_python((h + 3) & MASK)
    # broadcasting: one seed for a grid of pixels
    y, x = np.mgrid[0:3, 0:4]
    grid = random_stream(x, y, 7, 1, 99)
    assert grid.shape == (3, 4) and grid[2, 3] == stream_python(3, 2, 7, 1, 99)
    # every argument matters
    assert len({int(random_stream(*args)) for args in
                [(0, 0, 0, 0, 0), (1, 0, 0, 0, 0), (0, 1, 0, 0, 0), (0, 0, 1, 0, 0),
                 (0, 0, 0, 1, 0), (0, 0, 0, 0, 1)]}) == 6


def test_unit_float_is_exact_and_in_range():
    h = np.array([0, 255, 256, 0x80000000, MASK], dtype=np.uint32)
    f = uint_to_unit_float(h)
    assert f.dtype == np.float32
    assert f.tolist() == [0.0, 0.0, 2.0**-24, 0.5, 1 - 2.0**-24]     # 1 - 2^-24 < 1 in float32
    assert (f.astype(np.float64) == (h >> 8).astype(np.float64) / 2**24).all()
    many = random_float(random_stream(np.arange(10000), 0, 0, 0, 1), 0)
    assert many.min() >= 0 and many.max() < 1 and abs(many.mean() - 0.5) < 0.01


def test_glsl_hash_is_the_twin_bit_for_bit(gl_contexts):
    width, height = 64, 32
    y, x = np.mgrid[0:height, 0:width]
    vertex = shader_source("fullscreen.vert", directory=GLSL).text
    fragment = shader_source("raytrace_random.frag", directory=GLSL).text
    for kind, ctx in gl_contexts.items():
        program = ctx.program(vertex_shader=vertex, fragment_shader=fragment)
        texture = ctx.texture((width, height), 4, dtype="u4")
        framebuffer = ctx.framebuffer([texture])
        vao = ctx.vertex_array(program, [])
        try:
            for sample, bounce, seed in [(0, 0, 0), (3, 2, 0xDEADBEEF), (MASK, 7, 1)]:
                program["u_sample"].value, program["u_bounce"].value = sample, bounce
                program["u_seed"].value = seed
                framebuffer.use()
                framebuffer.clear()
                vao.render(vertices=3)
                got = np.frombuffer(texture.read(), np.uint32).reshape(height, width, 4)
                stream = random_stream(x, y, sample, bounce, seed)
                assert np.array_equal(got[..., 0], stream), (kind, sample, bounce, seed)
                assert np.array_equal(got[..., 1], random_uint(stream, 0)), kind
                assert np.array_equal(got[..., 2], random_uint(stream, 1)), kind
                assert np.array_equal(got[..., 3], random_float(stream, 2).view(np.uint32)), kind
        finally:
            for thing in (vao, framebuffer, texture, program):
                thing.release()
