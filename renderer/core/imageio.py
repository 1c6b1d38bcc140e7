"""Writing images, arrays and text: every output of every command goes through one
transaction, `outputs()`, so that a command's files are written all or none, never half.

    with outputs() as out:                 # or outputs(path, path2): checked before any work
        out.image("out/img.png", rgba)     # each to a temporary file beside its target
        out.npy("out/depth.npy", depth)
    # leaving the block renames them all into place; an error inside it removes the temporaries

- Names are checked before anything is written (`check_outputs`, which a command also calls
  before it renders): an empty name, an existing folder, a parent path that is a file, and two
  outputs of one command that name the same file (after resolving `.`, `..` and symlinks) are
  a `UserError` (exit status 2).
- A write the system refuses (read-only folder or file system, full disk, I/O error) is a
  `SystemFault`, one line and exit status 1; the temporaries written so far are removed and
  every existing target is left as it was.
- Commit: each existing target is first hard-linked to a backup beside it, then every
  temporary is renamed over its target (os.replace, atomic per file). If a rename fails
  midway, the targets already renamed get their backups back (or are removed when they did
  not exist before). On a file system without hard links the backup is skipped, and a rename
  failing midway (the disk cannot fill then: a rename needs no space) leaves the files renamed
  before it new: that window is the only way to get a mix of old and new.
- Temporaries are named `.NAME.renderer-PID-XXXXXXXX.tmp` beside NAME. A process killed
  while writing (SIGKILL) cannot remove its own; the next write of NAME removes those whose
  PID is no longer alive (a PID reused meanwhile keeps its file until the next write after).

`image` writes the format a user's file name asks for (`renderer render -o out.jpg`,
screenshots) and `image_format` refuses, before any work, a name whose format Pillow cannot
write; `png` writes PNG whatever the name (goldens, compare's images); `png_codes` and `exr`
write the output stage's N-bit codes and float images (renderer/core/image_formats.py). `write_png`,
`write_image`, `write_npy`, `write_text` and `write_bytes` are one-file transactions.
"""
from __future__ import annotations

import contextlib
import errno
import functools
import io
import os
import re
import secrets
from pathlib import Path

import numpy as np
from PIL import Image

from renderer.core import image_formats
from renderer.errors import SystemFault, UserError

# Pillow's defaults are for photographs (JPEG at quality 75 with halved chroma, lossy WebP);
# a render has sharp edges and flat colours: JPEG at 95 with full chroma, WebP lossless.
SAVE_OPTIONS = {"JPEG": {"quality": 95, "subsampling": 0}, "WEBP": {"lossless": True}}
SUGGESTED_SUFFIXES = ".png, .jpg, .webp, .tif, .bmp"
ALPHA_SUFFIXES = ".png, .webp or .tif"


_TEMP = re.compile(r"\.(?P<name>.+)\.renderer-(?P<pid>\d+)-[0-9a-z_]+\.tmp")


def temp_name(path: Path) -> Path:
    """A fresh temporary file's name beside `path`: `.NAME.renderer-PID-XXXXXXXX.tmp`."""
    return path.with_name(f".{path.name}.renderer-{os.getpid()}-{secrets.token_hex(4)}.tmp")


def _alive(pid: int) -> bool:
    try:
        os.kill(pid, 0)
    except ProcessLookupError:
        return False
    except OSError:                  # EPERM: alive, someone else's
        return True
    return True


def remove_stale_temporaries(path: Path) -> list[Path]:
    """Remove the temporaries of `path` left by processes no longer alive (killed mid-write);
    the names removed."""
    removed = []
    try:
        entries = list(os.scandir(path.parent))
    except OSError:
        return removed
    for entry in entries:
        match = _TEMP.fullmatch(entry.name)
        if match and match["name"] == path.name and int(match["pid"]) != os.getpid() \
                and not _alive(int(match["pid"])):
            try:
                os.unlink(entry.path)
                removed.append(Path(entry.path))
            except OSError:
                pass
    return removed


def _fault(path, error: OSError) -> UserError:
    """The one line for an OSError while writing `path`: a bad name is a UserError (status 2),
    anything else the system refused is a SystemFault (status 1)."""
    reason = (error.strerror or str(error)).lower() if error.errno else str(error)
    if error.errno in (errno.EISDIR, errno.ENOTDIR, errno.ENAMETOOLONG, errno.EINVAL):
        return UserError(f"cannot write there: {reason}", file=str(path))
    return SystemFault(f"cannot write: {reason}", file=str(path))


def _name(path) -> Path:
    if path is None or str(path) == "":
        raise UserError("an empty output name; name the file, e.g. out.png")
    return Path(path)


def check_outputs(*paths) -> list[Path]:
    """Refuse, before any work, output names that cannot be written as files: an empty name,
    an existing folder, a parent path that is a file (or anything but a folder), and two names
    of one command that are the same file. The paths, as Path; None is skipped."""
    checked, seen = [], {}
    for given in paths:
        if given is None:
            continue
        path = _name(given)
        try:
            _check_one(path, seen)
        except OSError as error:          # a folder on the way we may not look into
            raise _fault(path, error) from None
        checked.append(path)
    return checked


def _check_one(path: Path, seen: dict) -> None:
    if path.is_dir():
        raise UserError(f"is a folder; name a file in it, e.g. {path / ('out' + (path.suffix or '.png'))}",
                        file=str(path))
    for parent in path.parents:
        if parent.exists() or parent.is_symlink():
            if not parent.is_dir():
                raise UserError(f"{parent} is not a folder, so nothing can be written in it",
                                file=str(path))
            break
    real = os.path.realpath(path)
    if real in seen:
        raise UserError(f"the same file as {seen[real]}; give each output its own name",
                        file=str(path))
    seen[real] = path


def check_folder(folder) -> Path:
    """An output folder (compare's, shaders', extremes', report's --out), checked before any
    work: a non-empty name that is a folder or can be made one (nothing on the way a file)."""
    folder = _name(folder)
    for path in (folder, *folder.parents):
        try:
            if path.exists() or path.is_symlink():
                if not path.is_dir():         # named once: "out: is not a folder, ..."
                    which = "is" if path == folder else f"{path} is"
                    raise UserError(f"{which} not a folder, so nothing can be written in it",
                                    file=str(folder))
                break
        except OSError as error:
            raise _fault(folder, error) from None
    return folder


class _Plain:
    """A file as a writer without a file descriptor. NumPy (tofile) and Pillow (encode_to_file)
    write to a real file's descriptor themselves and report a full disk as 'N requested and M
    written' or 'encoder error', without the errno; through this, every byte goes through
    Python's write, which raises OSError(ENOSPC) and the like as they are."""

    def __init__(self, handle):
        self._handle = handle

    def write(self, data) -> int:
        return self._handle.write(data)

    def flush(self) -> None:
        self._handle.flush()

    def seek(self, offset: int, whence: int = 0) -> int:
        return self._handle.seek(offset, whence)

    def tell(self) -> int:
        return self._handle.tell()


class Outputs:
    """The files of one command, written to temporaries and renamed into place together
    (`outputs()`; module docstring)."""

    def __init__(self, planned=()):
        self._planned = [p for p in planned if p is not None]
        check_outputs(*self._planned)
        self._staged: list[tuple[Path, Path]] = []       # (temporary, target)
        self._made: list[Path] = []                       # folders made for them

    @property
    def paths(self) -> list[Path]:
        return [target for _, target in self._staged]

    def _write(self, path, write) -> Path:
        path = _name(path)
        check_outputs(*self.paths, path)
        for parent in reversed(path.parents):
            if not parent.exists():
                try:
                    parent.mkdir()
                except FileExistsError:
                    pass
                except OSError as error:
                    raise _fault(path, error) from None
                else:
                    self._made.append(parent)
        remove_stale_temporaries(path)
        tmp = temp_name(path)
        try:
            fd = os.open(tmp, os.O_WRONLY | os.O_CREAT | os.O_EXCL, 0o666)   # less the umask
        except OSError as error:
            raise _fault(path, error) from None
        self._staged.append((tmp, path))
        try:
            with os.fdopen(fd, "wb") as handle:
                write(_Plain(handle))
        except OSError as error:
            raise _fault(path, error) from None
        return path

    def image(self, path, image: np.ndarray) -> Path:
        """An (H, W, 3|4) uint8 array, row 0 at the top, in the format the suffix of `path`
        names (image_format; four channels need a format with alpha)."""
        image = np.ascontiguousarray(image)
        found = image_format(path, alpha=image.shape[2] == 4)
        return self._write(path, lambda handle: Image.fromarray(image).save(
            handle, format=found, **SAVE_OPTIONS.get(found, {})))

    def png(self, path, image: np.ndarray) -> Path:
        """An (H, W, 3|4) uint8 array, row 0 at the top, as PNG whatever the suffix."""
        image = np.ascontiguousarray(image)
        return self._write(path, lambda handle: Image.fromarray(image).save(handle, format="PNG"))

    def png_codes(self, path, codes: np.ndarray, bits: int, container_bits: int) -> Path:
        """(H, W, 1|2|3|4) codes of `bits` bits as a PNG of `container_bits` (8 or 16) bits
        per sample, whatever the suffix (renderer/core/image_formats.py: scaling, sBIT)."""
        return self._write(path, lambda handle: image_formats.write_png(handle, codes, bits, container_bits))

    def exr(self, path, array: np.ndarray) -> Path:
        """float32 (H, W, 3|4) colour or an (H, W) plane as OpenEXR (image_formats.write_exr)."""
        return self._write(path, lambda handle: image_formats.write_exr(handle, array))

    def npy(self, path, array: np.ndarray) -> Path:
        return self._write(path, lambda handle: np.save(handle, array))

    def text(self, path, text: str) -> Path:
        return self.bytes(path, text.encode())

    def bytes(self, path, data: bytes) -> Path:
        return self._write(path, lambda handle: handle.write(data))

    def discard(self) -> None:
        """Remove every temporary (and the folders made for them, when empty)."""
        for tmp, _ in self._staged:
            try:
                os.unlink(tmp)
            except FileNotFoundError:
                pass
        self._staged = []
        for folder in reversed(self._made):
            try:
                folder.rmdir()
            except OSError:
                pass
        self._made = []

    def commit(self) -> None:
        """Rename every temporary over its target; all or none (module docstring)."""
        backups: dict[Path, Path | None] = {}        # target -> its backup (None: none existed)
        renamed: list[Path] = []
        try:
            for _, target in self._staged:
                backups[target] = None
                if target.exists():
                    backup = temp_name(target)
                    try:
                        os.link(target, backup)
                        backups[target] = backup
                    except OSError:
                        del backups[target]          # no hard links here: no way back
            for tmp, target in self._staged:
                try:
                    os.replace(tmp, target)
                except OSError as error:
                    raise _fault(target, error) from None
                renamed.append(target)
        except BaseException:
            for target in reversed(renamed):         # put back what was already renamed
                if target in backups:
                    try:
                        if backups[target] is None:
                            os.unlink(target)
                        else:
                            os.replace(backups.pop(target), target)
                    except OSError:
                        pass
            self.discard()
            raise
        finally:
            for backup in backups.values():
                if backup is not None:
                    try:
                        os.unlink(backup)
                    except FileNotFoundError:
                        pass
        self._staged = []
        self._made = []


@contextlib.contextmanager
def outputs(*planned):
    """`with outputs() as out: out.image(...); out.npy(...)`: every file written to a
    temporary, all renamed into place when the block ends, none when it raises. `planned`
    names are checked first (check_outputs)."""
    transaction = Outputs(planned)
    try:
        yield transaction
    except BaseException:
        transaction.discard()
        raise
    transaction.commit()


def write_png(path, image: np.ndarray) -> None:
    """Write an (H, W, 3|4) uint8 array, row 0 at the top, as PNG."""
    with outputs() as out:
        out.png(path, image)


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
    Image.preinit()             # the common formats (PNG, JPEG, BMP, GIF, PPM): no more is
    found = Image.EXTENSION.get(suffix)         # loaded for them (init() imports every plugin)
    if found is None:
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
    with outputs() as out:
        out.image(path, image)


def write_npy(path, array: np.ndarray) -> None:
    with outputs() as out:
        out.npy(path, array)


def write_text(path, text: str) -> None:
    write_bytes(path, text.encode())


def write_bytes(path, data: bytes) -> None:
    with outputs() as out:
        out.bytes(path, data)


def read_png(path) -> np.ndarray:
    with Image.open(path) as image:
        return np.asarray(image.convert("RGBA"))
