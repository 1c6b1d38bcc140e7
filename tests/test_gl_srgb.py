"""GL's own sRGB encoding, measured (renderer/core/gl_rules.py, "GL's sRGB framebuffer";
docs/llvmpipe/output.md): GL_FRAMEBUFFER_SRGB on an SRGB8_ALPHA8 target stores each RGB
channel within SRGB_FRAMEBUFFER_LEVELS (1) of the exactly rounded 8-bit sRGB code
(renderer/core/quantise.py), and alpha as plain unorm8. That one level is why the output
stage does not use it: it quantises by exact decision points, the same on any GL.

On llvmpipe (Mesa 22.3.6; this sweep, EGL and OSMesa alike) 384 of the 2,560 inputs of a
channel come back one level off (229 below, 155 above): 252 of the 510 at or just below a
decision point, 105 of the 1,500 evenly spread, 27 of the 541 random ones."""

import numpy as np
import pytest

from renderer.core.gl_rules import GL_FRAMEBUFFER_SRGB, GL_SRGB8_ALPHA8, SRGB_FRAMEBUFFER_LEVELS
from renderer.core.output_settings import Transfer
from renderer.core.quantise import code_of, decision_points
from renderer.gpu.context import activate
from renderer.gpu.shaders import shader_source
from glsl_harness import GLSL

SRGB, LINEAR = Transfer("srgb"), Transfer("linear")
SIZE = (64, 40)                              # (W, H): 2,560 inputs a channel


def sweep() -> np.ndarray:
    """Each 8-bit sRGB decision point and the float below it (where rounding is hardest),
    evenly spread values over [0, 1], values GL clamps (negative, above 1, inf, NaN), and
    seeded random ones to fill the image."""
    points = decision_points(SRGB, 8)
    values = np.concatenate([points, np.nextafter(points, np.float32(0)),
                             np.linspace(0, 1, 1500, dtype=np.float32),
                             np.array([-1, -0.0, 0, 1e-45, 1, 1.5, np.inf, -np.inf, np.nan], np.float32)])
    rest = np.random.default_rng(18).random(SIZE[0] * SIZE[1] - values.size, dtype=np.float32)
    return np.concatenate([values, rest])


def gl_srgb_framebuffer(ctx, linear: np.ndarray) -> np.ndarray:
    """(H, W, 4) float32 -> the uint8 RGBA that GL's sRGB framebuffer stores for it (array row
    r is texel row r both ways: no flip)."""
    activate(ctx)
    height, width, _ = linear.shape
    program = ctx.program(vertex_shader=shader_source("fullscreen.vert", directory=GLSL).text,
                          fragment_shader=shader_source("srgb_encode.frag", directory=GLSL).text)
    source = ctx.texture((width, height), 4, np.ascontiguousarray(linear).tobytes(), dtype="f4")
    target = ctx.texture((width, height), 4, internal_format=GL_SRGB8_ALPHA8)  # a renderbuffer would not encode
    framebuffer = ctx.framebuffer([target])
    vao = ctx.vertex_array(program, [])
    try:
        framebuffer.use()
        source.use(0)
        ctx.enable_direct(GL_FRAMEBUFFER_SRGB)
        vao.render(vertices=3)
        return np.frombuffer(target.read(), np.uint8).reshape(height, width, 4)
    finally:
        ctx.disable_direct(GL_FRAMEBUFFER_SRGB)              # the contexts are shared by the run
        for thing in (vao, framebuffer, target, source, program):
            thing.release()


@pytest.mark.parametrize("kind", ["egl", "osmesa"])
def test_gls_srgb_framebuffer_is_within_a_level_of_the_exact_codes(kind, gl_contexts):
    values = sweep()
    linear = np.stack([values, values[::-1], np.roll(values, 1000), np.roll(values, 500)], -1)
    linear = linear.reshape(SIZE[1], SIZE[0], 4)
    stored = gl_srgb_framebuffer(gl_contexts[kind], linear).astype(np.int64)
    exact = code_of(linear[..., :3], SRGB, 8)
    off = np.abs(stored[..., :3] - exact)
    assert off.max() <= SRGB_FRAMEBUFFER_LEVELS, f"{np.count_nonzero(off > SRGB_FRAMEBUFFER_LEVELS)} inputs"
    # Alpha is stored as plain unorm8, not encoded (0.2 would be 124 encoded, 51 plain).
    assert np.abs(stored[..., 3] - code_of(linear[..., 3], LINEAR, 8)).max() <= SRGB_FRAMEBUFFER_LEVELS
