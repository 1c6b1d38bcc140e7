"""An analytic plane's polygon on the GPU (renderer/core/drawn.py, renderer/core/plane_clip.py):
buffers made once at the largest polygon's size (MAX_POLYGON_VERTICES vertices,
MAX_POLYGON_TRIANGLES triangles) and written again with each plan's polygon, for the camera
pass (renderer/gpu/pipeline.py, with texture coordinates) and for each shadow pass that draws
the plane (renderer/gpu/shadow_maps.py). `vertex_bytes` is the vertex layout both draw from."""

from __future__ import annotations

from dataclasses import dataclass

import moderngl
import numpy as np

from renderer.core.plane_clip import MAX_POLYGON_TRIANGLES, MAX_POLYGON_VERTICES
from renderer.core.scene import Mesh


def vertex_bytes(mesh: Mesh) -> bytes:
    """in_position, in_normal of each vertex: float32, interleaved."""
    return np.ascontiguousarray(np.hstack([mesh.positions, mesh.normals]), dtype=np.float32).tobytes()


@dataclass
class PolygonBuffers:
    """One polygon's buffers, of which `count` indices are drawn (0: the plane misses the view)."""
    vbo: moderngl.Buffer                   # in_position, in_normal: float32, interleaved
    ibo: moderngl.Buffer                   # faces, uint32
    uv_vbo: moderngl.Buffer | None = None  # in_uv, float32 (the camera pass's)
    count: int = 0

    @classmethod
    def make(cls, ctx: moderngl.Context, uvs: bool) -> "PolygonBuffers":
        return cls(ctx.buffer(reserve=MAX_POLYGON_VERTICES * 6 * 4),
                   ctx.buffer(reserve=MAX_POLYGON_TRIANGLES * 3 * 4),
                   ctx.buffer(reserve=MAX_POLYGON_VERTICES * 2 * 4) if uvs else None)

    def write(self, mesh: Mesh) -> None:
        if mesh.triangle_count:
            self.vbo.write(vertex_bytes(mesh))
            self.ibo.write(np.ascontiguousarray(mesh.faces, dtype=np.uint32).tobytes())
            if self.uv_vbo is not None:
                self.uv_vbo.write(np.ascontiguousarray(mesh.uvs, dtype=np.float32).tobytes())
        self.count = 3 * mesh.triangle_count

    def release(self) -> None:
        for buffer in (self.vbo, self.ibo, self.uv_vbo):
            if buffer is not None:
                buffer.release()
