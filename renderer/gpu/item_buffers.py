"""Radiosity's item buffers on the GPU (issue 33): which element each pixel of each hemicube
face sees, drawn by GL's rasteriser with glsl/radiosity/item_buffer.vert, .geom and .frag.

    buffers = ItemBuffers(ctx, elements, resolution)
    items = buffers.draw(indices)          # (len(indices), 5, N, N) uint32, row 0 at the top
    light = buffers.views(matrices)        # (F, N, N): whole views, a light's (light_buffers.py)

The elements' triangles sit in one vertex buffer (float32, relative to the elements' centre),
uploaded once. A batch of hemicubes is one instanced draw: an instance per face of each
hemicube of the batch, its matrix read from a texture, a geometry shader sending each triangle
to the face's layer of an R32UI array texture (and of a DEPTH_COMPONENT32F one), each layer
N x N drawn from texel (0, 0) as the twin draws it (llvmpipe evaluates depth from the window
origin). Reversed-Z (glClipControl ZERO_TO_ONE, cleared to 0, GL_GREATER: hemicube.DEPTH_MAPPING),
no culling (a back face seen hides what is behind it), the items cleared to 0 with
glClearBufferuiv (glClear's float colour is undefined on an integer buffer). GL's clip control,
depth function and depth test are left at their defaults after every draw (a context shared
with other renderers, as GpuRenderer expects it).

Twin: reference/radiosity/item_buffer.py.
"""

from __future__ import annotations

import ctypes

import moderngl
import numpy as np

from renderer.core.gl_rules import GL_LOWER_LEFT, STANDARD_DEPTH
from renderer.core.hemicube import DEPTH_MAPPING, FACES, clip_from_world, depth_range
from renderer.core.radiosity_elements import Elements
from renderer.gpu.array_textures import (ArrayTextureGL, delete_framebuffers, layered_framebuffer,
                                         make_depth_layers)
from renderer.gpu.context import activate, gl_function
from renderer.gpu.shaders import shader_source
from renderer.errors import ContextError

GL_COLOR, GL_DEPTH = 0x1800, 0x1801
NEAREST = {0x2801: 0x2600, 0x2800: 0x2600}        # MIN_FILTER, MAG_FILTER: NEAREST
# The batch's two array textures (4 bytes a pixel each) stay under this; and its matrices'
# texture under GL's 16384-texel width (llvmpipe's largest).
BATCH_BYTES = 64 << 20
MAX_BATCH = 16384 // (4 * len(FACES))


def batch_size(resolution: int, count: int, most: int = MAX_BATCH) -> int:
    """Hemicubes drawn at once: as many as BATCH_BYTES holds, at least one, at most `count`,
    MAX_BATCH and `most` (GL's array layers over five)."""
    per_hemicube = 8 * len(FACES) * resolution * resolution
    return max(1, min(count, MAX_BATCH, most, BATCH_BYTES // per_hemicube))


class ItemBuffers:
    """The GL objects that draw `elements`' hemicubes at `resolution` (even) on `ctx`."""

    def __init__(self, ctx: moderngl.Context, elements: Elements, resolution: int):
        activate(ctx)
        self.ctx, self.elements, self.resolution = ctx, elements, int(resolution)
        self.origin, diameter = elements.extent()
        self._frames, self._centres = elements.frames(), elements.centres      # once, not per batch
        self.near, self.far = depth_range(elements.shortest_edge(), diameter)
        self.batch = batch_size(self.resolution, len(elements),
                                ctx.info["GL_MAX_ARRAY_TEXTURE_LAYERS"] // len(FACES))
        self._gl = ArrayTextureGL(ctx, "radiosity's item buffers")
        self._clip_control = gl_function(ctx, "glClipControl", None, ctypes.c_uint, ctypes.c_uint)
        if self._clip_control is None:
            raise ContextError("radiosity's item buffers need glClipControl (OpenGL 4.5 or "
                               "ARB_clip_control), which this GL does not have")
        self._objects = []
        try:
            self.program = ctx.program(
                vertex_shader=shader_source("radiosity/item_buffer.vert").text,
                geometry_shader=shader_source("radiosity/item_buffer.geom").text,
                fragment_shader=shader_source("radiosity/item_buffer.frag").text)
            positions = (elements.corners - self.origin).astype(np.float32).reshape(-1, 3)
            self.vbo = ctx.buffer(positions.tobytes())
            self.vao = ctx.vertex_array(self.program, [(self.vbo, "3f", "in_position")])
            layers, n = len(FACES) * self.batch, self.resolution
            self.matrices = ctx.texture((4 * layers, 1), 4, dtype="f4")
            self.matrices.filter = (moderngl.NEAREST, moderngl.NEAREST)
            self.items = ctx.texture_array((n, n, layers), 1, dtype="u4")
            self.depth = make_depth_layers(ctx, self._gl, n, layers, NEAREST, "the item buffers' depth")
            self._objects = [self.program, self.vbo, self.vao, self.matrices, self.items, self.depth]
            self._framebuffer_name, self.framebuffer = layered_framebuffer(ctx, self._gl, self.items, self.depth)
            self.program["u_clip_from_world"].value = 0
        except BaseException:
            self.release()
            raise

    def matrices_of(self, indices: np.ndarray) -> np.ndarray:
        """(len(indices), 5, 4, 4) float64: the clip_from_world of each face of those hemicubes."""
        return clip_from_world(self._frames[indices], self._centres[indices], self.origin, self.near, self.far)

    def draw(self, indices) -> np.ndarray:
        """The item buffers of the hemicubes on elements `indices` (at most `batch` of them):
        (len, 5, N, N) uint32, faces in FACES' order, row 0 at the top of each face."""
        indices = np.asarray(indices, np.int64)
        count, n = len(indices), self.resolution
        if not 0 < count <= self.batch:
            raise ValueError(f"draw takes 1 to {self.batch} hemicubes, got {count}")
        layers = self._draw_layers(self.matrices_of(indices).reshape(-1, 4, 4), horizon=n / 2)
        return layers.reshape(count, len(FACES), n, n)

    def views(self, matrices) -> np.ndarray:
        """The item buffers of whole views (F, 4, 4) clip_from_world, relative to the elements'
        centre (a light's, renderer/core/light_buffers.py): (F, N, N) uint32, row 0 at the top;
        every row drawn (no horizon), as many layers at a time as the batch holds."""
        matrices = np.asarray(matrices, np.float64)
        layers = len(FACES) * self.batch
        return np.concatenate([self._draw_layers(matrices[s:s + layers], horizon=0.0)
                               for s in range(0, len(matrices), layers)])

    def _draw_layers(self, matrices: np.ndarray, horizon: float) -> np.ndarray:
        """(F, N, N): the elements through each of `matrices` (F, 4, 4), a layer each; on a side
        face of a hemicube (every layer but each fifth's first) rows below `horizon` drawn not."""
        n, ctx = self.resolution, self.ctx
        activate(ctx)
        faces = len(matrices)
        self.program["u_horizon"].value = horizon
        columns = np.swapaxes(matrices, -1, -2)                         # each matrix by columns
        self.matrices.write(columns.astype(np.float32).tobytes(), viewport=(0, 0, 4 * faces, 1))
        self.framebuffer.use()
        ctx.viewport = (0, 0, n, n)                   # every layer from texel (0, 0)
        self._gl.ClearBufferuiv(GL_COLOR, 0, (ctypes.c_uint * 4)(0, 0, 0, 0))
        self._gl.ClearBufferfv(GL_DEPTH, 0, (ctypes.c_float * 1)(DEPTH_MAPPING.clear_depth))
        ctx.enable_only(moderngl.DEPTH_TEST)          # no culling
        ctx.depth_func = DEPTH_MAPPING.depth_func
        ctx.wireframe = False
        self.matrices.use(0)
        self._clip_control(GL_LOWER_LEFT, DEPTH_MAPPING.clip_control)
        try:
            self.vao.render(moderngl.TRIANGLES, instances=faces)
        finally:                                      # GL's defaults back for whoever draws next
            self._clip_control(GL_LOWER_LEFT, STANDARD_DEPTH.clip_control)
            ctx.depth_func = STANDARD_DEPTH.depth_func
            ctx.disable(moderngl.DEPTH_TEST)
        data = np.frombuffer(self.items.read(), np.uint32)
        return data.reshape(-1, n, n)[:faces, ::-1].copy()              # GL rows to row 0 top

    def draw_all(self) -> list[np.ndarray]:
        """Every element's hemicube, batch by batch: a list of draw()'s arrays."""
        return [self.draw(np.arange(start, min(start + self.batch, len(self.elements))))
                for start in range(0, len(self.elements), self.batch)]

    def release(self) -> None:
        activate(self.ctx)
        if getattr(self, "_framebuffer_name", None):
            delete_framebuffers(self._gl, [self._framebuffer_name])
            self._framebuffer_name = None
        for item in reversed(self._objects):
            item.release()
        self._objects = []
