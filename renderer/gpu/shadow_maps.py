"""The shadow maps on the GPU: the atlas texture and the light-view depth pass that fills it.

    maps = ShadowMaps(ctx, layout)                  # once per GpuRenderer whose layout has maps
    maps.set_plan(plan, buffers, models)            # each update(): what each pass draws
    maps.draw()                                     # each frame, before the camera pass
    maps.bind()                                     # the atlas on SHADOW_ATLAS_UNIT for lighting

The atlas is one DEPTH_COMPONENT32F texture, `layout.atlas_side` texels on a side, holding every
map of the scene as a square tile (renderer/core/shadows.py). moderngl only makes 24-bit depth
textures, so the storage is re-specified through glTexImage2D as make_float_depth does for
renderbuffers. The lighting programs read it through GL's depth-compare sampler: LINEAR
filtering, CLAMP_TO_EDGE, compare LEQUAL (a tap is lit when its reference depth <= stored).

Each pass (ShadowPass) draws its casters with glsl/shadow/depth.vert and depth.frag into its
tile: the viewport on the tile, the tile alone (scissored) cleared to depth 1, GL_LESS, no
culling, filled triangles, depth only, and GL's standard depth mapping (z_w = (z_ndc + 1) / 2):
draw() expects glClipControl at GL's default, which GpuRenderer leaves behind after every
frame, and must run before a reversed-Z camera pass sets its own. The vertex arrays reuse the
renderer's vertex and index buffers (positions only); u_clip_from_model is each pass's
clip_from_world times the object's camera-relative model matrix, composed in float64 once per
set_plan(), so that a frame only uploads bytes and draws.
"""

from __future__ import annotations

import ctypes

import moderngl
import numpy as np

from renderer.core.gl_rules import STANDARD_DEPTH
from renderer.core.shadows import ShadowLayout, ShadowPlan
from renderer.core.transforms import to_glsl
from renderer.errors import ContextError
from renderer.gpu.context import gl_function
from renderer.gpu.shaders import shader_source
from renderer.gpu.uniforms import SHADOW_ATLAS_UNIT

GL_TEXTURE_2D = 0x0DE1
GL_DEPTH_COMPONENT = 0x1902
GL_DEPTH_COMPONENT32F = 0x8CAC
GL_FLOAT = 0x1406
GL_TEXTURE_INTERNAL_FORMAT = 0x1003


def make_float_depth_texture(ctx: moderngl.Context, side: int) -> moderngl.Texture:
    """A side x side depth texture re-specified as DEPTH_COMPONENT32F (a ContextError where
    GL cannot): the atlas's storage."""
    texture = ctx.depth_texture((side, side))
    c_uint, c_int = ctypes.c_uint, ctypes.c_int
    bind = gl_function(ctx, "glBindTexture", None, c_uint, c_uint)
    image = gl_function(ctx, "glTexImage2D", None, c_uint, c_int, c_int, c_int, c_int, c_int,
                        c_uint, c_uint, ctypes.c_void_p)
    query = gl_function(ctx, "glGetTexLevelParameteriv", None, c_uint, c_int, c_uint,
                        ctypes.POINTER(c_int))
    if bind is None or image is None or query is None:
        texture.release()
        raise ContextError("this GL has no glTexImage2D to make a DEPTH_COMPONENT32F shadow atlas")
    value = c_int(0)
    bind(GL_TEXTURE_2D, texture.glo)
    image(GL_TEXTURE_2D, 0, GL_DEPTH_COMPONENT32F, side, side, 0, GL_DEPTH_COMPONENT, GL_FLOAT, None)
    ctx.error                                               # clear any error it raised
    query(GL_TEXTURE_2D, 0, GL_TEXTURE_INTERNAL_FORMAT, ctypes.byref(value))
    bind(GL_TEXTURE_2D, 0)
    if value.value != GL_DEPTH_COMPONENT32F:
        texture.release()
        raise ContextError(f"this GL made the shadow atlas {hex(value.value)}, not DEPTH_COMPONENT32F")
    texture.filter = (moderngl.LINEAR, moderngl.LINEAR)
    texture.repeat_x = texture.repeat_y = False            # CLAMP_TO_EDGE
    texture.compare_func = "<="                            # COMPARE_REF_TO_TEXTURE, LEQUAL
    return texture


class ShadowMaps:
    """The atlas, its depth-only framebuffer and the depth pass of one GpuRenderer."""

    def __init__(self, ctx: moderngl.Context, layout: ShadowLayout):
        self.ctx = ctx
        self.layout: ShadowLayout | None = None
        self.atlas: moderngl.Texture | None = None
        self.framebuffer: moderngl.Framebuffer | None = None
        self.program = ctx.program(vertex_shader=shader_source("shadow/depth.vert").text,
                                   fragment_shader=shader_source("shadow/depth.frag").text)
        self._clip_from_model = self.program["u_clip_from_model"]
        self._vertex_arrays: dict[int, tuple[moderngl.Buffer, moderngl.VertexArray]] = {}
        self._passes: list[tuple[tuple[int, int, int, int], list]] = []   # (viewport, [(vao, bytes)])
        self.plan: ShadowPlan | None = None
        self.set_layout(layout)

    def set_layout(self, layout: ShadowLayout) -> None:
        """Use `layout` from now on; the atlas is made again only when its side changes."""
        if self.atlas is None or layout.atlas_side != self.layout.atlas_side:
            self._release_atlas()
            self.atlas = make_float_depth_texture(self.ctx, layout.atlas_side)
            self.framebuffer = self.ctx.framebuffer(depth_attachment=self.atlas)
        self.layout = layout
        self.plan, self._passes = None, []

    def set_plan(self, plan: ShadowPlan, buffers: list, models: list) -> None:
        """What draw() draws: each pass of `plan` with its casters. `buffers[i]` is object i's
        (vertex buffer, index buffer) (positions then normals, float32; faces uint32) and
        `models[i]` its camera-relative model matrix (float64)."""
        self.plan, self._passes = plan, []
        for shadow_pass in plan.passes:
            tile = shadow_pass.tile
            draws = [(self._vertex_array(i, *buffers[i]),
                      to_glsl(shadow_pass.clip_from_world @ np.asarray(models[i], dtype=np.float64)))
                     for i in shadow_pass.casters]
            self._passes.append(((tile.x, tile.y, tile.size, tile.size), draws))

    def _vertex_array(self, index: int, vbo: moderngl.Buffer, ibo: moderngl.Buffer) -> moderngl.VertexArray:
        """Object `index`'s vertex array, made again when the renderer uploaded a new mesh."""
        made = self._vertex_arrays.get(index)
        if made is not None and made[0] is vbo:
            return made[1]
        if made is not None:
            made[1].release()
        vao = self.ctx.vertex_array(self.program, [(vbo, "3f 3x4", "in_position")],
                                    index_buffer=ibo, index_element_size=4)
        self._vertex_arrays[index] = (vbo, vao)
        return vao

    @property
    def vertex_arrays(self) -> dict:
        """Object index -> its depth-pass vertex array, for those drawn so far."""
        return {index: vao for index, (_vbo, vao) in self._vertex_arrays.items()}

    def draw(self) -> None:
        """Draw every pass of the plan into its tile (GL's default clip control expected)."""
        ctx = self.ctx
        self.framebuffer.use()
        ctx.enable_only(moderngl.DEPTH_TEST)                 # no culling: both sides cast
        ctx.depth_func = STANDARD_DEPTH.depth_func                        # GL_LESS
        ctx.wireframe = False                                # a viewer's wireframe is the camera's
        for viewport, draws in self._passes:
            ctx.viewport = viewport
            self.framebuffer.clear(depth=STANDARD_DEPTH.clear_depth, viewport=viewport)   # the tile alone
            for vao, clip_from_model in draws:
                self._clip_from_model.write(clip_from_model)
                vao.render(moderngl.TRIANGLES)

    def bind(self) -> None:
        """The atlas on SHADOW_ATLAS_UNIT, where the lighting programs' u_shadow_atlas reads."""
        self.atlas.use(SHADOW_ATLAS_UNIT)

    def read_atlas(self) -> np.ndarray:
        """The atlas's depths, float32 (S, S), GL rows (row 0 at the bottom): for tests."""
        side = self.layout.atlas_side
        return np.frombuffer(self.atlas.read(), dtype=np.float32).reshape(side, side).copy()

    def _release_atlas(self) -> None:
        for item in (self.framebuffer, self.atlas):
            if item is not None:
                item.release()
        self.framebuffer = self.atlas = None

    def release(self) -> None:
        for _vbo, vao in self._vertex_arrays.values():
            vao.release()
        self._vertex_arrays, self._passes = {}, []
        self._release_atlas()
        self.program.release()
