"""What `renderer colour` measures: an image file's pixels, or a scene's frame rendered, as
linear RGB with coverage, then each pixel's CIE XYZ and chromaticity from the chosen backend's
colour pass (renderer/gpu/colour.py on "gpu", reference/output/colour.py on "reference").

Images: a PNG's codes are read exactly, 8 or 16 bits and sBIT honoured (renderer/core/
image_formats.py); other formats Pillow reads come as 8-bit RGBA; OpenEXR and .npy hold float
colour. `colorspace` says what the RGB values are: "srgb" (encoded: the IEC 61966-2-1 curve is
undone, renderer/core/quantise.py `decode`) or "linear" (light as it is); by default "srgb"
for integer images and "linear" for float ones. Alpha is never encoded. Pixels of alpha 0 (a
scene's background, a transparent image's empty parts) are not counted.
"""

from __future__ import annotations

from dataclasses import dataclass, field
from pathlib import Path

import numpy as np

from renderer.core.output_settings import Transfer
from renderer.core.quantise import decode
from renderer.core.user_files import (ARRAY_FILE, IMAGE_FILE, FileRefused, image_size_problem,
                                      npy_header, open_image, open_user_file, png_data_problem,
                                      read_capped, refuse)
from renderer.errors import UserError

FLOAT_SUFFIXES = (".exr", ".npy")
COLORSPACES = ("srgb", "linear")

# Measuring an image, at the peak: resident memory grows by about 143 bytes a pixel from a
# 1024^2 to a 2048^2 PNG (`renderer colour --backend reference`: the codes, float64 RGBA,
# float32 linear, XYZ and chromaticity planes, the plots), rounded up. Checked against the
# memory limit on the size the file's header declares, before any pixel is decoded.
COLOUR_BYTES_PER_PIXEL = 192


@dataclass
class ColourSource:
    """A source's pixels measured: `linear` (H, W, 4) float32 RGB and coverage, `xyz`
    (H, W, 4) XYZ and coverage, `chromaticity` (H, W, 3) x, y, z (from the backend's pass),
    the `scene` for a scene (None for an image) and what to say about it (`details`: kind,
    source, colorspace or backend and size, milliseconds)."""
    name: str
    linear: np.ndarray
    xyz: np.ndarray
    chromaticity: np.ndarray
    scene: object = None
    details: dict = field(default_factory=dict)

    @property
    def covered(self) -> np.ndarray:
        """(H, W) bool: the pixels counted (alpha > 0)."""
        return self.linear[..., 3] > 0

    @property
    def lit(self) -> np.ndarray:
        """(H, W) bool: counted pixels with light, so a chromaticity (X + Y + Z > 0)."""
        return self.covered & (self.xyz[..., :3].sum(axis=-1) > 0)


def is_image_name(text: str) -> bool:
    """Whether a command-line argument names an image (by its suffix) rather than a scene."""
    from PIL import Image
    Image.init()
    suffix = Path(text).suffix.lower()
    return suffix in FLOAT_SUFFIXES or suffix in Image.registered_extensions()


def _read_pixels(path: Path) -> tuple[np.ndarray, bool]:
    """(H, W, 4) RGBA values in [0, 1] (or float colour as stored), and whether it was float.
    The file is opened once, through renderer/core/user_files.py (a regular file, at most
    its kind's size), and the size its header declares is held against the memory limit
    before a pixel is decoded."""
    suffix = path.suffix.lower()
    with open_user_file(path, ARRAY_FILE if suffix == ".npy" else IMAGE_FILE) as handle:
        if suffix == ".exr":
            return _read_exr(handle), True
        if suffix == ".npy":
            return _read_npy(handle), True
        if suffix != ".png":
            with open_image(handle, max_side=None, bytes_per_pixel=COLOUR_BYTES_PER_PIXEL) as image:
                return np.asarray(image.convert("RGBA"), np.float64) / 255.0, False
        import png

        from renderer.core.image_formats import read_png
        header = png.Reader(file=handle)
        header.preamble()                       # the chunks before the image data: IHDR's size
        _check_size(header.width, header.height)
        missing = png_data_problem(handle)      # rows missing: said as such, not as a shape
        if missing:
            raise FileRefused(missing)
        handle.seek(0)
        codes, bits, _ = read_png(read_capped(handle, IMAGE_FILE))
        return _as_rgba(codes / np.array([(1 << b) - 1 for b in bits], np.float64)), False


def _check_size(width: int, height: int) -> None:
    problem = image_size_problem(width, height, max_side=None,
                                 bytes_per_pixel=COLOUR_BYTES_PER_PIXEL)
    if problem:
        raise FileRefused(problem)


def _read_exr(handle) -> np.ndarray:
    """An OpenEXR file's pixels; its header's data window checked first. The binding opens
    by name only: it is given the open file's own (/dev/fd/N), the regular file checked."""
    import OpenEXR

    from renderer.core.image_formats import read_exr
    name = f"/dev/fd/{handle.fileno()}"
    low, high = OpenEXR.File(name, header_only=True).header()["dataWindow"]
    _check_size(int(high[0]) - int(low[0]) + 1, int(high[1]) - int(low[1]) + 1)
    return _as_rgba(read_exr(name))


def _read_npy(handle) -> np.ndarray:
    """A .npy array's values; its header's shape and type checked first (numpy.lib.format),
    so that a header declaring 50000 x 50000 x 4 float32 is refused without reading on."""
    shape, dtype = npy_header(handle)
    if dtype.kind not in "fiu" or len(shape) not in (2, 3) or (
            len(shape) == 3 and shape[2] not in (1, 2, 3, 4)):
        raise ValueError(f"expected (H, W) or (H, W, 1|2|3|4) numbers, got {dtype} {shape}")
    _check_size(shape[1], shape[0])
    return _as_rgba(np.load(handle, allow_pickle=False))


def _as_rgba(values: np.ndarray) -> np.ndarray:
    """Grey, grey + alpha, RGB or RGBA (H, W[, C]) -> (H, W, 4) float64 (opaque if no alpha)."""
    if values.dtype.kind not in "fiu" or values.ndim not in (2, 3) or (
            values.ndim == 3 and values.shape[2] not in (1, 2, 3, 4)):
        raise ValueError(f"expected (H, W) or (H, W, 1|2|3|4) numbers, got {values.dtype} "
                         f"{values.shape}")
    values = np.asarray(values, np.float64).reshape(*values.shape[:2], -1)
    channels = values.shape[2]
    colour = values[..., :3] if channels >= 3 else np.repeat(values[..., :1], 3, axis=2)
    alpha = values[..., -1:] if channels in (2, 4) else np.ones_like(values[..., :1])
    return np.concatenate([colour, alpha], axis=2)


def read_image(path, colorspace: str | None = None) -> tuple[np.ndarray, str]:
    """(linear (H, W, 4) float32, the colorspace it was read as); a file that is missing or
    cannot be read is a one-line UserError naming it."""
    path = Path(path)
    if not path.exists():
        raise UserError("no such image file", file=str(path))
    import png
    try:
        pixels, is_float = _read_pixels(path)
    except FileRefused as refused:
        raise refuse(refused, path) from None
    # pypng's errors are png.Error, OpenEXR's RuntimeError, Pillow's OSError (and, for a
    # damaged file, ValueError, SyntaxError or EOFError), a wrong .npy's ValueError
    except (png.Error, RuntimeError, OSError, ValueError, SyntaxError, EOFError) as error:
        raise UserError(f"cannot read it as an image: {error}", file=str(path)) from None
    if not np.isfinite(pixels).all():
        raise UserError("holds NaN or infinite values, which have no colour", file=str(path))
    colorspace = colorspace or ("linear" if is_float else "srgb")
    if colorspace == "srgb":
        pixels[..., :3] = decode(pixels[..., :3], Transfer("srgb"))
    return pixels.astype(np.float32), colorspace


def measure_colour(linear: np.ndarray, backend: str, ctx=None, context_kind: str = "auto"):
    """(xyz, chromaticity, milliseconds) of the backend's colour pass; on "gpu" in `ctx`, or
    a context of `context_kind` made for it."""
    if backend == "reference":
        import time

        from reference.output.colour import colour_planes as reference_planes
        start = time.perf_counter()
        xyz, chromaticity = reference_planes(linear)
        return xyz, chromaticity, (time.perf_counter() - start) * 1000.0
    from renderer.gpu.colour import ColourPass
    with ColourPass(ctx, context_kind=context_kind) as colour_pass:
        xyz, chromaticity = colour_pass.apply(linear)
        return xyz, chromaticity, colour_pass.last_milliseconds


def image_source(path, colorspace: str | None, backend: str, context_kind: str) -> ColourSource:
    linear, colorspace = read_image(path, colorspace)
    xyz, chromaticity, ms = measure_colour(linear, backend, context_kind=context_kind)
    return ColourSource(Path(path).name, linear, xyz, chromaticity, None, {
        "kind": "image", "source": str(path), "colorspace": colorspace, "backend": backend,
        "size": [linear.shape[1], linear.shape[0]], "colour_pass_ms": round(ms, 3)})


def scene_source(scene, size, backend: str, context_kind: str) -> ColourSource:
    """The scene rasterised at `size` with its linear colour (unclamped), then measured."""
    from renderer.methods import open_renderer
    with open_renderer(scene, size, backend=backend, context_kind=context_kind) as renderer:
        frame = renderer.render(linear=True, depth=False)
        # the colour pass on the GPU runs in the renderer's context (the reference has none)
        xyz, chromaticity, ms = measure_colour(frame.linear, backend,
                                               renderer.ctx if backend == "gpu" else None)
    return ColourSource(scene.name, frame.linear, xyz, chromaticity, scene, {
        "kind": "scene", "source": scene.source or scene.name, "backend": backend,
        "size": list(size), "render_ms": round(frame.milliseconds, 3),
        "colour_pass_ms": round(ms, 3)})
