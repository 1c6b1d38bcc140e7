"""JSON as every output of the project writes it (`renderer compare`'s figures, extremes.json,
the viewer's --stats, golden sidecars and figures.json): standard JSON (RFC 8259).

Standard JSON has no NaN or infinity, and Python's json module writes them as `NaN` and
`Infinity` unless told not to, which strict parsers (jq, JavaScript's JSON.parse, serde)
refuse. `to_json` tells it not to (allow_nan=False): a non-finite float anywhere raises
ValueError, so a figure that turns NaN fails loudly instead of writing a file nobody can
read. A figure that is infinite on purpose is mapped before: `finite_or_none` (the PSNR of
two identical images is null).
"""

from __future__ import annotations

import json
import math

from renderer.core.imageio import write_text


def to_json(value, *, indent: int | None = None) -> str:
    """json.dumps(value, indent=indent), refusing NaN and infinities (ValueError)."""
    return json.dumps(value, indent=indent, allow_nan=False)


def json_text(value, *, indent: int = 1) -> str:
    """A JSON file's text: `to_json(value)` and a newline."""
    return to_json(value, indent=indent) + "\n"


def write_json(path, value, *, indent: int = 1) -> None:
    """`json_text(value)` written atomically (imageio.write_text; with other files of the same
    command: `imageio.outputs()` and `out.text(path, json_text(value))`)."""
    write_text(path, json_text(value, indent=indent))


def canonical_json(value) -> str:
    """The text a digest is taken of (a batch job's identity, a scene's): keys sorted, no
    spaces, a value JSON has no word for (a TOML date) as its str(). Not a file's text: NaN
    and infinities are written as Python writes them, since a scene may hold gloss = inf."""
    return json.dumps(value, sort_keys=True, separators=(",", ":"), default=str)


def finite_or_none(x: float | None) -> float | None:
    """x when it is a finite number, else None (JSON's null)."""
    return x if x is not None and math.isfinite(x) else None
