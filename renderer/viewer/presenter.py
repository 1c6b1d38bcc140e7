"""Showing frames in a window: double or triple buffering, and where each image goes.

The renderer draws into its own offscreen framebuffer (GpuRenderer.draw), exactly as it does
headless; the presenter copies framebuffers onto the window's back buffer with
glBlitFramebuffer and the window swaps. So the window shows the headless image, pixel for
pixel, when it is shown at its own size.

- Double buffering: frame N is drawn, copied to the back buffer and swapped in: it is on the
  screen after one swap.
- Triple buffering: a ring of three offscreen framebuffers. Frame N is drawn and copied into
  slot N mod 3 while the window shows slot N-1, the frame before: the image on the screen is
  never the one being written, at the price of one frame of latency. `latency_ms` measures
  it: from the start of drawing a frame to the swap that shows it. (The viewer's loop is one
  thread, so with v-sync on its swap still waits for the screen.)

Images the CPU makes (the reference view, the difference heat map, the help and figures
overlay) are uploaded to textures attached to framebuffers (`CpuImage`) and copied the same way.
GL's window origin is the bottom-left corner; every array handed in has row 0 at the top
(docs/conventions.md) and is flipped on upload.
"""

from __future__ import annotations

import collections
import ctypes
import statistics
import time

import moderngl
import numpy as np

from renderer.gpu.context import gl_function

GL_READ_FRAMEBUFFER = 0x8CA8
GL_DRAW_FRAMEBUFFER = 0x8CA9
GL_COLOR_BUFFER_BIT = 0x4000
GL_NEAREST = 0x2600
GL_LINEAR = 0x2601
BUFFERINGS = {2: "double", 3: "triple"}


def fit(image_size: tuple[int, int], region: tuple[int, int, int, int]) -> tuple[int, int, int, int]:
    """The largest rectangle (x0, y0, x1, y1) with the image's aspect ratio centred in
    `region` (x0, y0, x1, y1), in whole pixels: letterboxing, so no image is ever stretched."""
    width, height = image_size
    x0, y0, x1, y1 = region
    scale = min((x1 - x0) / width, (y1 - y0) / height)
    w, h = max(1, round(width * scale)), max(1, round(height * scale))
    left, bottom = x0 + (x1 - x0 - w) // 2, y0 + (y1 - y0 - h) // 2
    return left, bottom, left + w, bottom + h


class Blitter:
    """glBlitFramebuffer from one framebuffer to a rectangle of another (moderngl's
    copy_framebuffer copies only at the same size)."""

    def __init__(self, ctx: moderngl.Context):
        c_uint, c_int = ctypes.c_uint, ctypes.c_int
        self.ctx = ctx
        self._bind = gl_function(ctx, "glBindFramebuffer", None, c_uint, c_uint)
        self._blit = gl_function(ctx, "glBlitFramebuffer", None, *([c_int] * 8), c_uint, c_uint)
        if self._bind is None or self._blit is None:
            raise RuntimeError("this GL has no glBlitFramebuffer")

    def copy(self, source: moderngl.Framebuffer, target: moderngl.Framebuffer,
             rect: tuple[int, int, int, int] | None = None) -> None:
        """All of `source` into `rect` (x0, y0, x1, y1; GL window coordinates) of `target`,
        by default all of it; nearest-neighbour when the sizes match, linear otherwise."""
        sw, sh = source.size
        rect = rect or (0, 0, *target.size)
        same = (rect[2] - rect[0], rect[3] - rect[1]) == (sw, sh)
        self._bind(GL_READ_FRAMEBUFFER, source.glo)
        self._bind(GL_DRAW_FRAMEBUFFER, target.glo)
        self._blit(0, 0, sw, sh, *rect, GL_COLOR_BUFFER_BIT, GL_NEAREST if same else GL_LINEAR)
        target.use()               # moderngl's idea of the bound framebuffer is right again


class CpuImage:
    """An image made on the CPU, (H, W, 3 or 4) uint8 with row 0 at the top, in a texture
    attached to a framebuffer, so that Blitter can copy it; the texture is made again only
    when the size changes."""

    def __init__(self, ctx: moderngl.Context):
        self.ctx = ctx
        self._texture = self._fbo = None

    def upload(self, image: np.ndarray) -> moderngl.Framebuffer:
        height, width = image.shape[:2]
        if image.shape[2] == 3:
            image = np.concatenate([image, np.full((height, width, 1), 255, np.uint8)], axis=2)
        if self._texture is None or self._texture.size != (width, height):
            self.release()
            self._texture = self.ctx.texture((width, height), 4)
            self._fbo = self.ctx.framebuffer([self._texture])
        self._texture.write(np.ascontiguousarray(image[::-1]).tobytes())   # GL rows bottom-up
        return self._fbo

    @property
    def framebuffer(self) -> moderngl.Framebuffer | None:
        return self._fbo

    def release(self) -> None:
        for item in (self._fbo, self._texture):
            if item is not None:
                item.release()
        self._texture = self._fbo = None


class Presenter:
    """Double or triple buffering of the renderer's frames; see the module docstring.

        presenter.submit(gpu.draw(), started)   # the frame just drawn, and when drawing began
        image = presenter.shown                 # the framebuffer to put on the screen now
        ... blit it (and overlays) to the back buffer ...
        presenter.swapped()                     # after the swap: records the latency
    """

    def __init__(self, ctx: moderngl.Context, buffering: int = 2, history: int = 120):
        self.ctx = ctx
        self.blitter = Blitter(ctx)
        self._ring: list[moderngl.Framebuffer] = []
        self._renderbuffers: list = []
        self._frame = 0                       # frames submitted since the buffering was set
        self._started: dict[int, float] = {}  # ring slot -> when drawing its frame began
        self._shown_started: float | None = None
        self._latency = collections.deque(maxlen=history)
        self.buffering = 2
        self._current: moderngl.Framebuffer | None = None
        self.set_buffering(buffering)

    def set_buffering(self, buffering: int) -> None:
        if buffering not in BUFFERINGS:
            raise ValueError(f"buffering must be 2 (double) or 3 (triple), got {buffering}")
        self.buffering = buffering
        self._frame = 0
        self._started.clear()
        self._latency.clear()

    def _ensure_ring(self, size: tuple[int, int]) -> None:
        if self._ring and self._ring[0].size == size:
            return
        self._release_ring()
        for _ in range(3):
            colour = self.ctx.renderbuffer(size, 4)
            self._renderbuffers.append(colour)
            self._ring.append(self.ctx.framebuffer([colour]))
        self._frame = 0                       # a resize empties the ring
        self._started.clear()

    def submit(self, drawn: moderngl.Framebuffer, started: float) -> None:
        """Take the frame just drawn into `drawn` (drawing began at `started`,
        time.perf_counter()); afterwards `shown` is what the window should show."""
        if self.buffering == 2:
            self._current, self._shown_started = drawn, started
        else:
            self._ensure_ring(drawn.size)
            slot = self._frame % 3
            self.blitter.copy(drawn, self._ring[slot])
            self._started[slot] = started
            # Show the frame before this one; the very first frame has none before it.
            previous = (self._frame - 1) % 3 if self._frame else slot
            self._current, self._shown_started = self._ring[previous], self._started[previous]
        self._frame += 1

    @property
    def shown(self) -> moderngl.Framebuffer:
        return self._current

    def swapped(self, now: float | None = None) -> None:
        """Call right after the swap that put `shown` on the screen."""
        if self._shown_started is not None:
            now = time.perf_counter() if now is None else now
            self._latency.append((now - self._shown_started) * 1000.0)

    @property
    def latency_ms(self) -> float | None:
        """Median latency (drawing began -> on the screen) over the recent frames."""
        return statistics.median(self._latency) if self._latency else None

    @property
    def name(self) -> str:
        return BUFFERINGS[self.buffering]

    def _release_ring(self) -> None:
        for item in [*self._ring, *self._renderbuffers]:
            item.release()
        self._ring, self._renderbuffers = [], []

    def release(self) -> None:
        self._release_ring()
