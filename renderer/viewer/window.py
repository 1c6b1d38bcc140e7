"""A window on the screen with an OpenGL 3.3 core context (glfw), for renderer/viewer/viewer.py.

    window = Window(640, 480, "renderer view", vsync=True)   # DisplayError without a display
    window.ctx                       # moderngl context, adopted (renderer/gpu/context.py, "window")
    window.framebuffer_size          # pixels: what the renderer draws at
    window.swap(); window.poll()
    window.close()

The context is glfw's, so on this machine it is Mesa's llvmpipe through GLX (under Xvfb when
there is no screen): the same GL as the headless EGL and OSMesa paths. Event callbacks go to
the handler object passed to `connect` (renderer/viewer/controls.py's Controls), so the handling can
be tested without a window by calling the handler directly.
"""

from __future__ import annotations

import os

import glfw
import moderngl

from renderer.gpu.context import (REQUIRED_GL, activate, adopt_context, before_window_context,
                                  release_context)
from renderer.errors import ContextError


class DisplayError(ContextError):
    """No screen to open a window on: one line that suggests a virtual one."""


def _no_display(reason: str) -> DisplayError:
    return DisplayError(f"no display to open a window on ({reason}); run it on a virtual one: "
                        "xvfb-run -a renderer view ... (Debian package xvfb)")


class Window:
    """One glfw window and its context; see the module docstring."""

    def __init__(self, width: int, height: int, title: str, vsync: bool = True):
        if not (os.environ.get("DISPLAY") or os.environ.get("WAYLAND_DISPLAY")):
            raise _no_display("DISPLAY is not set")
        errors: list[str] = []
        glfw.set_error_callback(lambda code, text: errors.append(text.decode(errors="replace")))
        if not glfw.init():
            raise _no_display(f"glfw: {'; '.join(errors) or 'init failed'}")
        self._handle = None
        try:
            glfw.window_hint(glfw.CONTEXT_VERSION_MAJOR, REQUIRED_GL // 100)
            glfw.window_hint(glfw.CONTEXT_VERSION_MINOR, REQUIRED_GL % 100 // 10)
            glfw.window_hint(glfw.OPENGL_PROFILE, glfw.OPENGL_CORE_PROFILE)
            glfw.window_hint(glfw.OPENGL_FORWARD_COMPAT, True)
            glfw.window_hint(glfw.DOUBLEBUFFER, True)
            glfw.window_hint(glfw.SAMPLES, 0)       # the renderer does its own MSAA, offscreen
            before_window_context()     # glfw binds the new context at once; EGL must let go
            self._handle = glfw.create_window(int(width), int(height), title, None, None)
            if not self._handle:
                raise _no_display(f"glfw could not open an OpenGL {REQUIRED_GL / 100:.1f} window: "
                                  f"{'; '.join(errors) or 'no reason given'}")
            glfw.make_context_current(self._handle)
            self.ctx = moderngl.create_context(require=REQUIRED_GL)
            adopt_context(self.ctx,
                          make_current=lambda: glfw.make_context_current(self._handle),
                          release=lambda: glfw.make_context_current(None),
                          get_proc_address=glfw.get_proc_address)
            self.set_vsync(vsync)
        except BaseException:
            self.close()
            raise

    # -- state -------------------------------------------------------------------------------
    @property
    def framebuffer_size(self) -> tuple[int, int]:
        """The default framebuffer's size in pixels (the window's size on X11)."""
        return tuple(glfw.get_framebuffer_size(self._handle))

    @property
    def should_close(self) -> bool:
        return bool(glfw.window_should_close(self._handle))

    def set_size(self, width: int, height: int) -> None:
        """Ask for a new window size (as a user's resize would); it arrives with the events."""
        glfw.set_window_size(self._handle, int(width), int(height))

    def set_title(self, title: str) -> None:
        glfw.set_window_title(self._handle, title)

    def set_vsync(self, on: bool) -> None:
        """Swap interval 1 (wait for the vertical blank) or 0. Xvfb has no vertical blank, so
        there it changes nothing measurable."""
        glfw.swap_interval(1 if on else 0)

    # -- events ------------------------------------------------------------------------------
    def connect(self, handler) -> None:
        """Forward glfw's events to `handler`: key(key, scancode, action, mods),
        mouse_button(button, action, mods), cursor(x, y) (framebuffer pixels, y down),
        scroll(dx, dy) and resize(width, height) (framebuffer pixels)."""
        handle = self._handle
        glfw.set_key_callback(handle, lambda _w, *args: handler.key(*args))
        glfw.set_mouse_button_callback(handle, lambda _w, *args: handler.mouse_button(*args))
        glfw.set_cursor_pos_callback(handle, lambda _w, x, y: handler.cursor(*self._to_pixels(x, y)))
        glfw.set_scroll_callback(handle, lambda _w, dx, dy: handler.scroll(dx, dy))
        glfw.set_framebuffer_size_callback(handle, lambda _w, w, h: handler.resize(w, h))

    def _to_pixels(self, x: float, y: float) -> tuple[float, float]:
        """Cursor positions come in screen coordinates; pan must follow the cursor in the
        framebuffer's pixels. On X11 they are the same; on a HiDPI screen they are not."""
        window_w, window_h = glfw.get_window_size(self._handle)
        pixels_w, pixels_h = self.framebuffer_size
        if window_w <= 0 or window_h <= 0:
            return x, y
        return x * pixels_w / window_w, y * pixels_h / window_h

    def poll(self) -> None:
        glfw.poll_events()

    def wait(self, timeout: float) -> None:
        """Sleep until an event comes or `timeout` seconds pass (an idle viewer)."""
        glfw.wait_events_timeout(timeout)

    def swap(self) -> None:
        activate(self.ctx)                 # a headless context may have been bound meanwhile
        glfw.swap_buffers(self._handle)

    # -- lifetime ----------------------------------------------------------------------------
    def close(self) -> None:
        """Destroy the window (and its context) and end glfw; idempotent."""
        if getattr(self, "ctx", None) is not None:
            release_context(self.ctx)
            self.ctx = None
        if self._handle:
            glfw.destroy_window(self._handle)
            self._handle = None
        glfw.terminate()

    def __enter__(self) -> "Window":
        return self

    def __exit__(self, *exc) -> None:
        self.close()
