"""What every renderer offers (the Renderer protocol), and the GL context's lifetime that the
GPU's renderers share (ContextRenderer: renderer/gpu/pipeline.py's GpuRenderer,
renderer/gpu/raytracer.py's RayTracer).

    renderer = open_renderer(scene, (640, 480), method="raytrace")   # renderer/methods
    with renderer:
        frame = renderer.render()                   # Frame: rgba8, linear, depth, row 0 at the top
        renderer.scene.camera = moved               # or renderer.update(other_scene)
        renderer.update()
        renderer.render(out=frame)                  # into the arrays of the frame before

A renderer made without a context makes its own (EGL, else OSMesa) and releases it with
itself; one made on a given context (a window's, a batch worker's) frees only its GL objects.
"""

from __future__ import annotations

from typing import Protocol, runtime_checkable

import moderngl

from renderer.core.frame import Frame
from renderer.core.scene import Scene
from renderer.gpu.context import activate, context_kind, make_context, release_context


@runtime_checkable
class Renderer(Protocol):
    """One scene at one size, by one method on one backend (renderer/methods: open_renderer).

    render(out=None, *, linear=False, depth=True) -> Frame: rgba8 always; the linear colour
    (unclamped, alpha the coverage) and the depth (view depth, docs/conventions.md) when asked
    (a method that computes them anyway returns them always). `out`, an earlier frame of the
    same renderer, has its arrays written instead of new ones (a loop over many frames).
    `progress(rows done, rows)` is called as the frame advances (the GPU ray tracer's bands),
    and at least once when it is done.
    update(scene=None): take the scene again after its camera, lights or materials changed
    in place, or `scene`, another Scene of the same objects; resize(width, height);
    release() (idempotent), and the context manager that calls it; gl_info: what drew it."""
    scene: Scene
    width: int
    height: int

    def render(self, out: Frame | None = None, *, linear: bool = False,
               depth: bool = True, progress=None) -> Frame: ...

    def update(self, scene: Scene | None = None) -> None: ...

    def resize(self, width: int, height: int) -> None: ...

    def release(self) -> None: ...

    @property
    def gl_info(self) -> dict: ...

    def __enter__(self): ...

    def __exit__(self, *exc) -> None: ...


class ContextRenderer:
    """The context lifetime of a GPU renderer: `_open_context` in the constructor, `_free`
    (the subclass's GL objects) called once by release(), which then releases the context if
    this renderer made it. The subclass sets `_gl_info` once its context is known."""

    ctx: moderngl.Context
    _gl_info: dict

    def _open_context(self, context: moderngl.Context | None, kind: str) -> None:
        self._owns_context = context is None
        self._released = False
        self.ctx = make_context(kind) if context is None else context

    def _free(self) -> None:
        """Free this renderer's GL objects (its context is current)."""
        raise NotImplementedError

    def _context_info(self) -> dict:
        """What every frame's gl_info starts from: GL_VENDOR, GL_RENDERER, GL_VERSION and the
        context kind."""
        info = self.ctx.info
        return {key: info[key] for key in ("GL_VENDOR", "GL_RENDERER", "GL_VERSION")} | {
            "context": context_kind(self.ctx)}

    def _check_alive(self) -> None:
        if self._released:
            raise RuntimeError(f"this {type(self).__name__} was released")

    def release(self) -> None:
        """Free every GL object; the context too if this renderer made it. Idempotent."""
        if self._released:
            return
        self._released = True
        try:
            activate(self.ctx)
            self._free()
        finally:
            if self._owns_context:
                release_context(self.ctx)

    @property
    def gl_info(self) -> dict:
        """GL_VENDOR, GL_RENDERER, GL_VERSION and the context kind ("egl", "osmesa", or
        "external" for a context passed in), asked once when the renderer was made; every
        frame it renders carries the same dict."""
        return dict(self._gl_info)

    @property
    def subpixel_bits(self) -> int:
        """GL_SUBPIXEL_BITS of this renderer's context: vertices snap to 1 / 2^bits of a pixel
        (8 on llvmpipe); the reference rasteriser is told it (ReferenceRaster)."""
        return int(self.ctx.info["GL_SUBPIXEL_BITS"])

    def __enter__(self):
        return self

    def __exit__(self, *exc) -> None:
        self.release()

    def __repr__(self) -> str:
        state = "released" if self._released else context_kind(self.ctx)
        return f"<{type(self).__name__} {self.scene.name!r} {self.width}x{self.height} {state}>"
