"""The output stage's files, encoded and read back (docs/conventions.md, "Output"): N-bit
codes in an 8- or 16-bit PNG, float32 images in OpenEXR. Arrays have row 0 at the top, as
both formats store them (PNG's first row, OpenEXR's increasing y): nothing is flipped.
renderer/core/imageio.py writes them (`Outputs.png_codes`, `Outputs.exr`), all or none.

PNG (pypng: Pillow cannot write 16-bit RGB). A code c of N bits sits in a container of
M = 8 or 16 bits as
    v = floor(c (2^M - 1) / (2^N - 1) + 1/2)          (in integers)
the PNG specification's linear scaling (section 12.4, "Sample depth scaling"; where N divides
M it equals bit replication), with an sBIT chunk saying N when N < M. Read back,
    c = floor(v (2^N - 1) / (2^M - 1) + 1/2)
is exact for every N and code: with r = (2^M - 1) / (2^N - 1) >= 1, |v - c r| <= 1/2, so
v / r lies within 1 / (2 r) <= 1/2 of c, and the half is reached only at r = 1, where v = c.
(No tie arises on the way up either: 2 c (2^M - 1) is even and (2k + 1)(2^N - 1) odd.)
pypng's own writer at bitdepth=N writes these very bytes (tests/test_image_formats.py);
we scale in NumPy because it scales value by value in Python and always puts N <= 8 in an
8-bit container. pypng's reader undoes sBIT by a right shift, v >> (M - N), which gives the
same codes back for samples scaled so (the tests check every N and code) but is not the
rounding inverse for other samples; `read_png` applies the rule above.

OpenEXR: float32 channels, ZIP compression (lossless: every bit pattern, inf, NaN and
negatives included, comes back); colour as R, G, B(, A), a depth plane as Z.
"""

from __future__ import annotations

import io
from pathlib import Path
from typing import NamedTuple

import numpy as np
import OpenEXR
import png

PNG_CONTAINERS = (8, 16)                       # bits per sample of an RGB(A) or grey PNG
EXR_HEADER = {"compression": OpenEXR.ZIP_COMPRESSION, "type": OpenEXR.scanlineimage}
EXR_DEPTH = "Z"                                # OpenEXR's standard name for depth
EXR_COLOUR = {3: "RGB", 4: "RGBA"}             # the binding splits these into R, G, B(, A)


def _ratio_terms(bits: int, container_bits: int) -> tuple[int, int]:
    if container_bits not in PNG_CONTAINERS or not 1 <= bits <= container_bits:
        raise ValueError(f"{bits}-bit codes do not fit a {container_bits}-bit PNG container")
    return (1 << container_bits) - 1, (1 << bits) - 1


def scale_codes(codes: np.ndarray, bits: int, container_bits: int) -> np.ndarray:
    """N-bit codes -> the container's samples: floor(c (2^M-1)/(2^N-1) + 1/2), exactly."""
    full, top = _ratio_terms(bits, container_bits)
    codes = np.asarray(codes, dtype=np.int64)
    if codes.size and (codes.min() < 0 or codes.max() > top):
        raise ValueError(f"codes must lie in [0, {top}] for {bits} bits")
    scaled = (2 * codes * full + top) // (2 * top)
    return scaled.astype(np.uint8 if container_bits == 8 else np.uint16)


def unscale_codes(samples: np.ndarray, bits: int, container_bits: int) -> np.ndarray:
    """The container's samples -> N-bit codes (uint16): floor(v (2^N-1)/(2^M-1) + 1/2)."""
    full, top = _ratio_terms(bits, container_bits)
    samples = np.asarray(samples, dtype=np.int64)
    return ((2 * samples * top + full) // (2 * full)).astype(np.uint16)


def write_png(handle, codes: np.ndarray, bits: int, container_bits: int) -> None:
    """Write (H, W, C) codes of `bits` bits (C = 1 grey, 2 grey and alpha, 3 RGB, 4 RGBA)
    to the binary file `handle` as a PNG of `container_bits` bits per sample, with an sBIT
    chunk when bits < container_bits."""
    codes = np.asarray(codes)
    if codes.ndim != 3 or codes.shape[2] not in (1, 2, 3, 4):
        raise ValueError(f"codes must be (H, W, 1|2|3|4), got shape {codes.shape}")
    height, width, planes = codes.shape
    samples = scale_codes(codes, bits, container_bits)
    rows = samples.astype(">u2") if container_bits == 16 else samples    # PNG is big-endian
    rows = rows.reshape(height, -1).view(np.uint8)
    buffer = io.BytesIO()
    png.Writer(width, height, greyscale=planes < 3, alpha=planes in (2, 4),
               bitdepth=container_bits).write_packed(buffer, rows)
    chunks = list(png.Reader(bytes=buffer.getvalue()).chunks())
    if bits < container_bits:            # sBIT: after IHDR, before the image data
        chunks.insert(1, (b"sBIT", bytes([bits] * planes)))
    png.write_chunks(handle, chunks)


class PngCodes(NamedTuple):
    """What `read_png` returns: codes (H, W, C) uint16, the bits of each channel's codes
    (sBIT's, else the container's) and the container's bits per sample."""
    codes: np.ndarray
    bits: tuple[int, ...]
    container_bits: int


def read_png(source) -> PngCodes:
    """The codes of a PNG file (a path or its bytes), unscaled by its sBIT chunk (module
    docstring). A palette image is expanded to its colours, as stored."""
    data = source if isinstance(source, bytes) else Path(source).read_bytes()
    reader = png.Reader(bytes=data)
    width, height, rows, info = reader.read()
    if info.get("palette"):
        width, height, rows, info = png.Reader(bytes=data).asDirect()
    planes, container = info["planes"], info["bitdepth"]
    samples = np.vstack([np.asarray(row, dtype=np.uint16) for row in rows]).reshape(height, width, planes)
    if info.get("palette") or not reader.sbit:
        return PngCodes(samples, (container,) * planes, container)
    significant = tuple(reader.sbit)
    if len(significant) != planes or not all(1 <= b <= container for b in significant):
        raise ValueError(f"sBIT {significant} does not fit {planes} channels of {container} bits")
    codes = np.stack([unscale_codes(samples[..., i], significant[i], container)
                      for i in range(planes)], axis=-1)
    return PngCodes(codes, significant, container)


def write_exr(handle, array: np.ndarray) -> None:
    """Write float32 (H, W, 3|4) colour (channels R, G, B(, A)) or an (H, W) plane (channel
    Z: depth) to the binary file `handle` as OpenEXR, row 0 at the top."""
    array = np.ascontiguousarray(array, dtype=np.float32)
    if array.ndim == 2:
        channels = {EXR_DEPTH: array}
    elif array.ndim == 3 and array.shape[2] in EXR_COLOUR:
        channels = {EXR_COLOUR[array.shape[2]]: array}
    else:
        raise ValueError(f"an OpenEXR image is (H, W, 3|4) colour or an (H, W) plane, got {array.shape}")
    OpenEXR.File(dict(EXR_HEADER), channels).write(handle)      # the binding fills the dict in


def read_exr(source) -> np.ndarray:
    """The float32 pixels of an OpenEXR file written by `write_exr`: (H, W, 3|4) or (H, W)."""
    exr = OpenEXR.File(str(source))
    channels = exr.channels()
    if len(channels) != 1:
        raise ValueError(f"expected one colour group or one plane, got channels {sorted(channels)}")
    (channel,) = channels.values()
    return np.asarray(channel.pixels, dtype=np.float32)
