"""What a method is to the rest of the product (renderer/methods/__init__.py registers them):
its name and title, its options type, how it opens on each backend, and what it needs checked
before any work. A front end asks the Method, never `if method == ...`."""

from __future__ import annotations

from dataclasses import dataclass
from typing import Callable

from renderer.errors import OptionError

BACKENDS = ("gpu", "reference")


@dataclass(frozen=True)
class Method:
    """One way of making an image from a scene.

    open_gpu(scene, width, height, options, context, context_kind) and
    open_reference(scene, width, height, options, precision, subpixel_bits) return a Renderer
    (renderer/gpu/base.py); need(size, backends, options) is what drawing a scene will take
    (a renderer/core/memory.py Need: planned while the scene is read, checked once it is, by
    check_memory, which refuses in one line what would not fit); words(options, frame) says how a frame was
made in a few words for a front end's line ("" for nothing to say); samples(options) is
what a frame's work per pixel scales with (the ray tracer's samples times light samples;
memory estimates and a batch's costs). `progressive`: successive frames bring new
    samples (render(first_sample=k)), so a viewer refines while the view is still; `seeded`:
    the frames depend on a seed (reseed(seed), a batch item's own); `shutter`: objects move
during the camera's shutter (motion blur; a method without it draws time 0), so an
animation's frames differ; `solved_in_steps`: its frames show a solution converging, a step a
frame, which the camera does not change (radiosity: renderer/viewer/radiosity_view.py);
`stepped_to`: the viewer's M key steps to it."""
    name: str
    title: str
    options: type
    open_gpu: Callable
    open_reference: Callable
    need: Callable
    words: Callable = lambda options, frame: ""
    samples: Callable = lambda options: 1
    progressive: bool = False
    seeded: bool = False
    shutter: bool = False
    solved_in_steps: bool = False
    stepped_to: bool = True

    def check_memory(self, scene, size, backends, options) -> None:
        """One line (a UserError) when drawing `scene` would need more than the memory limit."""
        self.need(size, backends, options).check(scene)

    def options_from(self, given: dict, owners: dict[str, str]):
        """This method's options from the fields `given` (those not given keep their defaults);
        OptionError for a field that only another method takes (`owners`: field -> method)."""
        fields = set(self.options.__dataclass_fields__)
        for name in given:
            if name not in fields:
                owner = owners.get(name)
                raise OptionError(name, f"is for method {owner}, not {self.name}" if owner else
                                  f"is no option of method {self.name}")
        return self.options(**given)
