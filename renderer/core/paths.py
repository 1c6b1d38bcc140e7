"""Every path a user gives, checked in one place before anything uses it.

    checked_path("scene.toml")                     -> Path("scene.toml")
    checked_path(text, file="s.toml", key="objects[0].mesh.file", error=SceneError)

The scene argument, each mesh file a scene names and every output option (-o, --depth,
--out, --screenshot, --stats, --cache) go through `checked_path`, so that a path the
operating system cannot take is one line naming the file and the reason, not an OSError or
ValueError from deep inside pathlib (`Path.is_file()` raises on a name too long, and on a
folder on the way that cannot be searched). Refused:

- a null byte (no operating system call takes one);
- a path longer than PATH_MAX - 1 = 4095 bytes, or a file or folder name in it longer than
  NAME_MAX = 255 bytes (Linux's limits; encoded as the file system encodes it);
- a path whose status cannot be asked for (`stat`) for another reason than "it does not
  exist": permission denied on a folder on the way, a loop of symbolic links, ...

A path that does not exist passes: whether it must exist is the caller's question.

`output_stem` is the safe file-name stem of a scene, for default output names.
"""

from __future__ import annotations

import errno
import os
import re
from pathlib import Path

from renderer.errors import UserError

NAME_MAX = 255                   # bytes in one file or folder name (Linux)
PATH_MAX = 4096                  # bytes in a whole path, with its terminating null (Linux)
SHOWN_MAX = 80                   # characters of a path shown in a message


def show_path(path) -> str:
    """A path as a one-line message shows it: control characters escaped, long ones
    shortened in the middle."""
    text = os.fspath(path) if not isinstance(path, str) else path
    if isinstance(text, bytes):
        text = text.decode("utf-8", "backslashreplace")
    text = "".join(c if c.isprintable() else ascii(c)[1:-1] for c in text)
    if len(text) > SHOWN_MAX:
        text = f"{text[:SHOWN_MAX // 2 - 2]}...{text[-(SHOWN_MAX // 2 - 1):]}"
    return text


def _stat(path: Path) -> None:
    """The probe (a seam for tests: root may look in any folder)."""
    os.stat(path)


def path_problem(path) -> str | None:
    """Why the operating system cannot take `path`, or None when it can."""
    text = os.fspath(path)
    if isinstance(text, bytes):
        text = os.fsdecode(text)
    if "\0" in text:
        return "the path contains a null byte"
    try:
        encoded = os.fsencode(text)
    except UnicodeError:
        return "the path cannot be encoded for the file system"
    if len(encoded) >= PATH_MAX:
        return (f"the path is {len(encoded)} bytes long; the longest a path can be is "
                f"{PATH_MAX - 1} bytes (PATH_MAX)")
    for part in encoded.split(b"/"):
        if len(part) > NAME_MAX:
            return (f"a name in the path is {len(part)} bytes long "
                    f"({show_path(os.fsdecode(part))!r}); the longest is {NAME_MAX} bytes (NAME_MAX)")
    try:
        _stat(Path(text))
    except (FileNotFoundError, NotADirectoryError):
        return None
    except PermissionError:
        return "permission denied: a folder on the way cannot be searched"
    except OSError as exc:
        if exc.errno == errno.ELOOP:
            return "too many levels of symbolic links"
        return f"cannot use this path: {exc.strerror or exc}"
    except ValueError as exc:
        return f"cannot use this path: {exc}"
    return None


def checked_path(path, *, file: str | None = None, key: str | None = None,
                 error: type[UserError] = UserError) -> Path:
    """`path` as a Path, or a one-line `error` (UserError or SceneError) saying why not.
    The line names `file` and `key` when given (a scene file and the key that names the
    path; the path itself then starts the reason), else the path itself."""
    problem = path_problem(path)
    if problem is None:
        return Path(path)
    if file is None:
        raise error(problem, file=show_path(path), key=key)
    raise error(f"{show_path(path)}: {problem}", file=file, key=key)


# Where a command writes when not told: never the current folder itself (a checkout would
# collect render's, compare's and shaders' outputs among its files); `out/` is git-ignored.
DEFAULT_OUT = Path("out")


def default_output(name: str) -> Path:
    """The path of an output a command names itself (`SCENE.png`, `compare-SCENE`): in
    DEFAULT_OUT, under the current folder."""
    return DEFAULT_OUT / name


def output_stem(scene) -> str:
    """The stem of a scene's default output names (render's SCENE.png, compare-SCENE/, the
    viewer's view-SCENE-NNN.png, the ground-truth cache's files): the stem of the file it was
    read from (a built-in scene's is its name), never the free-text `name` inside the file;
    for a scene made in Python (no file), its name. Made safe as one file name: characters
    other than ASCII letters, digits, '.', '-' and '_' become '_', no leading dot, at most
    100 characters, and "scene" if nothing is left."""
    source = getattr(scene, "source", "") or ""
    text = Path(source).stem if source else str(getattr(scene, "name", "") or "")
    stem = re.sub(r"[^A-Za-z0-9._-]", "_", text).lstrip(".")[:100]
    return stem or "scene"
