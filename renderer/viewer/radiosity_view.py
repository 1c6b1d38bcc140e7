"""Radiosity in the viewer (the M key's step to it, or `renderer view --method radiosity`): the
solution shown converging, a step a frame (renderer/core/radiosity_progressive.py): first the
lights' direct light with the ambient term for the bounces to come, while the hemicubes are
drawn a batch a frame; then progressive refinement's shots, a few a frame, the ambient term
shrinking with the unshot light, until it converges; then nothing more is computed and the
frames only follow the camera.

A camera move keeps the steps going (the form factors do not depend on it); anything else that
changes what radiosity sees (lights on or off, the window's scene) starts them again, keeping
the form factors where the geometry is the same (radiosity.what_changed). The frame is drawn by
RadiosityRenderer in the window's context and handed to the presenter as an image.
"""

from __future__ import annotations

from renderer.core.radiosity import change_between, elements_for, lighting_for
from renderer.core.radiosity_options import RadiosityOptions
from renderer.errors import UserError
from renderer.gpu.radiosity import RadiosityRenderer
from renderer.viewer.presenter import CpuImage


class RadiosityView:
    """See the module docstring: `frame(scene, size)` a step and the picture's framebuffer;
    `line` where the steps are; `done` once converged."""

    def __init__(self, ctx, options: RadiosityOptions | None = None, on_message=print):
        self.ctx = ctx
        self.options = options or RadiosityOptions(solver="progressive")
        self.say = on_message
        self.renderer: RadiosityRenderer | None = None
        self._steps = None                 # the progressive_solution generator running
        self._for = None                   # the (elements, lighting) it runs for
        self.line = ""
        self.done = False
        self._image = CpuImage(ctx)

    def frame(self, scene, size: tuple[int, int], changed: bool):
        """One step (unless done) of radiosity for `scene` (the viewer's, changed in place) at
        `size`, `changed`: something other than the size may have changed since the last frame
        (the steps start again only if radiosity's problem did). The frame's framebuffer."""
        drawn = self.options.scene_for(scene)          # the physical model's units, or `scene`
        if self.renderer is None:
            self.renderer = RadiosityRenderer(drawn, *size, self.options, context=self.ctx, solve=False)
            changed = True
        elif size != (self.renderer.width, self.renderer.height):
            self.renderer.resize(*size)
        self.renderer.scene = drawn                    # the camera, as the viewer moves it
        if changed:
            problem = (elements_for(drawn, self.options), lighting_for(drawn, self.options))
            if self._for is None or change_between(*self._for, *problem) != "nothing":
                self._restart(problem)
        if self._steps is not None:
            try:
                progress = next(self._steps)
            except UserError as error:                 # more memory than allowed: said, not raised
                self.line, self.done, self._steps = f"radiosity: {error.line()}", True, None
                self.say(self.line)
            else:
                self.line, self.done = progress.line, progress.done
                if progress.done:
                    self._steps = None
        return self._image.upload(self.renderer.render(linear=False, depth=False).rgba8)

    def _restart(self, problem) -> None:
        if self._steps is not None:
            self._steps.close()                        # releases its item buffers
        self._for = problem
        self._steps = self.renderer.progressive()
        self.done = False

    def release(self) -> None:
        if self._steps is not None:
            self._steps.close()
            self._steps = None
        if self.renderer is not None:
            self.renderer.release()
            self.renderer = None
        self._image.release()
