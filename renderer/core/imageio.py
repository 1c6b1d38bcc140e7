"""Writing images and arrays atomically: a temporary file beside the target, then a rename,
so an interrupted write leaves the old file or the new one, never a truncated one.

`write_png` writes PNG whatever the name (goldens, compare's images); `write_image` writes the
format a user's file name asks for (`renderer render -o out.jpg`, screenshots), and
`image_format` refuses, before any work, a name whose format Pillow cannot write.
"""

from __future__ import annotations

import functools
import io
import os
import tempfile
from pathlib import Path

import numpy as np
from PIL import Image

from renderer.errors import UserError

# Pillow's defaults are for photographs (JPEG at quality 75 with halved chroma, lossy WebP);
# a render has sharp edges and flat colours: JPEG at 95 with full chroma, WebP lossless.
SAVE_OPTIONS = {"JPEG": {"quality": 95, "subsampling": 0}, "WEBP": {"lossless": True}}
SUGGESTED_SUFFIXES = ".png, .jpg, .webp, .tif, .bmp"
ALPHA_SUFFIXES = ".png, .webp or .tif"


def _umask() -> int:
    mask = os.umask(0)
    os.umask(mask)
    return mask


def _atomic_write(path: Path, write) -> None:
    path = Path(path)
    path.parent.mkdir(parents=True, exist_ok=True)
    fd, tmp = tempfile.mkstemp(prefix=f".{path.name}.", suffix=".tmp", dir=path.parent)
    try:
        with os.fdopen(fd, "wb") as handle:
            write(handle)
        os.chmod(tmp, 0o666 & ~_umask())     # mkstemp makes it private; give it a normal file's mode
        os.replace(tmp, path)
    except BaseException:
        os.unlink(tmp)
        raise


def write_png(path, image: np.ndarray) -> None:
    """Write an (H, W, 3|4) uint8 array, row 0 at the top, as PNG."""
    _atomic_write(path, lambda handle: Image.fromarray(np.ascontiguousarray(image)).save(handle, format="PNG"))


@functools.cache
def _pillow_writes(image_format: str, alpha: bool) -> bool:
    """Whether Pillow writes an RGB image (alpha False) or an RGBA image keeping an alpha
    channel (alpha True) in `image_format`: a 2x2 image written to memory and read back."""
    pixels = np.zeros((2, 2, 4 if alpha else 3), np.uint8)
    pixels[0, 0] = 255
    buffer = io.BytesIO()
    try:
        Image.fromarray(pixels).save(buffer, format=image_format)
        if not alpha:
            return True
        buffer.seek(0)
        with Image.open(buffer) as back:
            return "A" in back.mode or "transparency" in back.info
    except Exception:           # Pillow raises OSError, ValueError, KeyError, ... by format
        return False


def image_format(path, alpha: bool = False) -> str:
    """Pillow's name of the format the suffix of `path` asks for ("PNG", "JPEG", ...) when
    Pillow can write an image there (RGBA with its alpha kept, if `alpha`); otherwise a
    one-line UserError naming the file. Case does not matter: .JPG is JPEG."""
    path = Path(path)
    suffix = path.suffix.lower()
    if not suffix:
        raise UserError(f"no suffix to say the image format; name the file e.g. {path.name}.png "
                        f"or {path.name}.jpg", file=str(path))
    Image.init()
    found = Image.registered_extensions().get(suffix)
    if found is None or not _pillow_writes(found, alpha=False):
        raise UserError(f"cannot write {suffix} images; use {SUGGESTED_SUFFIXES} or another suffix "
                        f"Pillow writes", file=str(path))
    if alpha and not _pillow_writes(found, alpha=True):
        raise UserError(f"{found} ({suffix}) keeps no alpha channel, which a transparent background "
                        f"needs; use {ALPHA_SUFFIXES}", file=str(path))
    return found


def write_image(path, image: np.ndarray) -> None:
    """Write an (H, W, 3|4) uint8 array, row 0 at the top, in the format the suffix of `path`
    names (image_format; four channels need a format with alpha)."""
    image = np.ascontiguousarray(image)
    found = image_format(path, alpha=image.shape[2] == 4)
    _atomic_write(path, lambda handle: Image.fromarray(image).save(handle, format=found,
                                                                   **SAVE_OPTIONS.get(found, {})))


def write_npy(path, array: np.ndarray) -> None:
    _atomic_write(path, lambda handle: np.save(handle, array))


def write_text(path, text: str) -> None:
    write_bytes(path, text.encode())


def write_bytes(path, data: bytes) -> None:
    _atomic_write(path, lambda handle: handle.write(data))


def read_png(path) -> np.ndarray:
    with Image.open(path) as image:
        return np.asarray(image.convert("RGBA"))
