"""Radiosity (issue 33; docs/radiosity.md; renderer/core/radiosity.py, glsl/radiosity/, twin
reference/radiosity/), registered as method "radiosity": RadiosityRenderer on the GPU, the twin
behind the same protocol. Both draw their own hemicubes (identical item buffers, so identical
form factors and solutions) and their own display."""

from __future__ import annotations


import contextlib

from renderer.core.frame import Frame
from renderer.core.memory import Need, raster_need
from renderer.core.radiosity import elements_for, lighting_for, refreshed, specular_display
from renderer.core.radiosity_options import RadiosityOptions
from renderer.core.radiosity_progressive import progressive_solution
from renderer.methods.reference_backend import ReferenceRenderer
from renderer.methods.registry import Method


class ReferenceRadiosity(ReferenceRenderer):
    """The twin: reference/radiosity/item_buffer.py's hemicubes, the same solve, and
    reference/radiosity/display.py's frame; the solution kept while only the camera moves
    (renderer/core/radiosity.py what_changed, as the GPU's)."""

    def __init__(self, scene, width, height, options: RadiosityOptions, precision=None,
                 subpixel_bits: int | None = None):
        super().__init__(scene, width, height, options, precision)
        self.subpixel_bits = subpixel_bits
        self._solution = None
        self._stale = True

    @property
    def solution(self):
        if self._stale:
            solution = refreshed(self._solution, elements_for(self.scene, self.options),
                                 lighting_for(self.scene, self.options), self.options, self._item_buffers,
                                 "reference", self.scene.name)
            self._solution = self._solution if solution is None else solution
            self._stale = False
        return self._solution

    @contextlib.contextmanager
    def _item_buffers(self, elements, resolution, what):
        """The twin's item buffers for `elements` at `resolution` (`refreshed`)."""
        from reference.radiosity.item_buffer import ItemBuffers
        yield ItemBuffers(elements, resolution)

    def progressive(self, scene=None, **steps):
        """The twin of RadiosityRenderer.progressive: the same steps with the twin's item buffers."""
        if scene is not None:
            self.scene = scene
        for progress in progressive_solution(self._solution, elements_for(self.scene, self.options),
                                             lighting_for(self.scene, self.options), self.options,
                                             self._item_buffers, "reference", self.scene.name, **steps):
            self._solution, self._stale = progress.solution, False
            yield progress

    def _scene_changed(self) -> None:
        self._stale = True

    def _frame(self, *, linear: bool, depth: bool, progress=None) -> Frame:
        from reference.radiosity.display import render
        extra = {} if self.subpixel_bits is None else {"subpixel_bits": self.subpixel_bits}
        solution = self.solution
        origin = self.scene.matrices(self.width, self.height).origin
        return render(solution.elements.corners, solution.corner_radiosity, self.scene, self.width,
                      self.height, dtype=self.dtype, linear=linear, depth=depth,
                      specular=specular_display(solution, self.scene, origin), **extra)


def _open_gpu(scene, width, height, options: RadiosityOptions, context, context_kind):
    from renderer.gpu.radiosity import RadiosityRenderer
    return RadiosityRenderer(scene, width, height, options, context=context, context_kind=context_kind)


def _open_reference(scene, width, height, options, precision, subpixel_bits):
    return ReferenceRadiosity(scene, width, height, options, precision, subpixel_bits)


def _need(size, backends, options) -> Need:
    """The display's, as the rasteriser's; the form factors are checked once the elements are
    known (memory.check_radiosity)."""
    return raster_need(size, backends)


def _words(options: RadiosityOptions, frame) -> str:
    return f"radiosity, hemicubes of {options.hemicube}, {options.solver}"


# The viewer shows radiosity converging a step a frame (renderer/viewer/radiosity_view.py): its
# form factors take seconds for a scene of a few thousand elements, and no frame waits for them.
METHOD = Method("radiosity", "radiosity", RadiosityOptions, _open_gpu, _open_reference, _need, words=_words,
                solved_in_steps=True)


