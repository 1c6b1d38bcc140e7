"""The shadow maps on the GPU: their array textures and the light-view depth pass that fills them.

    maps = ShadowMaps(ctx, layout)                  # once per GpuRenderer whose layout has maps
    maps.set_plan(plan, buffers, models)            # each update(): what each pass draws
    maps.draw()                                     # each frame, before the camera pass
    maps.bind()                                     # the maps on SHADOW_MAPS_UNITS for lighting

Every map is a layer of its light kind's DEPTH_COMPONENT32F 2D array texture (a stack:
`layout.stack(kind)`'s layers of its side; renderer/core/shadows.py), drawn from texel (0, 0): llvmpipe
evaluates a triangle's depth plane from the window origin in float32, so a map drawn at an
offset would store other depths. moderngl makes no depth array textures, so the storage is
re-specified through glTexImage3D (as make_float_depth does for renderbuffers), and each layer
gets a depth-only framebuffer through glFramebufferTextureLayer. The lighting programs read the
maps through GL's depth-compare sampler: LINEAR filtering, CLAMP_TO_EDGE, compare LEQUAL (a tap
is lit when its reference depth <= the stored one).

Each pass (ShadowPass) draws its casters with glsl/shadow/depth.vert and depth.frag into its
layer: the viewport at (0, 0), R x R (the map's resolution), that square alone (scissored)
cleared to depth 1, GL_LESS, no culling, filled triangles, depth only, and GL's standard depth
mapping (z_w = (z_ndc + 1) / 2): draw() expects glClipControl at GL's default, which GpuRenderer
leaves behind after every frame, and must run before a reversed-Z camera pass sets its own.
The vertex arrays reuse the renderer's vertex and index buffers (positions only);
u_clip_from_model is each pass's clip_from_world times the object's camera-relative model
matrix, composed in float64 once per set_plan(), so that a frame only uploads bytes and draws.
"""

from __future__ import annotations


import moderngl
import numpy as np

from renderer.core.gl_rules import STANDARD_DEPTH
from renderer.core.shadows import SHADOW_KINDS, ShadowLayout, ShadowPlan
from renderer.core.transforms import to_glsl
from renderer.gpu.array_textures import (ArrayTextureGL, delete_framebuffers, layer_framebuffers,
                                         make_depth_layers)
from renderer.gpu.polygon_buffers import PolygonBuffers
from renderer.gpu.shaders import shader_source
from renderer.gpu.uniforms import SHADOW_MAPS_UNITS

GL_TEXTURE_PARAMETERS = {               # name -> value, as the lookup needs them
    0x2801: 0x2601,                     # MIN_FILTER: LINEAR (one level, no mipmaps)
    0x2800: 0x2601,                     # MAG_FILTER: LINEAR
    0x2802: 0x812F,                     # WRAP_S: CLAMP_TO_EDGE
    0x2803: 0x812F,                     # WRAP_T: CLAMP_TO_EDGE
    0x813D: 0,                          # MAX_LEVEL: 0
    0x884C: 0x884E,                     # COMPARE_MODE: COMPARE_REF_TO_TEXTURE
    0x884D: 0x0203,                     # COMPARE_FUNC: LEQUAL
}


class ShadowMaps:
    """The maps' array textures (one per kind of light with maps), a framebuffer per layer and
    the depth pass of one GpuRenderer."""

    def __init__(self, ctx: moderngl.Context, layout: ShadowLayout):
        self.ctx = ctx
        self._gl = ArrayTextureGL(ctx, "shadow maps")
        self.layout: ShadowLayout | None = None
        # kind -> (array texture, per layer (GL name, moderngl view)) for the kinds with maps
        self._stacks: dict[str, tuple[moderngl.TextureArray, list]] = {}
        self.program = ctx.program(vertex_shader=shader_source("shadow/depth.vert").text,
                                   fragment_shader=shader_source("shadow/depth.frag").text)
        self._clip_from_model = self.program["u_clip_from_model"]
        self._vertex_arrays: dict[int, tuple[moderngl.Buffer, moderngl.VertexArray]] = {}
        self._polygon_slots: dict[tuple, tuple] = {}     # (pass, plane) -> (PolygonBuffers, vao)
        self._passes: list = []                          # (framebuffer, R, [(vao, bytes)])
        self.plan: ShadowPlan | None = None
        self.set_layout(layout)

    def set_layout(self, layout: ShadowLayout) -> None:
        """Use `layout` from now on; a stack's texture is made again only when its size changes."""
        for kind in SHADOW_KINDS:
            stack = layout.stack(kind)
            before = None if self.layout is None else self.layout.stack(kind)
            if kind in self._stacks and stack == before:
                continue
            self._release_stack(kind)
            if stack.layers:
                texture = make_depth_layers(self.ctx, self._gl, stack.side, stack.layers,
                                            GL_TEXTURE_PARAMETERS, "the shadow maps")
                self._stacks[kind] = (texture, layer_framebuffers(self.ctx, self._gl, texture, stack.layers))
        self.layout = layout
        self.plan, self._passes = None, []

    def set_plan(self, plan: ShadowPlan, buffers: list, models: list) -> None:
        """What draw() draws: each pass of `plan` with its casters. `buffers[i]` is object i's
        (vertex buffer, index buffer) (positions then normals, float32; faces uint32) and
        `models[i]` its camera-relative model matrix (float64)."""
        self.plan, self._passes = plan, []
        for k, shadow_pass in enumerate(plan.passes):
            tile = shadow_pass.tile
            draws = []
            for i in shadow_pass.casters:
                if i in shadow_pass.polygons:       # an analytic plane: its polygon in this pass
                    vao = self._polygon_array((k, i), shadow_pass.polygons[i])
                    draws.append((vao, to_glsl(np.asarray(shadow_pass.clip_from_world, np.float64)),
                                  3 * shadow_pass.polygons[i].triangle_count))
                else:
                    draws.append((self._vertex_array(i, *buffers[i]),
                                  to_glsl(shadow_pass.clip_from_world @ np.asarray(models[i], dtype=np.float64)),
                                  -1))
            framebuffer = self._stacks[shadow_pass.kind][1][tile.layer][1]
            self._passes.append((framebuffer, tile.size, draws))

    def _polygon_array(self, slot: tuple, polygon) -> moderngl.VertexArray:
        """The vertex array of a plane's polygon in a pass (`slot`: the pass's place in the
        plan and the plane's object index): buffers made the first time the slot is used, at
        the largest polygon's size (renderer/gpu/polygon_buffers.py), written with this plan's
        polygon."""
        made = self._polygon_slots.get(slot)
        if made is None:
            buffers = PolygonBuffers.make(self.ctx, uvs=False)
            vao = self.ctx.vertex_array(self.program, [(buffers.vbo, "3f 3x4", "in_position")],
                                        index_buffer=buffers.ibo, index_element_size=4)
            made = self._polygon_slots[slot] = (buffers, vao)
        buffers, vao = made
        buffers.write(polygon)
        return vao

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

    def texture(self, kind: str) -> moderngl.TextureArray | None:
        """Kind `kind`'s array texture (None where the layout has no map of that kind)."""
        made = self._stacks.get(kind)
        return None if made is None else made[0]

    def framebuffers(self, kind: str) -> list[moderngl.Framebuffer]:
        """Per layer of kind `kind`'s stack, its depth-only framebuffer
        (benchmarks/bench_shadows.py's bare program draws into the same storage)."""
        return [view for _name, view in self._stacks.get(kind, (None, []))[1]]

    @property
    def vertex_arrays(self) -> dict:
        """Object index -> its depth-pass vertex array, for those drawn so far."""
        return {index: vao for index, (_vbo, vao) in self._vertex_arrays.items()}

    def draw(self) -> None:
        """Draw every pass of the plan into its layer (GL's default clip control expected)."""
        ctx = self.ctx
        for framebuffer, size, draws in self._passes:
            framebuffer.use()
            ctx.viewport = (0, 0, size, size)               # the map, from texel (0, 0)
            framebuffer.clear(depth=STANDARD_DEPTH.clear_depth, viewport=(0, 0, size, size))
            ctx.enable_only(moderngl.DEPTH_TEST)            # no culling: both sides cast
            ctx.depth_func = STANDARD_DEPTH.depth_func      # GL_LESS
            ctx.wireframe = False                           # a viewer's wireframe is the camera's
            for vao, clip_from_model, count in draws:
                self._clip_from_model.write(clip_from_model)
                vao.render(moderngl.TRIANGLES, vertices=count)

    def bind(self) -> None:
        """Each stack on its SHADOW_MAPS_UNITS unit, where the lighting programs'
        u_directional_shadow_maps and u_point_shadow_maps read."""
        for kind, (texture, _framebuffers) in self._stacks.items():
            texture.use(SHADOW_MAPS_UNITS[kind])

    def read_layer(self, kind: str, layer: int) -> np.ndarray:
        """Layer `layer` of kind `kind`'s stack: its depths, float32 (S, S), GL rows (row 0 at
        the bottom): for tests and the viewer's map view (renderer/viewer/shadow_view.py)."""
        side = self.layout.stack(kind).side
        data = self._stacks[kind][1][layer][1].read(viewport=(0, 0, side, side), attachment=-1,
                                                   components=1, dtype="f4")
        return np.frombuffer(data, dtype=np.float32).reshape(side, side).copy()

    def _release_stack(self, kind: str) -> None:
        texture, framebuffers = self._stacks.pop(kind, (None, []))
        if framebuffers:
            delete_framebuffers(self._gl, (n for n, _ in framebuffers))
        if texture is not None:
            texture.release()

    def release(self) -> None:
        for _vbo, vao in self._vertex_arrays.values():
            vao.release()
        for buffers, vao in self._polygon_slots.values():
            vao.release()
            buffers.release()
        self._vertex_arrays, self._passes, self._polygon_slots = {}, [], {}
        for kind in SHADOW_KINDS:
            self._release_stack(kind)
        self.program.release()
