"""Every way of making an image, behind one call: a method ("raster", "raytrace", "radiosity",
"pathtrace") on a backend ("gpu": GLSL through moderngl; "reference": the NumPy twin), opened as
a Renderer
(renderer/gpu/base.py: render, update, resize, release, a context manager, gl_info).

    from renderer.methods import open_renderer
    with open_renderer(scene, (640, 480), method="raytrace", options=RayOptions(samples=4)) as r:
        frame = r.render()

A method is a module here that makes a Method (renderer/methods/registry.py: its options
type, how it opens on each backend, its memory check) and one entry in METHODS below; the
command line, compare, batch, the report, extremes, colour and the viewer all open their
renderers through open_renderer and ask the Method what differs.
"""

from __future__ import annotations

from renderer.core.scene import Scene
from renderer.errors import OptionError
from renderer.methods import pathtrace, radiosity, raster, raytrace
from renderer.methods.registry import BACKENDS, Method

METHODS: dict[str, Method] = {m.name: m for m in (raster.METHOD, raytrace.METHOD, radiosity.METHOD,
                                                pathtrace.METHOD)}


def method(name: str) -> Method:
    """The registered method called `name`; OptionError naming the known ones otherwise."""
    if name not in METHODS:
        raise OptionError("method", f"unknown method {name!r}; one of {', '.join(METHODS)}")
    return METHODS[name]


def option_owners() -> dict[str, str]:
    """Option field -> the method whose options have it (the first registered, if shared)."""
    owners: dict[str, str] = {}
    for m in METHODS.values():
        for name in m.options.__dataclass_fields__:
            owners.setdefault(name, m.name)
    return owners


def method_options(name: str, given: dict | None = None):
    """Method `name`'s options from the fields `given`, checked once (OptionError naming the
    field, also for a field of another method's options)."""
    return method(name).options_from(given or {}, option_owners())


def open_renderer(scene: Scene, size: tuple[int, int], *, method: str = "raster",
                  backend: str = "gpu", options=None, context=None, context_kind: str = "auto",
                  precision: str | None = None, subpixel_bits: int | None = None):
    """A Renderer of `scene` at `size` by `method` on `backend` with `options` (the method's
    options type; None: its defaults). GPU: on `context` if given, else a new context of
    `context_kind`. Reference: in `precision` ("float32", "float64"; None: the method's
    default) with the GPU's `subpixel_bits` (the rasteriser's snapping, None: GL's minimum)."""
    chosen = globals()["method"](method)
    if backend not in BACKENDS:
        raise OptionError("backend", f"unknown backend {backend!r}; one of {', '.join(BACKENDS)}")
    options = chosen.options() if options is None else options
    if not isinstance(options, chosen.options):
        raise TypeError(f"method {chosen.name} takes {chosen.options.__name__}, "
                        f"not {type(options).__name__}")
    scene = options.scene_for(scene)             # the scene as the options draw it (a lens)
    width, height = size
    if backend == "gpu":
        return chosen.open_gpu(scene, width, height, options, context, context_kind)
    return chosen.open_reference(scene, width, height, options, precision, subpixel_bits)


__all__ = ["BACKENDS", "METHODS", "Method", "method", "method_options", "open_renderer"]
