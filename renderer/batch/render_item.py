"""Rendering items on a worker: one GL context, renderers reused across items, files returned
as bytes (the driver writes them: renderer/batch/run.py).

    worker = ItemWorker("auto")                 # what executor.map's factory builds, once
    results = worker.run(items)                 # one ItemResult per item, in the batch's order
    worker.close()

A worker keeps, made on first use: the context; each scene (by its SceneSource digest); a
GpuRenderer or RayTracer per (scene, shading, method, size, ray options, motion on/off), the
last CACHED of each (an orbit's views share one renderer; a sweep moves on); and one
OutputPass. An item sets the renderer's scene camera and calls update(), and the tracer's
reseed(item.seed): bit for bit what a renderer made afresh for the item draws (tests/test_raytrace_update.py, tests/test_determinism.py),
in whatever order the items come. Nothing here writes a file.

An item that fails (its scene cannot be drawn, GL fails) gives an ItemResult with `error`
set and no files: the batch goes on, and the driver leaves the item out of the manifest so
that a re-run tries it again.
"""

from __future__ import annotations

import hashlib
import io
import time
import traceback
from collections import OrderedDict
from dataclasses import dataclass, field, replace

import numpy as np

from renderer.batch.items import Item, Output, SceneSource, Setting
from renderer.cluster.executor import worker_identity
from renderer.core import image_formats
from renderer.core.motion import moves
from renderer.core.output_settings import INTEGER_FORMATS
from renderer.core.scene import Scene
from renderer.errors import UserError
from renderer.methods import METHODS

CACHED = 4                    # scenes and renderers kept per worker (least recently used go)


def pixels_sha256(array: np.ndarray) -> str:
    """SHA-256 of an array's dtype, shape and bytes (C order): the pixels written, whatever
    bytes an encoder makes of them."""
    array = np.ascontiguousarray(array)
    digest = hashlib.sha256(f"{array.dtype.str}{list(array.shape)}:".encode())
    digest.update(array.tobytes())
    return digest.hexdigest()


@dataclass
class ItemResult:
    """What a worker returns for an item. `files` maps each path under DIR (item.files, in
    order) to its encoded bytes and `pixels` each path to pixels_sha256 of what it holds;
    render_ms is the camera update and the render, encode_ms the output stage and encoding.
    `worker` says where it ran: {"host", "pid", "gl_renderer"}. A failed item has `error`
    (a UserError's line, or a bug's traceback, `bug` True) and no files. With keep_frames,
    `frame` is (the Frame without its linear colour, the GL's subpixel bits or None for the
    ray tracer), what reference_item holds the reference against (--compare)."""
    key: str
    files: dict[str, bytes] = field(default_factory=dict)
    pixels: dict[str, str] = field(default_factory=dict)
    render_ms: float = 0.0
    encode_ms: float = 0.0
    worker: dict = field(default_factory=dict)
    error: str | None = None
    bug: bool = False
    frame: tuple | None = None


def load_source(source: SceneSource) -> Scene:
    """The scene of a SceneSource: its file read, the sweep point's overrides set."""
    from renderer.core.scene_file import read_scene, scene_from_dict, with_overrides
    data, path = read_scene(source.path)
    data = with_overrides(data, dict(source.overrides), str(path))
    return scene_from_dict(data, source=str(path), base_dir=path.parent)


def item_scene(base: Scene, item: Item) -> Scene:
    """A new Scene object for `item` with the item's camera (objects and meshes shared with
    `base`); what the setting's options change of it (a shading) open_renderer applies."""
    scene = replace(base)
    scene.camera = item.camera.camera(base.camera)
    return scene


def encode(output: Output, setting: Setting, frame, staged: np.ndarray | None) -> tuple[bytes, np.ndarray]:
    """An output's file bytes and the array they hold: the output stage's codes or floats
    (RGB, or RGBA with a transparent background), or the depth plane."""
    buffer = io.BytesIO()
    if output.depth is not None:
        array = frame.depth
        (image_formats.write_exr if output.depth == "exr" else np.save)(buffer, array)
        return buffer.getvalue(), array
    s = output.settings
    array = np.ascontiguousarray(staged if setting.background == "transparent" else staged[..., :3])
    if s.quantised:
        image_formats.write_png(buffer, array, s.code_bits, INTEGER_FORMATS[s.format])
    elif s.format == "exr":
        image_formats.write_exr(buffer, array)
    else:
        np.save(buffer, array)
    return buffer.getvalue(), array


class ItemWorker:
    """Renders items (module docstring). Picklable before first use: nothing is made until
    `run`, so executor.map's factory may be the class itself or functools.partial of it."""

    def __init__(self, context_kind: str = "auto", keep_frames: bool = False):
        self.context_kind = context_kind
        self.keep_frames = keep_frames
        self.ctx = None
        self._scenes: OrderedDict[str, Scene] = OrderedDict()
        self._renderers: OrderedDict[tuple, object] = OrderedDict()
        self._output_pass = None
        self._where: dict | None = None

    def run(self, items: list[Item]) -> list[ItemResult]:
        """One result per item, in order; an item's failure is its result's `error`."""
        return [self._run_one(item) for item in items]

    def _run_one(self, item: Item) -> ItemResult:
        try:
            return self.render(item)
        except UserError as error:
            return ItemResult(item.key, worker=self._worker(), error=error.line())
        except Exception:          # a bug: its traceback travels to the driver
            return ItemResult(item.key, worker=self._worker(), error=traceback.format_exc(),
                              bug=True)

    def _worker(self) -> dict:
        """Where items run: host, pid and, once the context exists, its GL renderer."""
        if self._where is None or self._where["gl_renderer"] is None:
            gl = None if self.ctx is None else self.ctx.info["GL_RENDERER"]
            self._where = worker_identity() | {"gl_renderer": gl}
        return self._where

    def _context(self):
        if self.ctx is None:
            from renderer.gpu.context import make_context
            self.ctx = make_context(self.context_kind)
        return self.ctx

    def _scene(self, source: SceneSource) -> Scene:
        scene = self._scenes.pop(source.digest, None) or load_source(source)
        self._scenes[source.digest] = scene
        while len(self._scenes) > CACHED:
            self._scenes.popitem(last=False)
        return scene

    def _renderer(self, item: Item, scene: Scene):
        """The renderer for the item, its scene's camera set and updated (made if needed)."""
        setting = item.setting
        # the options but the seed (reseeded below), and whether something moves (a tracer's layout)
        key = (item.scene.digest, setting.method, setting.size, setting.options, moves(scene))
        renderer = self._renderers.pop(key, None)
        if renderer is None:
            from renderer.methods import open_renderer
            renderer = open_renderer(scene, setting.size, method=setting.method,
                                     options=setting.options_for(item.seed), context=self._context())
            while len(self._renderers) >= CACHED:
                self._renderers.popitem(last=False)[1].release()
        else:
            try:
                renderer.scene.camera = scene.camera
                renderer.update()
                if METHODS[setting.method].seeded:
                    renderer.reseed(item.seed)
            except BaseException:
                renderer.release()            # out of the cache already: not left holding GL objects
                raise
        self._renderers[key] = renderer
        return renderer

    def render(self, item: Item) -> ItemResult:
        """Render and encode one item (exceptions propagate: `run` catches them)."""
        setting = item.setting
        start = time.perf_counter()
        scene = item_scene(self._scene(item.scene), item)
        renderer = self._renderer(item, scene)
        depth = self.keep_frames or any(o.depth for o in setting.outputs)
        frame = renderer.render(linear=True, depth=depth)
        rendered = time.perf_counter()
        result = ItemResult(item.key, worker=self._worker())
        for path, output in zip(item.files, setting.outputs):
            staged = None if output.depth else self._stage().apply(frame.linear, output.settings)
            data, array = encode(output, setting, frame, staged)
            result.files[path] = data
            result.pixels[path] = pixels_sha256(array)
        result.render_ms = (rendered - start) * 1000.0
        result.encode_ms = (time.perf_counter() - rendered) * 1000.0
        if self.keep_frames:             # what the reference is held against (no linear colour)
            subpixel_bits = renderer.subpixel_bits                     # the GPU's snapping
            result.frame = (replace(frame, linear=None), subpixel_bits)
        return result

    def _stage(self):
        if self._output_pass is None:
            from renderer.gpu.output import OutputPass
            self._output_pass = OutputPass(self._context())
        return self._output_pass

    def close(self) -> None:
        """Release every renderer and the context."""
        for renderer in self._renderers.values():
            renderer.release()
        self._renderers.clear()
        self._output_pass = None
        if self.ctx is not None:
            from renderer.gpu.context import release_context
            release_context(self.ctx)
            self.ctx = None


@dataclass
class ReferenceResult:
    """reference_item's answer: the bytes of gpu.png, reference.png and diff.png and the
    figures of `renderer compare`, or `error` (and `bug`) as in ItemResult."""
    files: tuple[bytes, ...] = ()
    figures: dict | None = None
    error: str | None = None
    bug: bool = False


def _png(rgba8: np.ndarray) -> bytes:
    buffer = io.BytesIO()
    image_formats.write_png(buffer, rgba8, 8, 8)
    return buffer.getvalue()


def reference_item(item: Item, frame, subpixel_bits: int | None) -> ReferenceResult:
    """The NumPy reference of `item` held against its GPU `frame` (a plain task: no GL)."""
    from renderer.checks.against_reference import against_reference
    try:
        scene = item_scene(load_source(item.scene), item)
        setting = item.setting
        check = against_reference(scene, setting.size, frame, method=setting.method,
                                  options=setting.options_for(item.seed), subpixel_bits=subpixel_bits)
    except UserError as error:
        return ReferenceResult(error=error.line())
    except Exception:
        return ReferenceResult(error=traceback.format_exc(), bug=True)
    return ReferenceResult((_png(frame.rgba8), _png(check.reference.rgba8), _png(check.heat)),
                           check.figures)
