"""User-facing errors: one line naming the file, the key and the reason.

The command line turns a `UserError` into that line on stderr and its `status`: 2 for a
mistake in what the user gave (a bad scene, option or output name), 1 for a `SystemFault`,
where the system failed us (a read-only folder or file system, a full disk, an I/O error).
Anything else is a bug and keeps its traceback.
"""

from __future__ import annotations

import math
import unicodedata


INTERRUPTED = 130       # the exit status after Ctrl-C (128 + SIGINT, as a shell says it)


class UserError(Exception):
    """A mistake in the user's input (a scene file, a mesh, an option), not a bug."""

    status = 2          # the command line's exit status for it

    def __init__(self, reason: str, file: str | None = None, key: str | None = None):
        self.reason, self.file, self.key = reason, file, key
        super().__init__(self.line())

    def line(self) -> str:
        """FILE: KEY: REASON, always one line whatever the input: a file or key holding a line
        break or another control character is shown quoted (Python's repr), and such
        characters in the reason are escaped (\\n, \\x1b, \\u2028)."""
        where = ": ".join(quoted(part) for part in (self.file, self.key) if part)
        reason = escaped(self.reason)
        return f"{where}: {reason}" if where else reason


def _is_control(char: str) -> bool:
    # Cc: C0/C1 controls (\n, \r, \x1b, \x85, ...); Zl, Zp: U+2028, U+2029, which
    # str.splitlines and many terminals also take as line breaks.
    return unicodedata.category(char) in ("Cc", "Zl", "Zp")


def quoted(text: str) -> str:
    """`text` as it is, or repr-quoted when it holds a control character (a line break...)."""
    text = str(text)
    return repr(text) if any(_is_control(c) for c in text) else text


def escaped(text: str) -> str:
    """`text` with each control character written as its escape (newline as \\n)."""
    text = str(text)
    if not any(_is_control(c) for c in text):
        return text
    return "".join(repr(c)[1:-1] if _is_control(c) else c for c in text)


class UsageError(UserError):
    """A command line that argparse (or a check of how options go together) refuses. The
    command line prints `PROG: REASON` and then the usage line of the (sub)command PROG."""

    def __init__(self, reason: str, prog: str, usage: str):
        self.prog, self.usage = prog, usage
        super().__init__(reason)


class SystemFault(UserError):
    """The system refused what a correct command asked (writing to a read-only folder or file
    system, a full disk, an I/O error): one line like a UserError, but exit status 1."""

    status = 1


class OptionError(ValueError):
    """An option out of its range, or two that do not go together: `fields` names the options
    concerned by their field names (RayOptions', OutputSettings'), `reason` says why in words
    that name no front end's spelling. The rule is written once, where the options object is
    made; the command line and the job file each spell the fields their own way (`--spp 2
    --pattern adaptive`, `settings[0].samples`) in front of the same reason."""

    def __init__(self, fields: str | tuple[str, ...], reason: str):
        self.fields = (fields,) if isinstance(fields, str) else tuple(fields)
        self.reason = reason
        super().__init__(f"{', '.join(self.fields)}: {reason}")


class SceneError(UserError):
    """A scene file (or a mesh it names) that cannot be rendered."""


class ContextError(UserError):
    """No GL context could be made (missing system packages, no display)."""


def show_number(x: float) -> str:
    """A number as a message shows it: short, and nan / inf / -inf spelled as TOML does."""
    if math.isnan(x):
        return "nan"
    if math.isinf(x):
        return "inf" if x > 0 else "-inf"
    return f"{x:g}"
