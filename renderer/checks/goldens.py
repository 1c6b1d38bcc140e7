"""Golden images: a stored PNG per name, its JSON sidecar, and holding a frame against them.

    DIR/NAME.png    the expected RGBA8 image, row 0 on top
    DIR/NAME.json   its sidecar: what made it (scene, size, renderer version, GL_VENDOR,
                    GL_RENDERER, GL_VERSION, context), the policy it is held to, and the
                    SHA-256 of its pixels (so a PNG edited or half-updated since is noticed)

`check_golden(..., update=...)` is the only code that writes a golden; the pytest plugin
(renderer/checks/pytest_plugin.py) calls it so only under --update-goldens. `update="failing"`
(plain --update-goldens) writes missing goldens and rewrites only those the frame fails under
their policy (or whose PNG and sidecar disagree); `update="all"` (or True;
--update-goldens=all) rewrites every golden whose pixels differ at all. Writes are atomic
(renderer/core/imageio.py): an interrupted update leaves the old file or the new one, never a
truncated one. This module knows nothing of pytest.
"""

from __future__ import annotations

import hashlib
import json
import re
from dataclasses import dataclass
from pathlib import Path

import numpy as np

import renderer
from renderer.errors import UserError
from renderer.core.imageio import read_png, write_png, write_text
from renderer.core.jsonio import to_json
from renderer.checks.policies import Policy, Verdict, policy_from

SIDECAR_FORMAT = 1
NAME_PATTERN = re.compile(r"[A-Za-z0-9][A-Za-z0-9._-]{0,149}")
# What a test declares about its golden: when one of these changes, --update-goldens rewrites
# the sidecar even though the pixels are the same.
DECLARED_KEYS = ("format", "name", "scene", "size", "policy", "rgba_sha256")


class GoldenError(UserError):
    """Wrong use of a golden: a bad name, a golden of another size, an unreadable PNG or JSON."""


@dataclass
class Outcome:
    """What holding one frame against its golden found (or, when updating, did)."""
    name: str
    status: str                    # checking: "passed", "failed", "missing"; updating: "created",
                                   # "updated" (new pixels), "refreshed" (sidecar only), "unchanged"
    png: Path
    actual: np.ndarray             # the frame's RGBA8
    expected: np.ndarray | None    # the golden's pixels before this check (None if there was none)
    policy: Policy
    verdict: Verdict | None        # None when nothing was compared
    notes: list[str]               # what the message should also say (another GL implementation, ...)


def golden_paths(directory, name: str) -> tuple[Path, Path]:
    """(NAME.png, NAME.json) in `directory`, after checking the name is a plain file stem."""
    if not isinstance(name, str) or not NAME_PATTERN.fullmatch(name):
        raise GoldenError(f"{name!r} is not a golden name: use letters, digits, '.', '_' and '-' "
                          "(at most 150, starting with a letter or digit)", key="name")
    directory = Path(directory)
    return directory / f"{name}.png", directory / f"{name}.json"


def pixels_sha256(rgba8: np.ndarray) -> str:
    """SHA-256 of the pixels (not of the PNG's bytes, which depend on the encoder)."""
    digest = hashlib.sha256(f"{rgba8.shape[1]}x{rgba8.shape[0]}:".encode())
    digest.update(np.ascontiguousarray(rgba8, dtype=np.uint8).tobytes())
    return digest.hexdigest()


def read_golden(png: Path) -> np.ndarray:
    """The golden's (H, W, 4) uint8 pixels; GoldenError if the file is not a readable PNG."""
    try:
        with open(png, "rb") as handle:
            if handle.read(8) != b"\x89PNG\r\n\x1a\n":
                raise GoldenError("not a PNG file (its first bytes are not PNG's signature); restore "
                                  "it from version control or run pytest --update-goldens", file=str(png))
        return read_png(png)
    except GoldenError:
        raise
    except (OSError, SyntaxError, ValueError) as exc:     # Pillow's errors for a damaged file
        raise GoldenError(f"cannot be read as a PNG ({exc}); restore it from version control or "
                          "run pytest --update-goldens", file=str(png)) from None


def read_sidecar(path: Path) -> dict:
    try:
        data = json.loads(path.read_text(encoding="utf-8"))
    except FileNotFoundError:
        raise GoldenError("the golden has no JSON sidecar; run pytest --update-goldens to write it",
                          file=str(path)) from None
    except (OSError, UnicodeDecodeError, json.JSONDecodeError) as exc:
        raise GoldenError(f"cannot be read as JSON ({exc}); run pytest --update-goldens to rewrite it",
                          file=str(path)) from None
    if not isinstance(data, dict):
        raise GoldenError("must hold a JSON object", file=str(path))
    return data


def make_sidecar(name: str, rgba8: np.ndarray, policy: Policy, scene: str | None,
                 gl_info: dict | None) -> dict:
    gl_info = gl_info or {}
    return {
        "format": SIDECAR_FORMAT,
        "name": name,
        "scene": scene,
        "size": [int(rgba8.shape[1]), int(rgba8.shape[0])],
        "policy": policy.as_dict(),
        "rgba_sha256": pixels_sha256(rgba8),
        "renderer_version": renderer.__version__,
        "gl_vendor": gl_info.get("GL_VENDOR"),
        "gl_renderer": gl_info.get("GL_RENDERER"),
        "gl_version": gl_info.get("GL_VERSION"),
        "context": gl_info.get("context"),
    }


def implementation_note(sidecar: dict, gl_info: dict | None) -> str | None:
    """A sentence when the golden was made on another GL implementation than this frame."""
    if not gl_info or not gl_info.get("GL_RENDERER") or not sidecar.get("gl_renderer"):
        return None                                  # one side does not say what made it
    made = (sidecar.get("gl_renderer"), sidecar.get("gl_version"))
    now = (gl_info.get("GL_RENDERER"), gl_info.get("GL_VERSION"))
    if made == now:
        return None
    return (f"the golden was made on another GL implementation: {made[0]} / {made[1]}; this frame "
            f"comes from {now[0]} / {now[1]}, so a difference may be the implementation's, not your change")


def _size(rgba8: np.ndarray) -> str:
    return f"{rgba8.shape[1]}x{rgba8.shape[0]}"


UPDATE_MODES = ("failing", "all")


def check_golden(directory, name: str, actual_rgba8: np.ndarray, *, policy=None, scene: str | None = None,
                 gl_info: dict | None = None, update: bool | str = False) -> Outcome:
    """Hold a frame against golden `name` in `directory` under `policy` (default "threshold").

    Without `update` nothing is written: a missing golden is status "missing"; a golden of
    another size, or an unreadable PNG or sidecar, raises GoldenError.
    With update="failing" a missing, unreadable or wrong-size golden is created, a golden the
    frame fails under the policy, or whose sidecar does not describe its PNG, is rewritten
    ("updated"); a golden the frame passes keeps its pixels (status "passed" when they differ,
    "unchanged" or "refreshed" (declared sidecar keys only) when they are equal).
    With update="all" (or True) the golden is rewritten when its pixels or declared sidecar
    keys differ at all.
    """
    policy = policy_from(policy)
    actual = np.asarray(actual_rgba8)
    if actual.dtype != np.uint8 or actual.ndim != 3 or actual.shape[2] != 4:
        raise GoldenError(f"a golden holds an (H, W, 4) uint8 RGBA image; got {actual.dtype} "
                          f"{actual.shape}", key=name)
    png, sidecar_path = golden_paths(directory, name)
    if update is True:
        update = "all"
    if update and update not in UPDATE_MODES:
        raise GoldenError(f"unknown update mode {update!r}; expected one of: {', '.join(UPDATE_MODES)}",
                          key="update")
    if update:
        wanted = make_sidecar(name, actual, policy, scene, gl_info)
        return _update(png, sidecar_path, name, actual, policy, wanted, update, gl_info)
    if not png.exists():
        return Outcome(name, "missing", png, actual, None, policy, None, [])
    expected = read_golden(png)
    sidecar = read_sidecar(sidecar_path)
    if expected.shape != actual.shape:
        raise GoldenError(f"the golden is {_size(expected)} and the frame is {_size(actual)}; render at "
                          f"{_size(expected)}, or run pytest --update-goldens to replace the golden",
                          file=str(png), key="size")
    verdict = policy.evaluate(expected, actual)
    notes = [note for note in (implementation_note(sidecar, gl_info),) if note]
    if sidecar.get("rgba_sha256") != pixels_sha256(expected):
        notes.append(f"{sidecar_path.name} does not describe these pixels: the PNG was changed after "
                     "its sidecar was written (by hand, or by an interrupted update)")
    return Outcome(name, "passed" if verdict.passed else "failed", png, actual, expected, policy, verdict, notes)


def _update(png, sidecar_path, name, actual, policy, wanted, mode, gl_info) -> Outcome:
    try:
        expected = read_golden(png) if png.exists() else None
        sidecar = read_sidecar(sidecar_path) if expected is not None else {}
    except GoldenError:                              # an unreadable golden is replaced
        expected, sidecar = None, {}
    if (mode == "failing" and expected is not None and expected.shape == actual.shape
            and not np.array_equal(expected, actual)
            and sidecar.get("rgba_sha256") == pixels_sha256(expected)):
        verdict = policy.evaluate(expected, actual)
        if verdict.passed:                           # within policy: the golden keeps its pixels
            kept = dict(wanted, rgba_sha256=sidecar["rgba_sha256"])
            status = "passed"
            if not all(sidecar.get(key) == kept[key] for key in DECLARED_KEYS):
                # The declared keys are the test's; what made the pixels stays as recorded.
                write_text(sidecar_path, to_json(
                    dict(sidecar, **{key: kept[key] for key in DECLARED_KEYS}), indent=2) + "\n")
                status = "refreshed"
            notes = [note for note in (implementation_note(sidecar, gl_info),) if note]
            return Outcome(name, status, png, actual, expected, policy, verdict, notes)
    if expected is not None and expected.shape == actual.shape and np.array_equal(expected, actual):
        if all(sidecar.get(key) == wanted[key] for key in DECLARED_KEYS):
            status = "unchanged"
        else:
            write_text(sidecar_path, to_json(wanted, indent=2) + "\n")
            status = "refreshed"
        verdict = None
    else:
        write_png(png, actual)                       # the PNG first: the sidecar names its pixels
        write_text(sidecar_path, to_json(wanted, indent=2) + "\n")
        status = "created" if expected is None else "updated"
        verdict = policy.evaluate(expected, actual) if expected is not None and \
            expected.shape == actual.shape else None
    return Outcome(name, status, png, actual, expected, policy, verdict, [])
