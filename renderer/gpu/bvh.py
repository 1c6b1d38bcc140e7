"""A BVH (renderer/core/bvh.py) as the two RGBA32F textures glsl/raytrace/bvh.glsl reads:
nodes and triangles, texel k at (k % width, k // width), the width a power of two
(`renderer.core.bvh.texels`)."""

from __future__ import annotations

import moderngl

from renderer.core.bvh import Bvh, texels


def _texture(ctx: moderngl.Context, array) -> moderngl.Texture:
    data = texels(array)
    texture = ctx.texture((data.shape[1], data.shape[0]), 4, data.tobytes(), dtype="f4")
    texture.filter = (ctx.NEAREST, ctx.NEAREST)
    texture.repeat_x = texture.repeat_y = False
    return texture


def bvh_textures(ctx: moderngl.Context, bvh: Bvh) -> tuple[moderngl.Texture, moderngl.Texture]:
    """(nodes, triangles) textures; the caller releases them."""
    return _texture(ctx, bvh.nodes), _texture(ctx, bvh.triangles)
