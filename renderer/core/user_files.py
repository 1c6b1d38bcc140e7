"""Every file a user names is opened here, one way: a regular file, no larger than its kind's cap.

    with open_user_file(path, SCENE_FILE) as handle: ...        # a binary file object
    data = read_user_file(path, IMAGE_FILE)                     # its bytes, at most the cap
    image = open_image(handle_or_bytes, max_side=16384, bytes_per_pixel=160)   # lazy Pillow
    shape, dtype = npy_header(handle)                           # before np.load
    target = confined(folder, uri)                              # a glTF's resources

A scene, job, mesh, texture, glTF buffer or image, manifest, `renderer colour`'s image or
.npy: whatever its kind, a path a user gave (or a file of theirs names) is

- asked for its status first (`stat`), so that a FIFO, a device (/dev/zero), a folder or a
  socket is refused in one line naming what it is, before anything opens it;
- opened with O_NONBLOCK, so that a FIFO swapped in after the stat cannot hang the open, and
  the open file's own status (`fstat`) checked again: what is read is the regular file seen;
- refused when larger than its kind's cap (USER_FILE_CAPS), before a byte is read, and never
  read past the cap even if it grows meanwhile.

Each refusal is a `FileRefused` whose reason never quotes the file's contents; the callers
turn it into their one-line UserError or SceneError (`refuse`, with checked_path's rule for
naming the file). renderer/core/paths.py checks the path itself first; this module the file.
tests/test_user_files.py walks renderer/ for any other open of a user's file.
"""

from __future__ import annotations

import contextlib
import os
import stat
import threading
import warnings
from pathlib import Path
from typing import BinaryIO

from renderer.core import memory
from renderer.core.paths import show_path
from renderer.errors import UserError

MIB = 1 << 20
GIB = 1 << 30

# Kinds of file, as the refusals name them.
SCENE_FILE = "scene file"
JOB_FILE = "job file"
MESH_FILE = "mesh file"
GLTF_RESOURCE = "glTF resource"        # a .gltf's buffer or image file (its JSON: MESH_FILE)
IMAGE_FILE = "image file"
ARRAY_FILE = "NumPy array file"
MANIFEST_FILE = "manifest"

# The caps, in bytes, checked before reading. Each is far above any file the kind holds in
# use, and low enough that reading (and parsing) a file at the cap stays bounded:
USER_FILE_CAPS = {
    # tomllib parses about 3 MiB a second: 8 MiB is ~100,000 objects written out in full, a
    # few seconds of parsing; geometry beyond that belongs in mesh files.
    SCENE_FILE: 8 * MIB,
    # a job's largest parts (poses, sweep values: at most 100,000 each) fit in 8 MiB; the
    # same parser, the same bound in time.
    JOB_FILE: 8 * MIB,
    # a binary STL of 80 million triangles (50 bytes each); the memory limit (16 bytes of
    # parsing per byte, renderer/core/memory.py MESH_PARSE_FACTOR) refuses most files below.
    MESH_FILE: 4 * GIB,
    # a .gltf's external buffer is its geometry: the mesh files' bound.
    GLTF_RESOURCE: 4 * GIB,
    # a 16384 x 16384 16-bit RGBA PNG stored without compression (2 GiB and its rows'
    # filter bytes and chunk headers): the largest image the output stage writes.
    IMAGE_FILE: 2 * GIB + 64 * MIB,
    # a 16384 x 16384 float32 RGBA frame (4 GiB) and its header.
    ARRAY_FILE: 4 * GIB + MIB,
    # a job's records (at most 100,000 items, renderer/batch/job_file.py MAX_ITEMS) of
    # well under 1 kB each, with room to spare.
    MANIFEST_FILE: 1 * GIB,
}

READ_CHUNK = 64 * MIB          # read_capped: a file that grew is read on in these

# What a file that is not a regular file is, as the refusal says it.
_NOT_REGULAR = ((stat.S_ISDIR, "a directory"), (stat.S_ISFIFO, "a named pipe (FIFO)"),
                (stat.S_ISCHR, "a character device"), (stat.S_ISBLK, "a block device"),
                (stat.S_ISSOCK, "a socket"))


class FileRefused(Exception):
    """Why a user's file is not read: `reason`, one line that never quotes the file."""

    def __init__(self, reason: str):
        self.reason = reason
        super().__init__(reason)


def refuse(refused: FileRefused, path, *, file: str | None = None, key: str | None = None,
           error: type[UserError] = UserError) -> UserError:
    """The one-line `error` for a refusal of `path`: named as checked_path names it ("PATH:
    reason", or "FILE: KEY: PATH: reason" when a scene or job file `file` named it)."""
    if file is None:
        return error(refused.reason, file=show_path(path), key=key)
    return error(f"{show_path(path)}: {refused.reason}", file=file, key=key)


def _article(kind: str) -> str:
    return "an" if kind[0] in "aeiouAEIOU" else "a"


def _check_status(status: os.stat_result, kind: str) -> None:
    for test, what in _NOT_REGULAR:
        if test(status.st_mode):
            raise FileRefused(f"is {what}, not a regular file; {_article(kind)} {kind} must be one")
    if not stat.S_ISREG(status.st_mode):
        raise FileRefused(f"is not a regular file; {_article(kind)} {kind} must be one")
    cap = USER_FILE_CAPS[kind]
    if status.st_size > cap:
        raise FileRefused(f"is {memory.show(status.st_size)}; {_article(kind)} {kind} is at "
                          f"most {memory.show(cap)}")


def open_user_file(path, kind: str) -> BinaryIO:
    """`path` opened for reading in binary, after the checks of the module docstring; a
    FileRefused otherwise (not found, not a regular file, over the cap, unreadable)."""
    if kind not in USER_FILE_CAPS:
        raise ValueError(f"unknown kind of file {kind!r}; one of {', '.join(USER_FILE_CAPS)}")
    try:
        _check_status(os.stat(path), kind)
        fd = os.open(path, os.O_RDONLY | os.O_NONBLOCK | os.O_NOCTTY | os.O_CLOEXEC)
    except (FileNotFoundError, NotADirectoryError):
        raise FileRefused(f"{kind} not found") from None
    except OSError as exc:
        raise FileRefused(f"cannot read: {exc.strerror or exc}") from None
    try:
        _check_status(os.fstat(fd), kind)          # the file opened is the file checked
        os.set_blocking(fd, True)                  # no effect on a regular file; tidy
        return os.fdopen(fd, "rb")
    except BaseException:
        os.close(fd)
        raise


def read_user_file(path, kind: str) -> bytes:
    """The bytes of `path` (open_user_file's checks), never more than the kind's cap."""
    cap = USER_FILE_CAPS.get(kind)
    with open_user_file(path, kind) as handle:
        return read_capped(handle, kind, cap)


def read_capped(handle: BinaryIO, kind: str, cap: int | None = None) -> bytes:
    """The rest of `handle`, refused if it is more than the kind's cap (a file that grew
    after it was checked is not read on)."""
    cap = USER_FILE_CAPS[kind] if cap is None else cap
    # Asked for what the file holds (and a byte more, to see it end), never for the cap:
    # a read of n bytes takes n bytes of memory before it reads one (a 4 GiB cap would
    # take 4 GiB for a 100-byte file, or fail under an address-space limit).
    try:
        try:
            want = os.fstat(handle.fileno()).st_size - handle.tell() + 1
        except (AttributeError, OSError, ValueError):      # not a file: read in chunks
            want = READ_CHUNK
        chunks, total = [], 0
        while total <= cap:
            asked = max(1, min(want, cap + 1 - total))
            block = handle.read(asked)
            chunks.append(block)
            total += len(block)
            if len(block) < asked:                         # its end
                break
            want = READ_CHUNK                              # it grew: on, up to the cap
        data = b"".join(chunks)
    except OSError as exc:
        raise FileRefused(f"cannot read: {exc.strerror or exc}") from None
    if len(data) > cap:
        raise FileRefused(f"grew past {memory.show(cap)} while read; {_article(kind)} {kind} "
                          f"is at most {memory.show(cap)}")
    return data


def confined(folder: Path, uri: str, what: str, owner: str = "glTF") -> Path:
    """The file `uri` (already URL-decoded) names inside `folder`, or a FileRefused when it
    leaves it: an absolute path, '..' out of it, or a symbolic link that leads out (trimesh's
    rule for a glTF's buffers, FilePathResolver). `what` names the thing, `owner` the file
    whose folder it is, in the refusal."""
    root = Path(folder).resolve()
    rule = f"a {owner}'s resources are data: URIs or files in its own folder"
    if not uri or os.path.isabs(uri):
        raise FileRefused(f"{what} {show_path(uri)!r} is not a relative path; {rule}")
    if "\0" in uri:                                     # (resolve would raise ValueError)
        raise FileRefused(f"{what} {show_path(uri)!r} contains a null byte, which no file "
                          f"name holds")
    target = (root / uri).resolve()
    if not target.is_relative_to(root):
        raise FileRefused(f"{what} {show_path(uri)!r} leaves the {owner}'s folder; {rule}")
    return target


def read_resource(folder: Path, uri: str, what: str, owner: str = "glTF") -> bytes:
    """The bytes of the file `uri` names in `folder` (`confined`, then read_user_file as a
    GLTF_RESOURCE); a refusal to read it names it: "uri 'x.bin': is a named pipe ..."."""
    target = confined(folder, uri, what, owner)
    try:
        return read_user_file(target, GLTF_RESOURCE)
    except FileRefused as refused:
        raise FileRefused(f"{what} {show_path(uri)!r}: {refused.reason}") from None


# --------------------------------------------------------------------------- images

# Pillow refuses (DecompressionBombError) an image of more than 2 * MAX_IMAGE_PIXELS (about
# 13,400 squared) and warns above MAX_IMAGE_PIXELS, a process-wide setting. The checks here
# replace its: a side limit where the caller has one and the memory limit, on the size the
# header declares. Pillow's is set aside only while `open_image` opens (under a lock, so
# that another thread's open keeps its own rule), and put back.
_PILLOW_LOCK = threading.Lock()


@contextlib.contextmanager
def _pillow_checks_off():
    from PIL import Image
    with _PILLOW_LOCK, warnings.catch_warnings():
        warnings.simplefilter("ignore", Image.DecompressionBombWarning)
        before, Image.MAX_IMAGE_PIXELS = Image.MAX_IMAGE_PIXELS, None
        try:
            yield
        finally:
            Image.MAX_IMAGE_PIXELS = before


def image_size_problem(width: int, height: int, *, max_side: int | None,
                       bytes_per_pixel: int, what: str = "image",
                       side: str = "pixels on a side") -> str | None:
    """Why an image of width x height (as its header declares) is not decoded, or None:
    no pixels, a side over `max_side` (None: no such limit; `side` says the unit and the
    rule), or more memory than the limit at `bytes_per_pixel` (the whole use of a pixel,
    decoding included)."""
    if width <= 0 or height <= 0:
        return f"image has no pixels ({width} x {height})"
    if max_side is not None and max(width, height) > max_side:
        return f"image is {width} x {height}; {_article(what)} {what} is at most {max_side} {side}"
    too_much = memory.over_limit(width * height * bytes_per_pixel, loading=True)
    if too_much:
        return f"a {width} x {height} {what} {too_much}"
    return None


def open_image(source, *, max_side: int | None, bytes_per_pixel: int, what: str = "image",
               side: str = "pixels on a side"):
    """A Pillow image of `source` (a binary file object or bytes), opened but not decoded
    (Pillow reads only the header), after image_size_problem's checks on its declared size;
    a FileRefused otherwise, Pillow's own errors included. The caller loads it (`.load()`,
    `.convert`) and closes it."""
    import io

    from PIL import Image, UnidentifiedImageError

    stream = io.BytesIO(source) if isinstance(source, (bytes, bytearray)) else source
    try:
        with _pillow_checks_off():
            image = Image.open(stream)
    except UnidentifiedImageError:
        raise FileRefused("could not be read as an image: not a format Pillow knows") from None
    except (OSError, SyntaxError, ValueError, EOFError, Image.DecompressionBombError) as exc:
        raise FileRefused(f"could not be read as an image: {_first_line(exc)}") from None
    problem = image_size_problem(*image.size, max_side=max_side,
                                 bytes_per_pixel=bytes_per_pixel, what=what, side=side)
    if problem is None and image.format == "PNG":
        problem = png_data_problem(stream)
    if problem:
        image.close()
        raise FileRefused(problem)
    return image


# Adam7's passes: (first column, first row, column step, row step).
_ADAM7 = ((0, 0, 8, 8), (4, 0, 8, 8), (0, 4, 4, 8), (2, 0, 4, 4), (0, 2, 2, 4), (1, 0, 2, 2),
          (0, 1, 1, 2))
_PNG_CHANNELS = {0: 1, 2: 3, 3: 1, 4: 2, 6: 4}       # by colour type
_INFLATE_STEP = 16 << 20                             # bytes of output inflated at a time


def png_data_problem(stream) -> str | None:
    """Why a PNG's image data does not hold the rows its header declares, or None. Pillow
    draws missing rows black without a word when the compressed stream ends early but
    properly (a file cut and mended, a writer that stopped): the IDAT stream is inflated
    here, a bounded step at a time and counted, never held, and its length held against the
    header's rows (Adam7's seven passes for an interlaced file). The stream's position is
    put back."""
    import struct
    import zlib

    start = stream.tell()
    try:
        stream.seek(0)
        if stream.read(8) != b"\x89PNG\r\n\x1a\n":
            return None                                 # Pillow's own checks said PNG
        expected, inflater, inflated = None, zlib.decompressobj(), 0
        while True:
            head = stream.read(8)
            if len(head) < 8:
                break
            length, kind = struct.unpack(">I4s", head)
            if kind == b"IHDR" and length >= 13:
                width, height, depth, colour, _, _, interlace = struct.unpack(">IIBBBBB", stream.read(13))
                stream.seek(length - 13 + 4, 1)
                bits = _PNG_CHANNELS.get(colour, 4) * depth
                passes = _ADAM7 if interlace else ((0, 0, 1, 1),)
                expected = 0
                for x0, y0, dx, dy in passes:
                    columns, rows = -(-(width - x0) // dx), -(-(height - y0) // dy)
                    if columns > 0 and rows > 0:
                        expected += rows * (1 + -(-columns * bits // 8))
            elif kind == b"IDAT":
                left = length
                while left > 0 and not inflater.eof:
                    block = stream.read(min(left, 1 << 20))
                    if not block:
                        break
                    left -= len(block)
                    while block and not inflater.eof:
                        inflated += len(inflater.decompress(block, _INFLATE_STEP))
                        block = inflater.unconsumed_tail
                stream.seek(left + 4, 1)
            elif kind == b"IEND":
                break
            else:
                stream.seek(length + 4, 1)
        while not inflater.eof:                         # what the last step left inflated
            more = inflater.decompress(b"", _INFLATE_STEP)
            if not more:
                break
            inflated += len(more)
    except (OSError, struct.error, zlib.error):
        return None                                     # Pillow's decode will say what is wrong
    finally:
        stream.seek(start)
    if expected is not None and inflated < expected:
        return (f"is truncated: its image data holds {inflated:,} of the {expected:,} bytes "
                f"its header's {width} x {height} pixels need (rows are missing)")
    return None


def _first_line(exc: BaseException) -> str:
    text = str(exc).strip()
    return text.splitlines()[0] if text else type(exc).__name__


# --------------------------------------------------------------------------- .npy

def npy_header(handle: BinaryIO) -> tuple[tuple[int, ...], object]:
    """(shape, dtype) from a .npy file's header, the handle left at its start; a FileRefused
    for a file that is not one (or holds Python objects, which are never loaded)."""
    import tokenize

    from numpy.lib import format as npy_format

    try:
        # NumPy retries a header it cannot parse as one written by Python 2 (tokenize, with
        # its own errors) and warns when that works: neither reaches the user
        with warnings.catch_warnings():
            warnings.simplefilter("ignore")
            version = npy_format.read_magic(handle)
            read = {(1, 0): npy_format.read_array_header_1_0,
                    (2, 0): npy_format.read_array_header_2_0}.get(version)
            if read is None:
                raise ValueError(f"unsupported .npy format version {version}")
            shape, _, dtype = read(handle)
    except (ValueError, OSError, EOFError, SyntaxError, tokenize.TokenError) as exc:
        raise FileRefused(f"could not be read as a .npy array: {_first_line(exc)}") from None
    if dtype.hasobject:
        raise FileRefused("holds Python objects, not numbers; a .npy image holds numbers")
    handle.seek(0)
    return tuple(int(n) for n in shape), dtype
