"""Test helpers for the shadow maps on llvmpipe (tests/test_shadow_lookup.py,
tests/test_shadow_depth.py): a DEPTH_COMPONENT32F texture (moderngl makes DEPTH_COMPONENT24;
it is re-specified through glTexImage2D, /work/notes/llvmpipe-shadow-sampler.md section 1), and
tests/glsl/shadow_lookup.frag run once per input texel."""

import ctypes
from pathlib import Path

import numpy as np

from renderer.gpu.context import gl_function
from renderer.gpu.shaders import shader_source

GLSL = Path(__file__).parent / "glsl"
GL_TEXTURE_2D, GL_DEPTH_COMPONENT, GL_DEPTH_COMPONENT32F, GL_FLOAT = 0x0DE1, 0x1902, 0x8CAC, 0x1406


def depth32f_texture(ctx, width: int, height: int, data: np.ndarray | None = None):
    """A DEPTH_COMPONENT32F texture (data: (height, width) float32, GL rows, or None)."""
    texture = ctx.depth_texture((width, height))
    bind = gl_function(ctx, "glBindTexture", None, ctypes.c_uint, ctypes.c_uint)
    image = gl_function(ctx, "glTexImage2D", None, ctypes.c_uint, *([ctypes.c_int] * 5),
                        ctypes.c_uint, ctypes.c_uint, ctypes.c_void_p)
    buffer = None if data is None else np.ascontiguousarray(data, np.float32)
    bind(GL_TEXTURE_2D, texture.glo)
    image(GL_TEXTURE_2D, 0, GL_DEPTH_COMPONENT32F, width, height, 0, GL_DEPTH_COMPONENT, GL_FLOAT,
          None if buffer is None else buffer.ctypes.data)
    bind(GL_TEXTURE_2D, 0)
    texture.repeat_x = texture.repeat_y = False          # CLAMP_TO_EDGE (moderngl: REPEAT)
    return texture


def run_lookup_shader(ctx, inputs: np.ndarray, mode: int, atlas: np.ndarray | None = None) -> np.ndarray:
    """out_value of tests/glsl/shadow_lookup.frag for each row of inputs (N, 4) -> (N, 4)
    float32; `atlas` (S, S) float32 is sampled as u_shadow_atlas (LINEAR, LEQUAL, CLAMP)."""
    from renderer.gpu.context import activate
    activate(ctx)
    n = len(inputs)
    program = ctx.program(vertex_shader=shader_source("fullscreen.vert", directory=GLSL).text,
                          fragment_shader=shader_source("shadow_lookup.frag", directory=GLSL).text)
    data = np.asarray(inputs, np.float32).reshape(1, n, 4)
    source = ctx.texture((n, 1), 4, data.tobytes(), dtype="f4")
    output = ctx.texture((n, 1), 4, dtype="f4")
    framebuffer = ctx.framebuffer([output])
    vao = ctx.vertex_array(program, [])
    things = [vao, framebuffer, program, source, output]
    try:
        source.filter = (ctx.NEAREST, ctx.NEAREST)
        source.use(1)
        program["u_inputs"].value = 1
        program["u_mode"].value = mode
        if atlas is not None:
            texture = depth32f_texture(ctx, atlas.shape[1], atlas.shape[0], atlas)
            things.append(texture)
            texture.filter = (ctx.LINEAR, ctx.LINEAR)
            texture.compare_func = "<="
            texture.use(0)
            program["u_shadow_atlas"].value = 0
            program["u_shadow_atlas_size"].value = float(atlas.shape[0])
        framebuffer.use()
        ctx.viewport = (0, 0, n, 1)
        vao.render(vertices=3)
        return np.frombuffer(output.read(), np.float32).reshape(n, 4)
    finally:
        for thing in things:
            thing.release()
