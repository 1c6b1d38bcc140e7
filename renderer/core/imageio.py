"""Writing images and arrays atomically: a temporary file beside the target, then a rename,
so an interrupted write leaves the old file or the new one, never a truncated one."""

from __future__ import annotations

import os
import tempfile
from pathlib import Path

import numpy as np
from PIL import Image


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


def write_npy(path, array: np.ndarray) -> None:
    _atomic_write(path, lambda handle: np.save(handle, array))


def write_text(path, text: str) -> None:
    write_bytes(path, text.encode())


def write_bytes(path, data: bytes) -> None:
    _atomic_write(path, lambda handle: handle.write(data))


def read_png(path) -> np.ndarray:
    with Image.open(path) as image:
        return np.asarray(image.convert("RGBA"))
