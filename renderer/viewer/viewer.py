"""`renderer view`: a scene in a window, drawn by the same GpuRenderer as the headless path.

Each frame: handle the window's events (renderer/viewer/controls.py turns them into a camera and a
ViewState), bring the renderer up to date when something changed (GpuRenderer.update, or
resize when the window's size changed: the image always has the window's aspect ratio),
draw offscreen (GpuRenderer.draw), and let the presenter (renderer/viewer/presenter.py) put the
frame on the back buffer by double or triple buffering, with the reference view and the
overlay beside or over it; then swap. The reference view is the NumPy reference of the same
view, made in a background process (renderer/viewer/reference_view.py), side by side with the GPU
image or as a heat map of their difference with its figures.

With the ray tracer on (the M key, `method="raytrace"`; or the path tracer, `"pathtrace"`, the
key's next step) a frame is one sample per pixel traced by a RayTracer (PathTracer) made on
first use in the window's context (renderer/gpu/raytracer.py, pathtracer.py) and added
to the running mean of the view's samples (renderer/viewer/progressive.py); the window shows
the mean, and the title the samples per pixel so far. A change of the picture (camera, size,
shading, lights, materials) takes the tracer's update() and starts the mean again; once it
holds progressive.MAX_SPP samples nothing more is traced and the interactive loop waits for
events. The reference view compares the rasteriser only: it is off while ray tracing.

With radiosity on (`method="radiosity"`, a method `solved_in_steps`) a frame is one step of
radiosity's progressive solution (renderer/viewer/radiosity_view.py): the lights' direct light
at once, the hemicubes a batch a frame, then progressive refinement's shots converging; the
title says where it is. A camera move keeps it going; a change of lights starts it again; once
converged the loop waits for events.

Shadows (the O key) switch GpuRenderer.shadows; the reference view is then asked for the scene
with every light's shadows off, the image the GPU draws. The shadow-map view (the D key,
renderer/viewer/shadow_view.py) replaces the picture with the map of the chosen light as the
frame just drawn left it, the map its lighting read; the overlay names the light and the depth
range shown, or says why there is no map to show.

`Viewer.run(frames=N, orbit=DEG, screenshot=PATH)` is the scripted mode of the command line:
N frames, the camera orbiting DEG degrees per frame, then what the window shows saved to PNG
and the frame-time statistics returned.
"""

from __future__ import annotations

import statistics
import time
from dataclasses import dataclass, field
from pathlib import Path

import numpy as np

from renderer.checks.methods import without_shadow_maps
from renderer.viewer.controls import (Controls, ViewState, apply_view, help_lines, light_names_of,
                                      shown_light, working_copy)
from renderer.gpu.context import activate
from renderer.methods import METHODS, open_renderer
from renderer.core.imageio import write_image
from renderer.core.paths import default_output, output_stem
from renderer.viewer.orbit import OrbitCamera
from renderer.viewer.overlay import text_panel
from renderer.viewer.presenter import CpuImage, Presenter, fit
from renderer.viewer.progressive import PATTERN, SAMPLES_PER_FRAME, Accumulator
from renderer.viewer.radiosity_view import RadiosityView
from renderer.viewer.reference_view import BackgroundReference, difference_view, figures_line
from renderer.viewer.shadow_view import CUBE_FACE_NAMES, ShadowMapView, drawn_faces
from renderer.core.scene import Scene
from renderer.viewer.window import Window

SCREEN_CLEAR = (0.12, 0.12, 0.14)          # the window around a letterboxed image
TITLE_EVERY_S = 0.25                       # how often the title's figures are refreshed
IDLE_WAIT_S = 0.1                          # the longest an idle loop waits for events


@dataclass
class FrameStats:
    """Frame-time figures of a run: `frames` the frames drawn and swapped, `frame_ms` from
    swap to swap (what a user sees; one fewer than the frames, and none across a wait for
    the reference view), `draw_ms` the part spent issuing the scene's draw calls,
    `latency_ms` from drawing a frame to the swap that showed it."""
    frames: int = 0
    frame_ms: list[float] = field(default_factory=list)
    draw_ms: list[float] = field(default_factory=list)
    latency_ms: float | None = None

    def summary(self) -> dict:
        frames = sorted(self.frame_ms)
        if not frames:
            return {"frames": self.frames}
        median = statistics.median(frames)
        return {"frames": self.frames, "frame_ms_median": median,
                "frame_ms_p5": frames[int(0.05 * (len(frames) - 1))],
                "frame_ms_p95": frames[int(0.95 * (len(frames) - 1))],
                "frame_ms_max": frames[-1], "fps": 1000.0 / median if median > 0 else None,
                "draw_ms_median": statistics.median(self.draw_ms),
                "latency_ms_median": self.latency_ms}

    def line(self) -> str:
        s = self.summary()
        if "frame_ms_median" not in s:
            return f"{s['frames']} frame(s): no frame times"
        fps = "no" if s["fps"] is None else f"{s['fps']:.1f}"     # None: frames took no time
        latency = "" if s["latency_ms_median"] is None else \
            f", latency {s['latency_ms_median']:.2f} ms"
        return (f"{s['frames']} frames: frame time median {s['frame_ms_median']:.2f} ms "
                f"(p5 {s['frame_ms_p5']:.2f}, p95 {s['frame_ms_p95']:.2f}, max {s['frame_ms_max']:.2f}), "
                f"{fps} fps; drawing median {s['draw_ms_median']:.2f} ms{latency}")


class Viewer:
    """A window on one scene; see the module docstring."""

    def __init__(self, scene: Scene, width: int, height: int, *, vsync: bool = True,
                 buffering: int = 2, reference: str = "off", screenshot: Path | None = None,
                 on_message=print, method: str = "raster"):
        self.authored = scene
        self.shown = working_copy(scene)
        self.say = on_message
        self.screenshot_path = screenshot
        self._screenshots = 0
        self.state = ViewState(vsync=vsync, buffering=buffering, reference=reference,
                               method=method)
        self.orbit = OrbitCamera(scene.camera)
        self.controls = Controls(self.state, self.orbit, light_names_of(scene), on_message=on_message,
                                 scene=scene)
        self.window = Window(width, height, f"renderer view: {scene.name}", vsync=vsync)
        try:
            self.ctx = self.window.ctx
            size = self.window.framebuffer_size
            self.controls.resize(*size)
            apply_view(self.state, self.authored, self.shown, self.orbit.camera)
            self.gpu = open_renderer(self.shown, size, context=self.ctx)
            self.gpu.wireframe = self.state.wireframe
            self.presenter = Presenter(self.ctx, buffering)
            self.background = BackgroundReference()
            self._reference_image = CpuImage(self.ctx)   # the reference, for side by side
            self._difference_image = CpuImage(self.ctx)  # the heat map
            self._overlay = CpuImage(self.ctx)
            self._overlay_lines: tuple = ()
            self._tracer = None                # the RayTracer or PathTracer, made on first use
            self._tracer_method = None         # which of them
            self._traced_version = -1          # the version it and the mean were made for
            self.accumulator = Accumulator()
            self._traced = CpuImage(self.ctx)  # the mean so far
            self._radiosity = None             # the RadiosityView, made on first use
            self._radiosity_key = None         # what of the view (not the camera) it last saw
            self._radiosity_version = -1       # the version its last frame showed
            self._map_view = None              # the ShadowMapView, made on first use
            self._map_lines: tuple = ()        # the overlay's lines on it (none: not asked for)
            self._map_shown = False            # the picture is the map view
            self._version = 0                 # bumped whenever the shaded image would change
            self._levels_version, self._levels = -1, (0.0, 0.0)   # the title's tessellation levels
            self._view: tuple | None = None   # what the version stands for
            self._requested = -1              # the version the reference was asked for
            self._reference_version = -1      # the version the reference images show
            self._figures: dict | None = None
            self.window.connect(self.controls)
            self.stats = FrameStats()
            self._last_swap: float | None = None
            self._last_title = 0.0
            self._vsync_set = vsync
        except BaseException:
            self.close()
            raise

    # -- one frame ---------------------------------------------------------------------------
    def _follow_changes(self) -> None:
        """Bring the renderer up to date with the window's size and the controls' changes."""
        state = self.state
        size = self.window.framebuffer_size
        if size != (self.gpu.width, self.gpu.height) and min(size) > 0:   # 0 when minimised
            self.gpu.resize(*size)             # (the controls hear of it from the window)
        if state.camera_changed or state.scene_changed:
            apply_view(state, self.authored, self.shown, self.orbit.camera)
            self.gpu.update()
            state.camera_changed = state.scene_changed = False
        # The version names what the shaded image depends on (not wireframe, help or the
        # reference mode), so that only a new image asks the reference again.
        view = (self.gpu.width, self.gpu.height, repr(self.orbit.camera), state.shading,
                state.two_sided, tuple(state.lights_on), state.shadows)
        if view != self._view:
            self._view = view
            self._version += 1
        self.gpu.wireframe = state.wireframe
        self.gpu.shadows = state.shadows
        if state.vsync != self._vsync_set:
            self.window.set_vsync(state.vsync)
            self._vsync_set = state.vsync
        if state.buffering != self.presenter.buffering:
            self.presenter.set_buffering(state.buffering)

    def _follow_reference(self, wait: bool = False) -> None:
        """Ask for the reference of the current view when it is wanted and not asked for yet,
        and take a finished one (`wait`: wait for it): its heat map against a GPU image of
        the same view."""
        if self.state.reference == "off" or not self._rasterising:
            return
        if self._requested != self._version:
            scene = working_copy(self.shown)
            self.background.request(scene if self.state.shadows else without_shadow_maps(scene),
                                    self.gpu.width, self.gpu.height, self._version)
            self._requested = self._version
        result = self.background.wait() if wait else self.background.poll()
        if result is not None and result.version == self._version:
            self._take_reference(result)

    def _take_reference(self, result) -> None:
        wireframe, self.gpu.wireframe = self.gpu.wireframe, False   # compare shaded images
        try:
            gpu_rgba8 = self.gpu.render(depth=False).rgba8
        finally:
            self.gpu.wireframe = wireframe
        difference, self._figures = difference_view(gpu_rgba8, result)
        self._reference_image.upload(result.rgba8)
        self._difference_image.upload(difference)
        self._reference_version = result.version

    def _compose(self, shown) -> None:
        """The back buffer: the frame (and the reference view) letterboxed, then the overlay."""
        screen = self.ctx.screen
        width, height = self.window.framebuffer_size
        screen.use()
        blit = self.presenter.blitter.copy
        mode = "off" if not self._rasterising or self._map_shown else self.state.reference
        have_reference = self._reference_version >= 0
        whole = (0, 0, width, height)
        if mode != "off" or fit(shown.size, whole) != whole:
            screen.clear(*SCREEN_CLEAR, 1.0)           # letterbox bars; else all is covered
        if mode == "side-by-side":
            blit(shown, screen, fit(shown.size, (0, 0, width // 2, height)))
            if have_reference:
                reference = self._reference_image.framebuffer
                blit(reference, screen, fit(reference.size, (width // 2, 0, width, height)))
        elif mode == "difference" and have_reference:
            difference = self._difference_image.framebuffer
            blit(difference, screen, fit(difference.size, whole))
        else:
            blit(shown, screen, fit(shown.size, whole))
        lines = self._overlay_text()
        if lines != self._overlay_lines:
            panel = text_panel(list(lines), width, height)
            if panel is not None:
                self._overlay.upload(panel)
            else:
                self._overlay.release()
            self._overlay_lines = lines
        panel = self._overlay.framebuffer
        if lines and panel is not None:
            pw, ph = panel.size
            blit(panel, screen, (0, height - ph, pw, height))     # top left

    def _overlay_text(self) -> tuple:
        lines = []
        if not self._rasterising:
            if self.state.reference != "off":
                lines.append(f"reference view: off while {METHODS[self.state.method].title} draws "
                             "(it compares the rasteriser)")
        elif self.state.reference == "side-by-side":
            lines.append("left: GPU (GLSL)    right: NumPy reference")
        lines += self._map_lines
        if self.state.reference != "off" and self._rasterising and not self._map_shown:
            current = self._reference_version == self._version
            if self._figures is not None and self._reference_version >= 0:
                lines.append(figures_line(self._figures) + ("" if current else " (updating)"))
            elif self.background.busy:
                lines.append("reference view: computing...")
        if self.state.help:
            lines += help_lines(self.state, light_names_of(self.authored))
        return tuple(lines)

    def frame(self) -> None:
        """One frame: events, changes, draw, present, swap."""
        self.window.poll()
        self._follow_changes()
        self._follow_reference()
        started = time.perf_counter()
        if self._progressive:
            drawn = self._trace()
        elif self._solved_in_steps:
            drawn = self._radiosity_frame()
        else:
            drawn = self.gpu.draw()
        drawn = self._shadow_map(drawn)
        self.ctx.finish()                     # so that draw_ms is the drawing, not queued work
        self.stats.draw_ms.append((time.perf_counter() - started) * 1000.0)
        self.presenter.submit(drawn, started)
        self._compose(self.presenter.shown)
        if self.state.screenshot:
            self.state.screenshot = False
            self.save_screenshot()
        self.window.swap()
        self.stats.frames += 1
        now = time.perf_counter()
        self.presenter.swapped(now)
        if self._last_swap is not None:
            self.stats.frame_ms.append((now - self._last_swap) * 1000.0)
        self._last_swap = now
        if now - self._last_title >= TITLE_EVERY_S:
            self.window.set_title(self.title())
            self._last_title = now

    @property
    def _progressive(self) -> bool:
        """Whether the method shown refines over frames (the ray tracer: a mean of frames, no
        reference view) rather than drawing each frame whole (the rasteriser)."""
        return METHODS[self.state.method].progressive

    @property
    def _solved_in_steps(self) -> bool:
        """Whether the method shown converges a step a frame (radiosity)."""
        return METHODS[self.state.method].solved_in_steps

    @property
    def _rasterising(self) -> bool:
        """Whether the rasteriser draws the picture (the reference view and the shadow maps are its)."""
        return not (self._progressive or self._solved_in_steps)

    def _radiosity_frame(self):
        """Radiosity's next step of the current view (renderer/viewer/radiosity_view.py): its
        framebuffer. The steps start again only when something but the camera and size changed."""
        state = self.state
        key = (state.shading, state.two_sided, tuple(state.lights_on))
        if self._radiosity is None:
            self._radiosity = RadiosityView(self.ctx, on_message=self.say)
        changed, self._radiosity_key = key != self._radiosity_key, key
        self._radiosity_version = self._version
        return self._radiosity.frame(self.shown, (self.gpu.width, self.gpu.height), changed)

    def _trace(self):
        """The ray or path tracer's frame: the tracer of the method shown brought to the
        current view (made, or updated and the mean restarted, when the version moved on; made
        again when the method changed), one more frame added to the mean unless it is complete,
        and the mean uploaded; its framebuffer."""
        size = (self.gpu.width, self.gpu.height)
        method = METHODS[self.state.method]
        if self._tracer is not None and self._tracer_method != method.name:
            self._tracer.release()                    # the other tracer's: its mean is not this one's
            self._tracer = None
        if self._tracer is None:
            started = time.perf_counter()
            self._tracer = open_renderer(self.shown, size, method=method.name, context=self.ctx,
                                         options=method.options(samples=SAMPLES_PER_FRAME, pattern=PATTERN))
            self._tracer_method, self._traced_version = method.name, -1      # its mean starts
            rs = self._tracer.ray_scene
            self.say(f"{method.title} ready in {time.perf_counter() - started:.1f} s "
                     f"({len(rs.triangles):,} triangles, {len(rs.sphere_radius)} spheres, "
                     f"{len(rs.plane_offset)} planes)")
        elif self._traced_version != self._version:
            if size != (self._tracer.width, self._tracer.height):
                self._tracer.resize(*size)                       # (and update)
            else:
                self._tracer.update()
        if self._traced_version != self._version:
            self._traced_version = self._version
            self.accumulator.restart()
        if not self.accumulator.done:
            self.accumulator.trace(self._tracer)
            self._traced.upload(self.accumulator.rgba8)
        return self._traced.framebuffer

    def _shadow_map(self, drawn):
        """The map view's framebuffer in place of `drawn` when the D key asks for a map and
        the frame just drawn drew it; sets the overlay's lines: what is shown, or why not."""
        index, plan = self.state.shadow_map, self.gpu.drawn_shadow_plan
        self._map_shown = False
        if index is None:
            self._map_lines = ()
            return drawn
        name = light_names_of(self.authored)[index]
        light_map = None if plan is None else plan.layout.get(*shown_light(self.state, self.authored, index))
        if not self._rasterising:
            why = f"off while {METHODS[self.state.method].title} draws (the maps are the rasteriser's)"
        elif not self.state.shadows:
            why = "shadows are off (O)"
        elif light_map is None:
            why = "none drawn this frame (no receiver with shadow code in view)"
        else:
            why = None
        if why is not None:
            self._map_lines = (f"shadow map of {name}: {why}",)
            return drawn
        if self._map_view is None:
            self._map_view = ShadowMapView(self.ctx)
        size = (self.gpu.width, self.gpu.height)
        shown = self._map_view.draw(self.gpu.shadow_maps, plan, light_map, size, SCREEN_CLEAR)
        faces = drawn_faces(plan, light_map)
        r = light_map.resolution
        if light_map.kind == "point":
            drawn_names = "all" if len(faces) == 6 else " ".join(CUBE_FACE_NAMES[f] for f in faces) or "none"
            what = f"{r}x{r}, faces +x -x +y / -y +z -z (drawn: {drawn_names})"
        else:
            what = f"{r}x{r}" + ("" if faces else " (not drawn: nothing shadows the view)")
        depths = self._map_view.depth_range
        self._map_lines = (f"shadow map of {name}: {what}",
                           "nothing stored: all 1.0 (white)" if depths is None else
                           f"depth {depths[0]:.6g} black to {depths[1]:.6g} grey, 1.0 white")
        self._map_shown = True
        return shown

    @property
    def idle(self) -> bool:
        """Nothing new to draw until an event comes: the ray tracer's mean of the current view
        is complete, or radiosity has converged and drawn it (the reference view is off then)."""
        if self._solved_in_steps:
            return (self._radiosity is not None and self._radiosity.done
                    and self._radiosity_version == self._version)
        return (self._progressive and self._traced_version == self._version
                and self.accumulator.done)

    @property
    def samples(self) -> int | None:
        """The samples per pixel in the picture on the screen: the ray tracer's so far, None
        while rasterising."""
        return self.accumulator.samples if self._progressive else None

    @property
    def radiosity_line(self) -> str | None:
        """Where radiosity's steps are (renderer/viewer/radiosity_view.py), None unless it draws."""
        if not self._solved_in_steps or self._radiosity is None:
            return None
        return self._radiosity.line

    @property
    def figures(self) -> dict | None:
        """The reference view's figures (renderer/viewer/reference_view.py) for the view on the
        screen, or None when there are none for it (not asked for, or not ready)."""
        if not self._rasterising:
            return None
        return self._figures if self._reference_version == self._version else None

    def title(self) -> str:
        recent = self.stats.frame_ms[-30:]
        timing = ""
        if recent:
            ms = statistics.median(recent)
            timing = f" | {1000.0 / ms if ms > 0 else 0:.0f} fps, {ms:.1f} ms/frame"
        latency = self.presenter.latency_ms
        latency_text = "" if latency is None else f", latency {latency:.1f} ms"
        tracing = ""
        if self._progressive:
            tracing = f" | {'path' if self.state.method == 'pathtrace' else 'ray'} tracing: {self.accumulator.samples} spp" + (
                " (done)" if self.accumulator.done else "")
        elif self._solved_in_steps and self._radiosity is not None:
            tracing = f" | {self._radiosity.line}"
        shadows = f" | shadows {'on' if self.state.shadows else 'off'}"
        shadows += self._levels_text()
        if self._map_shown:
            shadows += f" (map of {light_names_of(self.authored)[self.state.shadow_map]})"
        return (f"renderer view: {self.authored.name}{tracing}{timing}{shadows} | "
                f"{self.presenter.name} buffering{latency_text} | "
                f"v-sync {'on' if self.state.vsync else 'off'} | H for help")

    def _levels_text(self) -> str:
        """" | tessellation levels A-B" where the rasteriser draws objects through the
        tessellation stages: the least and largest level of their patches in this view (their
        control stage's twin, reference/tessellation/surface.py), worked out again only when
        the view changes."""
        if not self._rasterising or not any(o.tessellation for o in self.shown.objects):
            return ""
        if self._levels_version != self._version:
            from reference.tessellation.surface import levels_in_view
            found = levels_in_view(self.shown, self.gpu.width, self.gpu.height)
            self._levels = (min(low for _, low, _ in found), max(high for _, _, high in found))
            self._levels_version = self._version
        low, high = self._levels
        return f" | tessellation levels {low:.1f}-{high:.1f}"

    # -- screenshots -------------------------------------------------------------------------
    def window_image(self) -> np.ndarray:
        """What the back buffer holds now, (H, W, 3) uint8, row 0 at the top."""
        width, height = self.window.framebuffer_size
        data = self.ctx.screen.read(viewport=(0, 0, width, height), components=3, alignment=1)
        return np.frombuffer(data, np.uint8).reshape(height, width, 3)[::-1].copy()

    def shown_image(self) -> np.ndarray:
        """What the window shows now, (H, W, 3) uint8: the image just swapped in is the front
        buffer; it is drawn again (the same frame, no orbit step) to read it from the back
        buffer (in the window's context: a headless render may have bound another since)."""
        activate(self.ctx)
        self._compose(self.presenter.shown)
        return self.window_image()

    def save_screenshot(self, path: Path | None = None) -> Path:
        if path is None:
            path = self.screenshot_path
        if path is None:
            while True:
                self._screenshots += 1
                path = default_output(f"view-{output_stem(self.authored)}-{self._screenshots:03d}.png")
                if not path.exists():
                    break
        write_image(path, self.window_image())
        self.say(f"screenshot: {path}")
        return path

    # -- loops -------------------------------------------------------------------------------
    def run(self, frames: int | None = None, orbit: float = 0.0,
            screenshot: Path | None = None) -> FrameStats:
        """Frames until Esc or the window is closed, or `frames` of them (scripted); then
        the screenshot, if asked, of what the window shows after the last frame. In the
        scripted mode a wanted reference view is waited for before the last frame."""
        count = 0
        while not (self.state.quit or self.window.should_close):
            if frames is not None and count >= frames:
                break
            last = frames is not None and count == frames - 1
            if frames is None and self.idle:
                self.window.wait(IDLE_WAIT_S)     # nothing to draw: no busy loop
            if orbit:
                self.orbit.orbit(orbit, 0.0)
                self.state.camera_changed = True
            if last and self.state.reference != "off" and self._rasterising:
                self._follow_changes()        # the last frame's view, orbit step included
                self._follow_reference(wait=True)
                self._last_swap = None        # the wait is not a frame time
            self.frame()
            if last and screenshot is not None:
                write_image(screenshot, self.shown_image())
            count += 1
        self.stats.latency_ms = self.presenter.latency_ms
        return self.stats

    def close(self) -> None:
        for name in ("background", "_reference_image", "_difference_image", "_overlay",
                     "_traced", "_tracer", "_radiosity", "_map_view", "presenter", "gpu"):
            item = getattr(self, name, None)
            if item is not None:
                (item.close if hasattr(item, "close") else item.release)()
        if getattr(self, "window", None) is not None:
            self.window.close()

    def __enter__(self) -> "Viewer":
        return self

    def __exit__(self, *exc) -> None:
        self.close()
