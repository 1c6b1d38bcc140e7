"""Array textures moderngl does not make, through GL's own entry points: DEPTH_COMPONENT32F 2D
array textures (the shadow maps' stacks, the hemicubes' depth) and framebuffers on one layer of
them or on all their layers at once (layered rendering: a geometry shader's gl_Layer picks the
layer; renderer/gpu/item_buffers.py).

moderngl's texture_array makes colour storage only, so a depth array is made as a float one
and re-specified through glTexImage3D, and checked to have become DEPTH_COMPONENT32F.
"""

from __future__ import annotations

import ctypes

import moderngl

from renderer.errors import ContextError
from renderer.gpu.context import gl_function

GL_TEXTURE_2D_ARRAY = 0x8C1A
GL_DEPTH_COMPONENT = 0x1902
GL_DEPTH_COMPONENT32F = 0x8CAC
GL_FLOAT = 0x1406
GL_TEXTURE_INTERNAL_FORMAT = 0x1003
GL_FRAMEBUFFER = 0x8D40
GL_FRAMEBUFFER_BINDING = 0x8CA6
GL_DEPTH_ATTACHMENT = 0x8D00
GL_COLOR_ATTACHMENT0 = 0x8CE0
GL_FRAMEBUFFER_COMPLETE = 0x8CD5
GL_NONE = 0


class ArrayTextureGL:
    """The GL entry points moderngl does not wrap for array textures and their framebuffers."""

    SIGNATURES = {
        "glBindTexture": (None, "u", "u"),
        "glTexImage3D": (None, "u", "i", "i", "i", "i", "i", "i", "u", "u", "p"),
        "glTexParameteri": (None, "u", "u", "i"),
        "glGetTexLevelParameteriv": (None, "u", "i", "u", "ip"),
        "glGetIntegerv": (None, "u", "ip"),
        "glGenFramebuffers": (None, "i", "up"),
        "glDeleteFramebuffers": (None, "i", "up"),
        "glBindFramebuffer": (None, "u", "u"),
        "glFramebufferTextureLayer": (None, "u", "u", "u", "i", "i"),
        "glFramebufferTexture": (None, "u", "u", "u", "i"),
        "glCheckFramebufferStatus": ("u", "u"),
        "glDrawBuffer": (None, "u"),
        "glReadBuffer": (None, "u"),
        "glClearBufferuiv": (None, "u", "i", "up"),
        "glClearBufferfv": (None, "u", "i", "fp"),
    }
    _TYPES = {"u": ctypes.c_uint, "i": ctypes.c_int, "p": ctypes.c_void_p,
              "ip": ctypes.POINTER(ctypes.c_int), "up": ctypes.POINTER(ctypes.c_uint),
              "fp": ctypes.POINTER(ctypes.c_float), None: None}

    def __init__(self, ctx: moderngl.Context, purpose: str):
        for name, (restype, *argtypes) in self.SIGNATURES.items():
            function = gl_function(ctx, name, self._TYPES[restype], *(self._TYPES[a] for a in argtypes))
            if function is None:
                raise ContextError(f"{purpose} need {name}, which this GL does not have")
            setattr(self, name[2:], function)


def make_depth_layers(ctx: moderngl.Context, gl: ArrayTextureGL, side: int, layers: int,
                      parameters: dict, what: str) -> moderngl.TextureArray:
    """A side x side x layers array texture re-specified as DEPTH_COMPONENT32F with the
    sampling state `parameters` (GL name -> value), or a ContextError naming `what` where GL
    cannot make it."""
    texture = ctx.texture_array((side, side, layers), 1, dtype="f4")
    value = ctypes.c_int(0)
    gl.BindTexture(GL_TEXTURE_2D_ARRAY, texture.glo)
    gl.TexImage3D(GL_TEXTURE_2D_ARRAY, 0, GL_DEPTH_COMPONENT32F, side, side, layers, 0,
                  GL_DEPTH_COMPONENT, GL_FLOAT, None)
    ctx.error                                               # clear any error it raised
    gl.GetTexLevelParameteriv(GL_TEXTURE_2D_ARRAY, 0, GL_TEXTURE_INTERNAL_FORMAT, ctypes.byref(value))
    for name, setting in parameters.items():
        gl.TexParameteri(GL_TEXTURE_2D_ARRAY, name, setting)
    gl.BindTexture(GL_TEXTURE_2D_ARRAY, 0)
    if value.value != GL_DEPTH_COMPONENT32F:
        texture.release()
        raise ContextError(f"this GL made {what} {hex(value.value)}, not "
                           f"DEPTH_COMPONENT32F ({side}x{side}, {layers} layers)")
    return texture


def layer_framebuffers(ctx: moderngl.Context, gl: ArrayTextureGL, texture, layers: int) -> list:
    """A depth-only framebuffer on each layer of `texture`: (GL name, moderngl's view of it);
    GL's framebuffer binding is left as it was."""
    bound = ctypes.c_int(0)
    gl.GetIntegerv(GL_FRAMEBUFFER_BINDING, ctypes.byref(bound))
    names = (ctypes.c_uint * layers)()
    gl.GenFramebuffers(layers, names)
    try:
        for layer, name in enumerate(names):
            gl.BindFramebuffer(GL_FRAMEBUFFER, name)
            gl.FramebufferTextureLayer(GL_FRAMEBUFFER, GL_DEPTH_ATTACHMENT, texture.glo, 0, layer)
            gl.DrawBuffer(GL_NONE)
            gl.ReadBuffer(GL_NONE)
            status = gl.CheckFramebufferStatus(GL_FRAMEBUFFER)
            if status != GL_FRAMEBUFFER_COMPLETE:
                gl.DeleteFramebuffers(layers, names)
                raise ContextError(f"a shadow map's framebuffer is not complete ({hex(status)})")
        return [(name, ctx.detect_framebuffer(name)) for name in names]
    finally:
        gl.BindFramebuffer(GL_FRAMEBUFFER, bound.value)


def layered_framebuffer(ctx: moderngl.Context, gl: ArrayTextureGL, colour, depth) -> tuple:
    """One framebuffer with every layer of the array textures `colour` (attachment 0) and
    `depth` attached (layered: a geometry shader's gl_Layer picks the layer a primitive goes
    to): (GL name, moderngl's view of it); GL's framebuffer binding is left as it was."""
    bound = ctypes.c_int(0)
    gl.GetIntegerv(GL_FRAMEBUFFER_BINDING, ctypes.byref(bound))
    name = ctypes.c_uint(0)
    gl.GenFramebuffers(1, ctypes.byref(name))
    try:
        gl.BindFramebuffer(GL_FRAMEBUFFER, name.value)
        gl.FramebufferTexture(GL_FRAMEBUFFER, GL_COLOR_ATTACHMENT0, colour.glo, 0)
        gl.FramebufferTexture(GL_FRAMEBUFFER, GL_DEPTH_ATTACHMENT, depth.glo, 0)
        gl.DrawBuffer(GL_COLOR_ATTACHMENT0)
        gl.ReadBuffer(GL_COLOR_ATTACHMENT0)
        status = gl.CheckFramebufferStatus(GL_FRAMEBUFFER)
        if status != GL_FRAMEBUFFER_COMPLETE:
            gl.DeleteFramebuffers(1, ctypes.byref(name))
            raise ContextError(f"a layered framebuffer is not complete ({hex(status)})")
        return name.value, ctx.detect_framebuffer(name.value)
    finally:
        gl.BindFramebuffer(GL_FRAMEBUFFER, bound.value)


def delete_framebuffers(gl: ArrayTextureGL, names) -> None:
    names = list(names)
    if names:
        array = (ctypes.c_uint * len(names))(*names)
        gl.DeleteFramebuffers(len(array), array)
