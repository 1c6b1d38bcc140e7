"""Test helpers for the shadow maps on llvmpipe (tests/test_shadow_lookup.py,
tests/test_shadow_depth.py): a DEPTH_COMPONENT32F texture and a DEPTH_COMPONENT32F 2D array
texture (moderngl makes neither: they are re-specified through glTexImage2D / glTexImage3D,
docs/llvmpipe/shadow-sampler.md section 1), and tests/glsl/shadow_lookup.frag run once
per input texel."""

import ctypes
from pathlib import Path

import numpy as np

from renderer.gpu.context import gl_function
from renderer.gpu.shaders import shader_source

GLSL = Path(__file__).parent / "glsl"
GL_TEXTURE_2D, GL_DEPTH_COMPONENT, GL_DEPTH_COMPONENT32F, GL_FLOAT = 0x0DE1, 0x1902, 0x8CAC, 0x1406
GL_TEXTURE_2D_ARRAY, GL_LINEAR, GL_CLAMP_TO_EDGE, GL_LEQUAL = 0x8C1A, 0x2601, 0x812F, 0x0203
GL_TEXTURE_MIN_FILTER, GL_TEXTURE_MAG_FILTER, GL_TEXTURE_WRAP_S, GL_TEXTURE_WRAP_T = 0x2801, 0x2800, 0x2802, 0x2803
GL_TEXTURE_COMPARE_MODE, GL_TEXTURE_COMPARE_FUNC, GL_COMPARE_REF_TO_TEXTURE = 0x884C, 0x884D, 0x884E


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


def depth32f_array_texture(ctx, maps: np.ndarray):
    """A DEPTH_COMPONENT32F GL_TEXTURE_2D_ARRAY holding maps (layers, S, S) float32 (GL rows),
    sampled as the design's u_*_shadow_maps: LINEAR, COMPARE_REF_TO_TEXTURE with LEQUAL,
    CLAMP_TO_EDGE."""
    layers, height, width = maps.shape
    texture = ctx.texture_array((width, height, layers), 1, dtype="f4")
    bind = gl_function(ctx, "glBindTexture", None, ctypes.c_uint, ctypes.c_uint)
    image = gl_function(ctx, "glTexImage3D", None, ctypes.c_uint, *([ctypes.c_int] * 6),
                        ctypes.c_uint, ctypes.c_uint, ctypes.c_void_p)
    parameter = gl_function(ctx, "glTexParameteri", None, ctypes.c_uint, ctypes.c_uint, ctypes.c_int)
    buffer = np.ascontiguousarray(maps, np.float32)
    bind(GL_TEXTURE_2D_ARRAY, texture.glo)
    image(GL_TEXTURE_2D_ARRAY, 0, GL_DEPTH_COMPONENT32F, width, height, layers, 0,
          GL_DEPTH_COMPONENT, GL_FLOAT, buffer.ctypes.data)
    for name, value in ((GL_TEXTURE_MIN_FILTER, GL_LINEAR), (GL_TEXTURE_MAG_FILTER, GL_LINEAR),
                        (GL_TEXTURE_WRAP_S, GL_CLAMP_TO_EDGE), (GL_TEXTURE_WRAP_T, GL_CLAMP_TO_EDGE),
                        (GL_TEXTURE_COMPARE_MODE, GL_COMPARE_REF_TO_TEXTURE),
                        (GL_TEXTURE_COMPARE_FUNC, GL_LEQUAL)):
        parameter(GL_TEXTURE_2D_ARRAY, name, value)
    bind(GL_TEXTURE_2D_ARRAY, 0)
    return texture


def run_lookup_shader(ctx, inputs: np.ndarray, mode: int, maps: np.ndarray | None = None,
                      layer: int = 0) -> np.ndarray:
    """out_value of tests/glsl/shadow_lookup.frag for each row of inputs (N, 4) -> (N, 4)
    float32; `maps` (layers, S, S) float32 is sampled as u_point_shadow_maps (LINEAR, LEQUAL, CLAMP),
    at `layer`."""
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
        if maps is not None:
            texture = depth32f_array_texture(ctx, maps)
            things.append(texture)
            texture.use(0)
            program["u_point_shadow_maps"].value = 0
            program["u_point_shadow_map_size"].value = float(maps.shape[1])
            program["u_layer"].value = float(layer)
        framebuffer.use()
        ctx.viewport = (0, 0, n, 1)
        vao.render(vertices=3)
        return np.frombuffer(output.read(), np.float32).reshape(n, 4)
    finally:
        for thing in things:
            thing.release()
