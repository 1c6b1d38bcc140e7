"""Arrays as the RGBA32F textures the ray tracer's GLSL reads (`texel_texture`: texel k at
(k % width, k // width), the width a power of two, `renderer.core.bvh.texels`); a BVH
(renderer/core/bvh.py) as its two, entries and triangles, in the layout glsl/raytrace/bvh.glsl
walks (renderer/core/bvh.py's Walk)."""

from __future__ import annotations

import moderngl
import numpy as np

from renderer.core.bvh import Bvh, texels, walk_layout


def texel_texture(ctx: moderngl.Context, array) -> moderngl.Texture:
    """`array`'s rows of 4 floats (texels) as a nearest-filtered, unrepeated RGBA32F texture
    (RGBA32UI for a uint32 array)."""
    data = texels(array)
    texture = ctx.texture((data.shape[1], data.shape[0]), 4, data.tobytes(),
                          dtype="u4" if data.dtype == np.uint32 else "f4")
    texture.filter = (ctx.NEAREST, ctx.NEAREST)
    texture.repeat_x = texture.repeat_y = False
    return texture


def bvh_textures(ctx: moderngl.Context, bvh: Bvh) -> tuple[moderngl.Texture, moderngl.Texture]:
    """(entries, triangles) textures of `bvh` (a BVH or a forest); the caller releases them."""
    walk = walk_layout(bvh)
    return texel_texture(ctx, walk.entries), texel_texture(ctx, walk.triangles)
