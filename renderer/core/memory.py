"""Memory a render will need, estimated before anything is allocated, and the limit it must stay
under, so that a large size, a huge primitive or a big mesh file is refused with one line
instead of running the machine out of memory.

The figures are per pixel and per triangle, measured with benchmarks/bench_memory.py on
llvmpipe (peak resident memory over the process's baseline) and rounded up:

    GPU path     renderbuffers, read-back staging and the output arrays: 32 bytes a pixel
                 (+48 for linear colour, +8 a sample for MSAA), plus the context's own
                 ~128 MiB; 896 bytes a triangle (the scene's float64 mesh, the float32
                 vertex and index buffers, the facets' texture)
    reference    the output arrays, 8 bytes a pixel (+16 linear, +4 for a depth-tie image),
                 and a working set of 320 bytes a pixel of one band of at most TILE_PIXELS
                 (reference/pipeline.py draws a large frame band by band); 1280 bytes a
                 triangle (vertex outputs, clipping, window triangles, all float64)
    mesh files   parsing takes up to 16 times the file's size (trimesh's text parsers);
                 building the parsed mesh (merging, crease normals) up to 1024 bytes a
                 triangle at its peak, and the built mesh holds 192

The limit is half of the machine's physical memory unless set (`renderer ... --max-memory`,
or `limit_set`); `check` raises the one-line UserError when an estimate is over it.

A command knows what it will do before it reads its scene, but not how many triangles the
scene holds. It says what it will need (`planned(need, ...)`, a Need per method, size and
backends); the scene reader counts triangles as they become known (a TriangleTally: a mesh
file's once it is parsed, a primitive's before it is built) and refuses as soon as the count
would take the command over the limit, before the mesh is built (building a 5-million-
triangle mesh takes half a minute and 4.6 GiB). So the peak of the whole command, loading
included, stays under the limit: the larger of loading's peak and rendering's.
"""

from __future__ import annotations

import contextlib
import os
import re
from dataclasses import dataclass
from typing import Callable

from renderer.errors import UserError

MIB = 1 << 20
GIB = 1 << 30

GPU_FIXED = 128 * MIB
GPU_BYTES_PER_PIXEL = 32
GPU_LINEAR_BYTES_PER_PIXEL = 48
GPU_BYTES_PER_SAMPLE_PIXEL = 8
# Per triangle (the scene's float64 mesh, the float32 vertex and index buffers, the facets'
# normals and creases texture, the frame's plan): measured 742 bytes on a 1,046,528-triangle
# uv_sphere at 256x256 (benchmarks/bench_memory.py, 2026-12-03; 160 before was from before the
# shadow maps' facets), rounded up.
GPU_BYTES_PER_TRIANGLE = 896

REFERENCE_FIXED = 64 * MIB
REFERENCE_OUTPUT_BYTES_PER_PIXEL = 12          # rgba8, depth and a possible tie image
REFERENCE_LINEAR_BYTES_PER_PIXEL = 16
REFERENCE_WORKING_BYTES_PER_PIXEL = 320        # of one band
REFERENCE_BYTES_PER_TRIANGLE = 1280                # measured 1,118 as above (640 before)
# A reference frame of more pixels than this is drawn in bands of at most this many
# (reference/pipeline.py), so that its working set stays bounded.
REFERENCE_TILE_PIXELS = 1 << 20

MESH_PARSE_FACTOR = 16                          # bytes of memory per byte of mesh file
SCENE_BYTES_PER_TRIANGLE = 256                  # building a primitive (float64 mesh + temporaries)
# A mesh file's triangles once parsed: building them (renderer/core/meshio.py: checks, merged
# vertices, crease normals) peaks at 931 bytes a triangle over what was held before, and the
# built mesh holds 140 (5,005,448 triangles of a binary PLY without normals, peak and
# resident memory after, 2026-12-03); rounded up.
MESH_BUILD_BYTES_PER_TRIANGLE = 1024
MESH_HELD_BYTES_PER_TRIANGLE = 192
# What a command holds before its scene and its renderers: Python, NumPy, Pillow, trimesh and
# the GL libraries (`renderer render` refusing a scene peaks at 135 MiB); rounded up. A Need
# counts it and the scene's meshes, so that the whole process stays under the limit.
PROCESS_BYTES = 192 * MIB

DEFAULT_FRACTION = 0.5                          # of physical memory
_limit: int | None = None


def physical_memory() -> int:
    """The machine's physical memory in bytes."""
    return os.sysconf("SC_PAGE_SIZE") * os.sysconf("SC_PHYS_PAGES")


def default_limit() -> int:
    return int(physical_memory() * DEFAULT_FRACTION)


def limit() -> int:
    """The limit in force: the one set, else half of physical memory."""
    return default_limit() if _limit is None else _limit


@contextlib.contextmanager
def limit_set(value: int | None):
    """Within the block, estimates are held against `value` bytes (None: the default)."""
    global _limit
    before, _limit = _limit, value
    try:
        yield
    finally:
        _limit = before


def parse_size(text: str) -> int:
    """'512M', '2G', '1.5GiB', '300000000' -> bytes (binary units); ValueError otherwise."""
    match = re.fullmatch(r"\s*(\d+(?:\.\d+)?)\s*([kmgt]?)(?:i?b)?\s*", text.lower())
    if not match:
        raise ValueError(f"expected a size such as 512M or 2G, got {text!r}")
    number, unit = float(match[1]), match[2]
    value = int(number * (1 << (10 * " kmgt".index(unit or " "))))
    if value <= 0:
        raise ValueError(f"must be more than 0 bytes, got {text!r}")
    return value


def show(n: int) -> str:
    """Bytes as people read them: 6.4 GiB, 512 MiB, 27 kB."""
    if n >= GIB:
        return f"{n / GIB:.1f} GiB"
    return f"{n / MIB:.0f} MiB" if n >= MIB else f"{n / 1024:.0f} kB"


def gpu_bytes(width: int, height: int, triangles: int, *, linear: bool = False,
              samples: int = 1) -> int:
    pixels = width * height
    per_pixel = GPU_BYTES_PER_PIXEL + (GPU_LINEAR_BYTES_PER_PIXEL if linear else 0)
    per_pixel += GPU_BYTES_PER_SAMPLE_PIXEL * samples if samples > 1 else 0
    return GPU_FIXED + pixels * per_pixel + triangles * GPU_BYTES_PER_TRIANGLE


def reference_bytes(width: int, height: int, triangles: int, *, linear: bool = False,
                    tile_pixels: int | None = None) -> int:
    from_band = REFERENCE_TILE_PIXELS if tile_pixels is None else tile_pixels
    pixels = width * height
    band = min(pixels, max(from_band, width))       # a band is whole rows, at least one
    per_pixel = REFERENCE_OUTPUT_BYTES_PER_PIXEL + (REFERENCE_LINEAR_BYTES_PER_PIXEL if linear else 0)
    return (REFERENCE_FIXED + pixels * per_pixel + band * REFERENCE_WORKING_BYTES_PER_PIXEL
            + triangles * REFERENCE_BYTES_PER_TRIANGLE)


# The ray tracer (rough, from a 640x480 frame of tests/test_raytrace_trace.py's SHAPES scene,
# about 55 MiB over a chunk of 65,536 camera rays, doubled for scenes of many triangles):
RAYTRACE_FIXED = 128 * MIB
RAYTRACE_BYTES_PER_PIXEL = 64                   # float colour and depth targets, read-back, rgba8
# Per triangle: ray_scene (float64), the BVH and its build (a level's nodes split in bounded groups:
# renderer/core/bvh.py), and on the GPU the float textures and their upload. Measured on a
# 488,600-triangle uv_sphere at 64x48 (peak RSS over the scene's, 2026-12-03): GPU 1,069 and
# reference 641 bytes a triangle; but after loading a 999,698-triangle PLY (merged and
# creased, benchmarks/bench_memory.py's whole commands) the reference's peak was 829 bytes a
# triangle over the process and the mesh held (what loading left in the heap); rounded up.
RAYTRACE_GPU_BYTES_PER_TRIANGLE = 1280
RAYTRACE_BYTES_PER_TRIANGLE = 1024
RAYTRACE_REFERENCE_BYTES_PER_CAMERA_RAY = 64    # windows, O, D, colour, hit, s of every sample
RAYTRACE_REFERENCE_CHUNK_RAYS = 1 << 16         # reference/raytrace/pipeline.py, CHUNK_RAYS
RAYTRACE_REFERENCE_WORKING_BYTES_PER_RAY = 2048


def raytrace_gpu_bytes(width: int, height: int, triangles: int, *, samples: int = 1) -> int:
    """The GPU ray tracer (renderer/gpu/raytracer.py): samples are looped in the shader, so
    they cost nothing here."""
    return RAYTRACE_FIXED + width * height * RAYTRACE_BYTES_PER_PIXEL + triangles * RAYTRACE_GPU_BYTES_PER_TRIANGLE


def raytrace_reference_bytes(width: int, height: int, triangles: int, *, samples: int = 1) -> int:
    """The reference ray tracer (reference/raytrace/pipeline.py): every sample's camera ray
    held at once, traced a chunk at a time."""
    rays = width * height * samples
    return (RAYTRACE_FIXED + width * height * RAYTRACE_BYTES_PER_PIXEL
            + rays * RAYTRACE_REFERENCE_BYTES_PER_CAMERA_RAY
            + min(rays, RAYTRACE_REFERENCE_CHUNK_RAYS) * RAYTRACE_REFERENCE_WORKING_BYTES_PER_RAY
            + triangles * RAYTRACE_BYTES_PER_TRIANGLE)


# Radiosity (renderer/core/form_factors.py): a row holds at most one value per element and per
# pixel of its hemicube (N^2 on top, N^2 / 2 on each side: 3 N^2), 16 bytes each (column and
# value) and as much again while a batch's rows are summed; a batch's item buffers, their keys
# and weights, 48 bytes a hemicube pixel, at most RADIOSITY_BATCH_BYTES of GL storage beside
# them on the GPU (renderer/gpu/item_buffers.py BATCH_BYTES); the twin's fragments of one
# hemicube, 160 bytes a pixel (several fragments a pixel, each with its keys); elements, 512 bytes each.
RADIOSITY_BATCH_BYTES = 64 * MIB
RADIOSITY_BYTES_PER_ELEMENT = 512


def radiosity_bytes(elements: int, resolution: int, backend: str, direct: bool = False) -> int:
    """The form factors of `elements` elements at hemicube resolution `resolution`: the
    matrix at its largest and drawing it, on `backend` ("gpu" or "reference"); with `direct`,
    the direct solver's dense matrix and system beside it (16 bytes an element pair)."""
    pixels = 5 * resolution * resolution
    per_row = min(elements, 3 * resolution * resolution)
    batch = max(1, RADIOSITY_BATCH_BYTES // (8 * pixels))
    drawing = (min(batch, elements) * pixels * 48 + RADIOSITY_BATCH_BYTES if backend == "gpu"
               else pixels * 160)
    dense = 16 * elements * elements if direct else 0
    return elements * per_row * 32 + drawing + elements * RADIOSITY_BYTES_PER_ELEMENT + dense


def check_radiosity(elements: int, resolution: int, backend: str, name: str, direct: bool = False) -> None:
    """One line (a UserError) before any hemicube is drawn when the form factors of
    `elements` elements (and with `direct`, the direct solver's dense system) would need more
    than the limit."""
    check(radiosity_bytes(elements, resolution, backend, direct),
          f"radiosity of {name} ({elements:,} elements, hemicubes of {resolution}) on {backend}")


def over_limit(needed: int, *, loading: bool = False) -> str | None:
    """None when `needed` bytes fit under the limit, else the end of a refusal:
    "needs about 19.1 GiB of memory, over the limit of 12.0 GiB (...)". `loading`: `needed`
    is one step of reading a scene (a file, a texture), taken on top of the process's own
    PROCESS_BYTES, which count against the limit too and are said beside it."""
    allowed = limit()
    total = needed + PROCESS_BYTES if loading else needed
    if total <= allowed:
        return None
    origin = "set by --max-memory" if _limit is not None else \
        f"half of this machine's {show(physical_memory())}; --max-memory changes it"
    besides = f" ({show(total)} with the process's own)" if loading else ""
    return f"needs about {show(needed)} of memory{besides}, over the limit of {show(allowed)} ({origin})"


def check(needed: int, what: str, *, file: str | None = None) -> None:
    """A one-line UserError when `needed` bytes exceed the limit; `what` says what needs them."""
    reason = over_limit(needed)
    if reason:
        raise UserError(f"{what} {reason}", file=file)


@dataclass(frozen=True)
class Need:
    """What a command will take to draw a scene, known before the scene is read: `bytes_for`
    a scene of that many triangles (those it counts: an analytic shape's own triangles only
    when `shapes`, since the ray tracer intersects the shape itself). `verb`, `setting` and
    `backends` word the refusal: "ray tracing NAME at 64x48, 1 spp (N triangles) on gpu"."""
    verb: str
    setting: str
    backends: tuple[str, ...]
    bytes_for: Callable[[int], int]
    shapes: bool = True

    def counted(self, meshes: int, shapes: int) -> int:
        return meshes + (shapes if self.shapes else 0)

    def words(self, name: str | None, triangles: int | None, *, so_far: bool = False) -> str:
        named = f" {name}" if name else ""
        count = "" if triangles is None else f" ({triangles:,} triangles{' so far' if so_far else ''})"
        return f"{self.verb}{named} {self.setting}{count} on {' and '.join(self.backends)}"

    def check_unread(self, name: str) -> None:
        """One line before the scene `name` is read, when the command is over the limit with
        no triangles at all (its size alone)."""
        check(self.bytes_for(0), self.words(name, None))

    def check(self, scene) -> None:
        """One line, before any rendering, when drawing `scene` would need more than the limit."""
        meshes = sum(obj.mesh.triangle_count for obj in scene.objects if obj.shape is None)
        shapes = sum(obj.mesh.triangle_count for obj in scene.objects if obj.shape is not None)
        triangles = self.counted(meshes, shapes)
        check(self.bytes_for(triangles), self.words(scene.name, triangles))


def raster_need(size, backends) -> Need:
    """The rasteriser at `size` on each of `backends` ("gpu", "reference")."""
    # Every object's mesh is held, an analytic plane's square too (the shadow passes draw it);
    # the polygon the camera pass draws for a plane instead (renderer/core/drawn.py) adds at
    # most 4 triangles, a few kilobytes, below these figures' rounding.
    estimate = {"gpu": gpu_bytes, "reference": reference_bytes}
    return Need("rendering", f"at {size[0]}x{size[1]}", tuple(backends),
                lambda triangles: _whole(triangles, *(estimate[b](*size, triangles) for b in backends)))


def raytrace_need(size, backends, samples: int) -> Need:
    """The ray tracer at `size` and `samples` per pixel (its triangles: meshes only)."""
    estimate = {"gpu": raytrace_gpu_bytes, "reference": raytrace_reference_bytes}
    return Need("ray tracing", f"at {size[0]}x{size[1]}, {samples} spp", tuple(backends),
                lambda triangles: _whole(triangles, *(estimate[b](*size, triangles, samples=samples)
                                                      for b in backends)),
                shapes=False)


def _whole(triangles: int, *renderers: int) -> int:
    """A command's peak: the process, the scene's meshes held, and its renderers' estimates
    (each measured over the process and the scene)."""
    return PROCESS_BYTES + triangles * MESH_HELD_BYTES_PER_TRIANGLE + sum(renderers)


_planned: tuple[Need, ...] = ()


@contextlib.contextmanager
def planned(*needs: Need):
    """While a command reads its scene: what it will then need (each of `needs`, checked
    after reading anyway), so that the scene reader's TriangleTally refuses a scene too large
    for it as soon as its triangle count is known, before building it."""
    global _planned
    before, _planned = _planned, tuple(needs)
    try:
        yield
    finally:
        _planned = before


class TriangleTally:
    """The triangles one scene reader has counted so far: mesh files' (`meshes`) and analytic
    shapes' (`shapes`). Each count is checked, before those triangles are built, against the
    limit: building them on top of what is held, and what the planned command needs."""

    def __init__(self):
        self.meshes = 0
        self.shapes = 0

    def held(self) -> int:
        return (self.meshes + self.shapes) * MESH_HELD_BYTES_PER_TRIANGLE

    def add(self, count: int, *, shape: bool = False,
            build_bytes_per_triangle: int = MESH_BUILD_BYTES_PER_TRIANGLE) -> str | None:
        """Count `count` more triangles, about to be built: None when they fit, else why not
        (the end of a one-line refusal, after the file or key it names)."""
        too_much = over_limit(self.held() + count * build_bytes_per_triangle, loading=True)
        if too_much:
            return f"building its {count:,} triangles {too_much}"
        if shape:
            self.shapes += count
        else:
            self.meshes += count
        for need in _planned:             # (one over the limit unread: refused before reading)
            triangles = need.counted(self.meshes, self.shapes)
            too_much = over_limit(need.bytes_for(triangles))
            if too_much:
                return f"{need.words(None, triangles, so_far=True)} {too_much}"
        return None
