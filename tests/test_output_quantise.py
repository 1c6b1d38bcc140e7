"""Quantisation in the output stage (reference/output/quantise.py; glsl/output/quantise.glsl):
the count over a table and dithering's choice between two codes by hand, the GPU's binary
search against the rule itself (renderer/core/quantise.py, code_of) at every decision point,
and the baseline on a rendered frame: linear 8-bit codes are the framebuffer's rgba8.
"""

import numpy as np
import pytest

import reference.output
from renderer.core.output_settings import OutputSettings, Transfer
from renderer.core.quantise import code_of, decision_points
from renderer.core.scene_file import load_scene
from renderer.gpu import GpuRenderer
from reference.output.quantise import bracketed_code, count_at_or_below

LINEAR, SRGB, GAMMA = Transfer("linear"), Transfer("srgb"), Transfer("gamma", 2.2)


def test_count_at_or_below_counts_entries_not_above():
    table = np.array([0.25, 0.5, 0.75], np.float32)
    light = [-1.0, 0.0, 0.25, 0.3, 0.75, 2.0, np.inf, -np.inf, np.nan]
    assert count_at_or_below(light, table).tolist() == [0, 0, 1, 1, 3, 3, 3, 0, 0]   # NaN: 0


def test_bracketed_code_rounds_up_past_the_threshold():
    # linear, 2 bits: the codes' light is 0, 1/3, 2/3, 1; L = 0.5 is half way from code 1 to 2
    half = np.float32(0.5)
    assert bracketed_code(half, np.float32(0.4), LINEAR, 2) == 2
    assert bracketed_code(half, np.float32(0.6), LINEAR, 2) == 1
    # the top code stays; below 0, NaN and above 1 are clamped first
    light = np.array([1.0, 2.0, -1.0, np.nan, 0.0], np.float32)
    assert bracketed_code(light, np.float32(1e-6), LINEAR, 2).tolist() == [3, 3, 0, 0, 0]
    # sRGB, 1 bit: the codes' light is 0 and 1, so L itself is the fraction (not its encoding)
    assert bracketed_code(np.float32(0.3), np.float32(0.29), SRGB, 1) == 1
    assert bracketed_code(np.float32(0.3), np.float32(0.31), SRGB, 1) == 0


@pytest.mark.parametrize("kind", ("egl", "osmesa"))
def test_the_gpu_search_is_exact_whatever_its_guess(gl_contexts, kind):
    """quantise.glsl counts from the transfer curve's guess (one off at most, in practice);
    any guess, however wrong, must still end at the exact count: each lane of a SIMD vector
    then walks a different distance, as a NaN or a denormal's guess might make it."""
    from pathlib import Path
    from renderer.gpu.context import activate
    from renderer.gpu.output import table_texture
    from renderer.gpu.shaders import shader_source
    ctx = gl_contexts[kind]
    activate(ctx)
    rng = np.random.default_rng(5)
    points = decision_points(SRGB, 8)
    light = np.concatenate([points, np.nextafter(points, np.float32(0)),
                            rng.random(4096 - 2 * points.size, dtype=np.float32)])
    exact = count_at_or_below(light, points)
    guess = exact + rng.choice([-300, -40, -2, -1, 0, 0, 0, 1, 2, 40, 300], light.size)
    probes = np.stack([light, guess.astype(np.float32)], axis=-1).reshape(64, 64, 2)
    source = shader_source("output_count.comp", directory=Path(__file__).parent / "glsl")
    program = ctx.compute_shader(source.text)
    tables, uniforms = table_texture(ctx, SRGB, 8)
    inputs = ctx.texture((64, 64), 2, probes.astype(np.float32).tobytes(), dtype="f4")
    counts = ctx.texture((64, 64), 1, dtype="u4")
    try:
        for name, value in {**uniforms, "u_bits": 8, "u_tables": 0}.items():
            if name in program:
                program[name].value = value
        tables.use(0)
        inputs.bind_to_image(0, read=True, write=False)
        counts.bind_to_image(1, read=False, write=True)
        program.run(8, 8)
        ctx.memory_barrier()
        got = np.frombuffer(counts.read(), np.uint32).reshape(-1)
    finally:
        for thing in (program, tables, inputs, counts):
            thing.release()
    np.testing.assert_array_equal(got, exact)


def rule_edges(transfer: Transfer, bits: int, width: int = 256) -> np.ndarray:
    """(H, width, 4) float32 frame of every decision point and the float just below it."""
    points = decision_points(transfer, bits)
    light = np.concatenate([points, np.nextafter(points, np.float32(0))])
    light = np.resize(light, -(-light.size // (4 * width)) * 4 * width)
    return light.reshape(-1, width, 4)


@pytest.mark.parametrize("bits", (8, 16))
@pytest.mark.parametrize("transfer", (LINEAR, SRGB, GAMMA), ids=str)
def test_gpu_codes_are_the_rule_at_every_decision_point(output_passes, transfer, bits):
    frame = rule_edges(transfer, bits)
    codes = output_passes["egl"].apply(frame, OutputSettings(transfer=transfer, bits=bits,
                                                             format="png16"))
    np.testing.assert_array_equal(codes[..., :3], code_of(frame[..., :3], transfer, bits))
    np.testing.assert_array_equal(codes[..., 3], code_of(frame[..., 3], LINEAR, bits))


@pytest.fixture(scope="module")
def sphere_frame(gl_contexts):
    with GpuRenderer(load_scene("sphere"), 64, 48, context=gl_contexts["egl"]) as gpu:
        return gpu.render(linear=True, depth=False)


def test_linear_8_bit_codes_are_the_framebuffers_rgba8(output_passes, sphere_frame):
    """The stage's baseline is GL's own conversion: on a rendered frame's linear colour, both
    twins give back the rgba8 that GL wrote (alpha: coverage 0 or 1 -> 0 or 255)."""
    settings = OutputSettings()                     # linear, png8: 8 bits, no dither
    expected = sphere_frame.rgba8.astype(np.uint16)
    assert 0 < (expected[..., 3] == 255).mean() < 1                   # sphere and background
    np.testing.assert_array_equal(output_passes["egl"].apply(sphere_frame.linear, settings), expected)
    np.testing.assert_array_equal(reference.output.apply(sphere_frame.linear, settings), expected)
