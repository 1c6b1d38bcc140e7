"""A job's work items: scenes x cameras x sweep points x settings, each rendered once.

    job = read_job("job.toml")            # renderer/batch/job_file.py: checked, scenes loaded
    items = expand(job)                   # file order; stable keys; seeds from (job seed, key)
    for item in iter_items(job): ...      # the same, made one at a time (bounded memory)

An item's key names it everywhere (its folder, its manifest record, its seed):

    SCENE/CAMERA/sweep-NNN/SETTING        e.g. hierarchy/orbit-007/sweep-000/raster

SCENE is the [[scenes]] entry's name, CAMERA one of `camera-000` (the scene's own camera),
`orbit-NNN` (view NNN of an orbit), `pose-NNN` (the NNN-th pose), `frame-NNN` (frame NNN of
an animation), SETTING the [[settings]] entry's name. Every part is always there, numbered
from 0 with at least three digits (`sweep-000` for a scene without a sweep), so that a key is
known before the job runs. Expansion is in file order: scenes, then their cameras, then
their sweep points (the first sweep key varying slowest), then the settings.

Seeds: an item's seed is `item_seed(job.seed, key)`, the first four bytes (little-endian) of
SHA-256("JOB_SEED/KEY"): nothing comes from the worker, the order or the clock, so an item's
pixels are the same with 1 worker or N, in any order, on a restart, and adding items to a
job leaves the others' pixels alone. The ray tracer takes it as its sampling seed
(RayTracer.reseed); the rasteriser has no randomness.

Items are small frozen dataclasses: they travel to workers (pickled by Ray) and describe
the work, not its result; a worker loads the scene from `SceneSource` itself and caches it.
"""

from __future__ import annotations

import hashlib
import itertools
from collections.abc import Iterable, Iterator
from dataclasses import dataclass, field, replace
from typing import Any

from renderer.core.camera_paths import orbit_cameras
from renderer.core.jsonio import canonical_json
from renderer.core.output_settings import FORMATS, OutputSettings
from renderer.core.scene import Camera

ITEMS_FOLDER = "items"         # DIR/items/KEY/NAME: an item's files


def item_seed(job_seed: int, key: str) -> int:
    """The item's uint32 seed: SHA-256("JOB_SEED/KEY")'s first four bytes, little-endian."""
    return int.from_bytes(hashlib.sha256(f"{job_seed}/{key}".encode()).digest()[:4], "little")


def numbered(kind: str, index: int) -> str:
    """'orbit-007': a key part, numbered from 0 with at least three digits."""
    return f"{kind}-{index:03d}"


@dataclass(frozen=True)
class Output:
    """One file an item writes, `name` in its folder: colour through the output stage
    (`settings`, renderer/core/output_settings.py) or, with `depth` ("npy" or "exr"), the
    camera-space depth as float32 (+inf where nothing was hit)."""
    name: str
    settings: OutputSettings | None = None
    depth: str | None = None

    def describe(self) -> dict:
        """The canonical description (manifest records, the job's identity)."""
        if self.depth is not None:
            return {"name": self.name, "depth": self.depth}
        s = self.settings
        return {"name": self.name, "format": s.format, "transfer": str(s.transfer), "bits": s.bits,
                "dither": s.dither, "halftone": None if s.halftone is None else str(s.halftone)}


DEFAULT_OUTPUTS = (Output("image.png", OutputSettings()),)   # 8-bit PNG, linear: GL's colour as drawn


def default_output_name(output_settings: OutputSettings | None, depth: str | None) -> str:
    """image.png / image.exr / image.npy for colour, depth.npy / depth.exr for depth."""
    if depth is not None:
        return f"depth.{depth}"
    return f"image{FORMATS[output_settings.format]}"


@dataclass(frozen=True)
class Setting:
    """How an item is rendered: a [[settings]] entry of the job file (docs/batch-format.md).
    `options` is the method's options object (renderer/methods: RasterOptions, whose
    `shading` replaces every material's shading; RayOptions, whose seed each item replaces
    with its own: options_for)."""
    name: str
    method: str                                  # a renderer/methods METHODS name
    size: tuple[int, int]
    outputs: tuple[Output, ...] = DEFAULT_OUTPUTS
    background: str = "opaque"                   # "opaque" (RGB) | "transparent" (RGBA)
    options: Any = None                          # None: the method's defaults

    def __post_init__(self):
        if self.options is None:
            from renderer.methods import method_options
            object.__setattr__(self, "options", method_options(self.method))

    def options_for(self, seed: int):
        """The options an item drawn with `seed` renders with (the seed where the method has one)."""
        from renderer.methods import METHODS
        return self.options.replace(seed=seed) if METHODS[self.method].seeded else self.options

    def describe(self) -> dict:
        """The canonical description (manifest records, the job's identity): the fields a
        job gives, the options' SETTING_FIELDS among them."""
        data = {"name": self.name, "method": self.method, "size": list(self.size),
                "background": self.background}
        data |= {name: getattr(self.options, name) for name in self.options.SETTING_FIELDS}
        return data | {"outputs": [output.describe() for output in self.outputs]}


@dataclass(frozen=True)
class SceneSource:
    """Where a worker gets an item's scene: the scene file (`path`: a built-in scene's file or
    a path as the job file resolved it; it must be readable where the worker runs) and the
    sweep point's `overrides` (key path -> value, scene_file.with_overrides). `digest` is the
    SHA-256 of the parsed data after the overrides: the scene's identity (the job's identity,
    a worker's cache key)."""
    path: str
    overrides: tuple[tuple[str, Any], ...]
    digest: str


@dataclass(frozen=True)
class CameraSpec:
    """An item's camera, as the job file gives it (the key part `part`): the scene's own
    (`kind` "camera"), view `index` of an orbit of `views` at `elevation` degrees (None: the
    camera's own), a pose (eye, look and up: None keeps the scene camera's up), or frame
    `index` of an animation, whose shutter is `shutter`. `camera(base)` makes it from the
    scene's camera, in one step (no rounding adds up along an orbit)."""
    kind: str                                    # "camera" | "orbit" | "pose" | "frame"
    index: int = 0
    views: int | None = None
    elevation: float | None = None
    eye: tuple | None = None
    look: tuple | None = None
    up: tuple | None = None
    shutter: tuple[float, float] | None = None

    @property
    def part(self) -> str:
        return numbered(self.kind, self.index)

    def camera(self, base: Camera) -> Camera:
        if self.kind == "orbit":
            return orbit_cameras(base, self.views, self.elevation)[self.index]
        if self.kind == "pose":
            return replace(base, eye=self.eye, look=self.look, up=self.up or base.up)
        if self.kind == "frame":
            return replace(base, shutter=self.shutter)
        return base

    def describe(self) -> dict:
        return {name: value for name, value in (
            ("kind", self.kind), ("index", self.index), ("views", self.views),
            ("elevation", self.elevation), ("eye", self.eye), ("look", self.look), ("up", self.up),
            ("shutter", self.shutter)) if value is not None}


@dataclass(frozen=True)
class SceneEntry:
    """A [[scenes]] entry, checked: its key part `name`, the scene for each sweep point (in
    order; one point without overrides when there is no sweep) and its cameras."""
    name: str
    points: tuple[SceneSource, ...]
    cameras: tuple[CameraSpec, ...]


@dataclass(frozen=True)
class Job:
    """A job file, read and checked (job_file.read_job): nothing in it can fail later but a
    render itself."""
    path: str
    name: str
    seed: int
    scenes: tuple[SceneEntry, ...]
    settings: tuple[Setting, ...]
    description: str = ""


@dataclass(frozen=True)
class Item:
    """One frame to render and write: see the module docstring."""
    key: str
    seed: int
    scene: SceneSource
    camera: CameraSpec
    setting: Setting
    files: tuple[str, ...] = field(default=())   # paths under DIR, one per setting.outputs

    def describe(self) -> dict:
        """The canonical description: what the job's identity hashes, and the record keeps."""
        return {"key": self.key, "seed": self.seed, "scene": self.scene.digest,
                "overrides": dict(self.scene.overrides), "camera": self.camera.describe(),
                "setting": self.setting.describe()}

    @property
    def group(self) -> tuple:
        """Items of one group reuse one renderer on a worker: batches are cut by group."""
        return (self.scene.digest, self.setting.name)


def iter_items(job: Job) -> Iterator[Item]:
    """The job's items in file order (module docstring), made one at a time: a stream whose
    memory does not grow with the job (`expand` keeps them all)."""
    for entry in job.scenes:
        for camera, (index, point), setting in itertools.product(
                entry.cameras, enumerate(entry.points), job.settings):
            key = f"{entry.name}/{camera.part}/{numbered('sweep', index)}/{setting.name}"
            files = tuple(f"{ITEMS_FOLDER}/{key}/{output.name}" for output in setting.outputs)
            yield Item(key, item_seed(job.seed, key), point, camera, setting, files)


def item_count(job: Job) -> int:
    """How many items `iter_items` makes, without making them."""
    return sum(len(entry.cameras) * len(entry.points) for entry in job.scenes) * len(job.settings)


def expand(job: Job) -> list[Item]:
    """The job's items in file order, as a list (iter_items)."""
    return list(iter_items(job))


def job_identity(job: Job, items: Iterable[Item]) -> str:
    """SHA-256 of the canonical expanded items (keys, seeds, scenes' contents, cameras,
    settings): a manifest in DIR belongs to this job when its header carries the same.

    The text hashed is canonical_json({"seed": SEED, "items": [item.describe(), ...]}),
    fed to the hash item by item: each item's text is put together from its camera's,
    sweep point's and setting's texts (made once each), as json.dumps would write it, so
    neither the whole text nor the items need be held (tests/test_batch_items.py holds it
    to the one-piece text)."""
    digest = hashlib.sha256(b'{"items":[')
    texts: dict[tuple[str, int], str] = {}       # (what, id) -> canonical text, made once

    def text(what: str, part, describe) -> str:
        found = texts.get((what, id(part)))
        if found is None:
            found = texts[what, id(part)] = canonical_json(describe(part))
            held.append(part)                    # its id stays its own while cached
        return found

    held: list = []
    for n, item in enumerate(items):
        digest.update((("," if n else "") + '{"camera":' + text("camera", item.camera, CameraSpec.describe)
                       + ',"key":' + canonical_json(item.key) + ',"overrides":'
                       + text("overrides", item.scene, lambda source: dict(source.overrides))
                       + ',"scene":' + canonical_json(item.scene.digest) + ',"seed":' + str(item.seed)
                       + ',"setting":' + text("setting", item.setting, Setting.describe)
                       + "}").encode())
    digest.update(f'],"seed":{canonical_json(job.seed)}}}'.encode())
    return digest.hexdigest()
