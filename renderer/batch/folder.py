"""DIR, a batch's output folder: one driver at a time, and nothing read or written outside it.

    with locked(out) as out:                       # DIR/.renderer-batch.lock, held until the end
        check_inside(out, ["items/a/image.png"])   # before writing: no link on the way
        digest = sha256_inside(out, "items/a/image.png")   # None: missing, or not to be read

The lock. `locked` makes DIR (and the folders above it that are missing), then takes an
exclusive, non-blocking `fcntl.flock` on LOCK_NAME inside it and writes who holds it: pid,
host and start time (UTC), as JSON. A second driver on the same DIR is refused in one line
naming them (UserError, exit status 2) before it reads the manifest. The lock goes with the
process (the kernel drops a flock when its holder dies, even by SIGKILL); on a normal end, an
error or Ctrl-C the file is removed, and the folders `locked` made are removed again when
nothing was written in them. A driver that takes the lock checks that the name still names
the file it locked (another driver may have removed it meanwhile) and tries again if not.

Inside DIR. Every path a batch writes or reads under DIR is relative, without '..', and
reaches its file through real folders only: `check_inside` refuses (one line, exit status 2)
a symbolic link among the folders on the way, so that a link such as DIR/items -> /elsewhere
is refused before any work rather than written through. A manifest record's paths are
`inside` or not (`manifest.py` drops a record with a path that leaves DIR); `sha256_inside`
reads only a regular file (stat before open, O_NOFOLLOW | O_NONBLOCK: a FIFO, a device or a
link is never opened for reading), so that a tampered record can neither hang the driver nor
make it read a file outside DIR.
"""

from __future__ import annotations

import contextlib
import errno
import fcntl
import hashlib
import json
import os
import socket
import stat
import time
from pathlib import Path, PurePosixPath
from typing import Iterable, Iterator

from renderer.core.imageio import check_folder
from renderer.core.jsonio import to_json
from renderer.core.paths import show_path
from renderer.errors import SystemFault, UserError

LOCK_NAME = ".renderer-batch.lock"
READ_FLAGS = os.O_RDONLY | os.O_NOFOLLOW | os.O_NONBLOCK | os.O_CLOEXEC
CHUNK = 1 << 20                 # bytes hashed at a time


def parts_inside(relative) -> tuple[str, ...] | None:
    """The names of a relative path under DIR ('a/b/c.png' -> ('a', 'b', 'c.png')), or None
    when it is not one: not a string, empty, absolute, or holding '..', '.' or a null byte."""
    if not isinstance(relative, str) or not relative or "\0" in relative:
        return None
    path = PurePosixPath(relative)
    if path.is_absolute() or any(part in ("..", ".") for part in relative.split("/")):
        return None
    return path.parts


def file_kind(path: Path) -> int | None:
    """The file type bits of `path` itself (a link is not followed), None when missing."""
    try:
        return stat.S_IFMT(os.lstat(path).st_mode)
    except (FileNotFoundError, NotADirectoryError):
        return None


def check_inside(out: Path, relatives: Iterable[str]) -> None:
    """Refuse (UserError naming the link) a path under `out` whose folders on the way are not
    all real folders: a symbolic link there would take the write outside DIR."""
    seen: dict[str, int | None] = {}            # a folder (relative) -> its kind
    for relative in relatives:
        parts = parts_inside(relative)
        if parts is None:
            raise UserError(f"{show_path(relative)!r} is not a path inside the output folder",
                            file=str(out))
        for depth in range(1, len(parts)):
            folder = "/".join(parts[:depth])
            if folder not in seen:
                seen[folder] = file_kind(out / folder)
            kind = seen[folder]
            if kind is None:
                break                            # made by the write: nothing below exists
            if kind == stat.S_IFLNK:
                raise UserError(f"{show_path(folder)} is a symbolic link; batch writes only inside "
                                f"its output folder, through no link: remove the link or give "
                                f"another --out", file=str(out))
            if kind != stat.S_IFDIR:
                raise UserError(f"{show_path(folder)} is not a folder, so nothing can be written "
                                f"in it", file=str(out))


def regular_inside(out: Path, relative) -> bool | None:
    """Whether `relative` names a regular file reached through real folders under `out`: True;
    False when it leaves DIR or is something else (a link, a FIFO, a device, a folder); None
    when it (or a folder on the way) does not exist. Nothing is opened."""
    parts = parts_inside(relative)
    if parts is None:
        return False
    for depth in range(1, len(parts) + 1):
        kind = file_kind(out.joinpath(*parts[:depth]))
        if kind is None:
            return None
        if kind != (stat.S_IFREG if depth == len(parts) else stat.S_IFDIR):
            return False
    return True


def sha256_inside(out: Path, relative: str) -> str | None:
    """SHA-256 of a regular file under `out` (regular_inside True), None when it cannot be
    read; opened without following a link and without blocking, its type checked again on
    the open file."""
    parts = parts_inside(relative)
    if parts is None:
        return None
    try:
        fd = os.open(out.joinpath(*parts), READ_FLAGS)
    except OSError:
        return None
    try:
        if not stat.S_ISREG(os.fstat(fd).st_mode):
            return None
        digest = hashlib.sha256()
        while chunk := os.read(fd, CHUNK):
            digest.update(chunk)
        return digest.hexdigest()
    except OSError:
        return None
    finally:
        os.close(fd)


# -- the lock ---------------------------------------------------------------------------------

def _make(out: Path) -> list[Path]:
    """Make `out` and the folders above it that are missing; those made, outermost first."""
    missing = [folder for folder in (out, *out.parents) if file_kind(folder) is None]
    made = []
    for folder in reversed(missing):
        try:
            folder.mkdir()
        except FileExistsError:
            continue
        except OSError as error:
            raise SystemFault(f"cannot make the folder: {_reason(error)}",
                              file=str(folder)) from None
        made.append(folder)
    return made


def _holder(fd: int) -> str:
    """Who holds the lock, as its file says (pid, host, start time), for the refusal."""
    try:
        found = json.loads(os.pread(fd, 4096, 0).decode("utf-8"))
        pid, host, started = int(found["pid"]), str(found["host"]), float(found["started"])
    except (OSError, ValueError, TypeError, KeyError):
        return "who holds it has not written its name yet"
    when = time.strftime("%Y-%m-%d %H:%M:%S UTC", time.gmtime(started))
    return f"pid {pid} on {show_path(host)}, since {when}"


def _open_lock(path: Path, out: Path) -> int:
    try:
        fd = os.open(path, os.O_RDWR | os.O_CREAT | os.O_NOFOLLOW | os.O_NONBLOCK | os.O_CLOEXEC,
                     0o644)
    except OSError as error:
        if error.errno == errno.ELOOP:
            raise UserError(f"{LOCK_NAME} is a symbolic link; remove it", file=str(out)) from None
        if error.errno in (errno.EISDIR, errno.ENXIO, errno.ENODEV):   # a folder, a socket, a device
            raise UserError(f"{LOCK_NAME} is not a regular file; remove it", file=str(out)) from None
        raise SystemFault(f"cannot make the lock file {LOCK_NAME}: {_reason(error)}",
                          file=str(out)) from None
    if not stat.S_ISREG(os.fstat(fd).st_mode):
        os.close(fd)
        raise UserError(f"{LOCK_NAME} is not a regular file; remove it", file=str(out))
    return fd


def _acquire(out: Path) -> int:
    """The lock file's descriptor, locked and holding this process's name."""
    path = out / LOCK_NAME
    while True:
        fd = _open_lock(path, out)
        try:
            try:
                fcntl.flock(fd, fcntl.LOCK_EX | fcntl.LOCK_NB)
            except BlockingIOError:
                raise UserError(f"another `renderer batch` is writing in this folder "
                                f"({_holder(fd)}); wait for it to end, or give another --out",
                                file=str(out)) from None
            except OSError as error:                 # a file system without locks (ENOLCK)
                raise SystemFault(f"cannot lock {LOCK_NAME}: {_reason(error)}",
                                  file=str(out)) from None
            try:
                same = os.lstat(path).st_ino == os.fstat(fd).st_ino
            except FileNotFoundError:
                same = False
            if same:                                 # else removed by its last holder: again
                _write_holder(fd, out)
                return fd
        except BaseException:
            os.close(fd)
            raise
        os.close(fd)


def _write_holder(fd: int, out: Path) -> None:
    """This process's name in the lock file, for a driver refused (`_holder`)."""
    name = {"pid": os.getpid(), "host": socket.gethostname(), "started": time.time()}
    try:
        os.ftruncate(fd, 0)
        os.pwrite(fd, (to_json(name) + "\n").encode(), 0)
    except OSError as error:
        raise SystemFault(f"cannot write {LOCK_NAME}: {_reason(error)}", file=str(out)) from None


def _reason(error: OSError) -> str:
    return (error.strerror or str(error)).lower()


def _release(out: Path, fd: int) -> None:
    path = out / LOCK_NAME
    try:
        if os.lstat(path).st_ino == os.fstat(fd).st_ino:
            os.unlink(path)                          # while still locked: nobody holds a stale one
    except OSError:
        pass
    os.close(fd)


@contextlib.contextmanager
def locked(out) -> Iterator[Path]:
    """DIR made and locked for this driver (module docstring): the checked Path."""
    out = check_folder(out)
    made = _make(out)
    try:
        fd = _acquire(out)
        try:
            yield out
        finally:
            _release(out, fd)
    finally:
        for folder in reversed(made):                # a refused or empty job leaves nothing
            try:
                folder.rmdir()
            except OSError:
                break
