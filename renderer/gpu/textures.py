"""Textures on the GPU: each `Texture` uploaded once, one GL sampler object per `Sampler`.

    cache = TextureCache(ctx)                        # one per renderer (per context)
    texture, sampler = cache.get(material.texture)   # moderngl.Texture, moderngl.Sampler
    cache.bind(material.texture, unit)               # both on texture unit `unit`
    cache.release()

A `Texture` (renderer/core/textures.py) is uploaded the first time it is asked for, as an
RGBA8 2D texture with every level of `Texture.levels` (rows flipped: GL's row 0 is the image's
bottom), GL_TEXTURE_BASE_LEVEL 0 and GL_TEXTURE_MAX_LEVEL the last level, so that it is
mipmap complete and GL reads exactly the levels the twin (reference/sampler.py) reads; GL never
makes a level (glGenerateMipmap only allocates them here, and is overwritten). Textures are
keyed by identity, samplers by value (equal `Sampler`s share one GL sampler object).

A sampler object sets wrap S and T, the min and mag filters and the maximum anisotropy from
gl_rules (TEXTURE_WRAP_MODES, TEXTURE_FILTER_MODES); it overrides the texture's own sampling
state on the unit it is bound to. Min LOD and max LOD keep GL's defaults (-1000, 1000), which
keeps llvmpipe on its exact LOD path (no clamp after the log2).
"""

from __future__ import annotations

import ctypes

import moderngl
import numpy as np

from renderer.core import gl_rules
from renderer.core.textures import MaterialTexture, Sampler, Texture
from renderer.errors import ContextError
from renderer.gpu.context import activate, gl_function


class TextureCache:
    """GL textures and sampler objects of one context, made on first use (module docstring)."""

    def __init__(self, ctx: moderngl.Context):
        self.ctx = ctx
        self._textures: dict[int, tuple[Texture, moderngl.Texture]] = {}
        self._samplers: dict[Sampler, moderngl.Sampler] = {}
        self._sampler_parameter = None

    def get(self, material_texture: MaterialTexture) -> tuple[moderngl.Texture, moderngl.Sampler]:
        """The GL texture and sampler object for a material's texture."""
        return self.texture(material_texture.texture), self.sampler(material_texture.sampler)

    def bind(self, material_texture: MaterialTexture, unit: int) -> None:
        """Bind the texture and its sampler object to texture unit `unit`."""
        texture, sampler = self.get(material_texture)
        texture.use(unit)
        sampler.use(unit)

    def texture(self, texture: Texture) -> moderngl.Texture:
        """`texture` uploaded (once: the same object gives the same GL texture)."""
        key = id(texture)
        if key not in self._textures:    # the Texture is kept with it, so its id stays its own
            self._textures[key] = (texture, self._upload(texture))
        return self._textures[key][1]

    def sampler(self, sampler: Sampler) -> moderngl.Sampler:
        """The GL sampler object for `sampler` (one per distinct value)."""
        if sampler not in self._samplers:
            self._samplers[sampler] = self._make_sampler(sampler)
        return self._samplers[sampler]

    def release(self) -> None:
        """Release every GL texture and sampler object made; the cache can be used again."""
        for _, texture in self._textures.values():
            texture.release()
        for sampler in self._samplers.values():
            sampler.release()
        self._textures.clear()
        self._samplers.clear()

    # -- making them ---------------------------------------------------------------------------

    def _upload(self, texture: Texture) -> moderngl.Texture:
        activate(self.ctx)
        levels = [np.ascontiguousarray(np.asarray(level, dtype=np.uint8)[::-1]) for level in texture.levels]
        gl_texture = self.ctx.texture((texture.width, texture.height), 4, levels[0].tobytes(), alignment=1)
        # build_mipmaps allocates levels 1..last and sets BASE_LEVEL 0 and MAX_LEVEL last; its
        # generated texels are then replaced by ours.
        gl_texture.build_mipmaps(base=0, max_level=len(levels) - 1)
        for k, level in enumerate(levels[1:], start=1):
            gl_texture.write(level.tobytes(), level=k, alignment=1)
        return gl_texture

    def _make_sampler(self, sampler: Sampler) -> moderngl.Sampler:
        activate(self.ctx)
        gl_sampler = self.ctx.sampler(filter=gl_rules.TEXTURE_FILTER_MODES[sampler.filter],
                                      anisotropy=float(sampler.anisotropy))
        wrap = gl_rules.TEXTURE_WRAP_MODES[sampler.wrap]
        set_parameter = self._sampler_parameteri()
        # moderngl names only REPEAT and CLAMP_TO_EDGE; every wrap is set through GL, one rule.
        for axis in (gl_rules.GL_TEXTURE_WRAP_S, gl_rules.GL_TEXTURE_WRAP_T):
            set_parameter(gl_sampler._glo, axis, wrap)
        return gl_sampler

    def _sampler_parameteri(self):
        if self._sampler_parameter is None:
            self._sampler_parameter = gl_function(self.ctx, "glSamplerParameteri", None,
                                                  ctypes.c_uint, ctypes.c_uint, ctypes.c_int)
            if self._sampler_parameter is None:
                raise ContextError("this OpenGL context has no glSamplerParameteri (GL 3.3 has)")
        return self._sampler_parameter
