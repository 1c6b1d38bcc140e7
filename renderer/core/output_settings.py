"""What the output stage does to a frame's linear colour (notes 1.3 "Storing images", 5.2
"Outputs"): the display's transfer curve, the bit depth, dithering or half-toning, and the file
format. One `OutputSettings` travels from the command line (or a caller) to both twins of the
stage (renderer/gpu/output.py, reference/output/); each method is a word here and a GLSL
define there (renderer/gpu/defines.py, `output_defines`), so a pass compiles only what its
settings use.

Every parse_* function takes the user's text and returns the value, or raises ValueError with
the reason alone (the caller names the option: `--bits 0: must be between 1 and 16`).
"""

from __future__ import annotations

import math
from dataclasses import dataclass, field

from renderer.errors import OptionError

MIN_BITS, MAX_BITS = 1, 16                 # bits per channel the stage quantises to

# Ordered dithering by a Bayer matrix of side n (Bayer 1973), a blue-noise mask (Ulichney
# 1993, void-and-cluster), error diffusion by Floyd-Steinberg (1976) or Jarvis, Judice and
# Ninke (1976). "none" rounds to the nearest code (the baseline).
ORDERED = {"bayer2": 2, "bayer4": 4, "bayer8": 8}
ERROR_DIFFUSION = ("floyd-steinberg", "jarvis-judice-ninke")
DITHERS = ("none", *ORDERED, "blue-noise", *ERROR_DIFFUSION)

# Half-toning screens one ink per channel (CMY, and K by grey-component replacement) at the
# classic screen angles, in degrees, added to the user's angle: C 15, M 75, Y 0, K 45.
INK_ANGLES = {"c": 15.0, "m": 75.0, "y": 0.0, "k": 45.0}
MIN_CELL = 2.0                             # pixels: a smaller cell has no room for a spot
# pixels: a cell of 256 is a dot per 256 x 256 pixels, already coarser than any print
# screen (newsprint's 85 lines an inch is a 3.5-pixel cell at 300 dpi); a larger one is a
# typo, and one of 1e300 is not even a float32, the GPU screen's arithmetic.
MAX_CELL = 256.0
# degrees: a screen turned by a + 360 is the screen turned by a, so one turn either way
# says every angle; far larger values lose precision in the turn's sine and cosine.
ANGLE_RANGE = (-360.0, 360.0)

# Files the stage writes: 8- or 16-bit PNG (integer codes), float32 OpenEXR or NumPy (the
# encoded colour unquantised). The suffix of the output name names the format by default.
FORMATS = {"png8": ".png", "png16": ".png", "exr": ".exr", "npy": ".npy"}
INTEGER_FORMATS = {"png8": 8, "png16": 16}  # format -> container bits per channel
FLOAT_FORMATS = ("exr", "npy")


def format_for(suffix: str, bits: int | None = None) -> str | None:
    """The format a file name's suffix names (case aside): .png is png8, or png16 for more
    than 8 bits per channel; .exr, .npy. None for any other suffix."""
    suffix = suffix.lower()
    if suffix == ".png":
        return "png16" if bits is not None and bits > INTEGER_FORMATS["png8"] else "png8"
    return next((name for name, known in FORMATS.items() if known == suffix), None)


@dataclass(frozen=True)
class Transfer:
    """The display's transfer curve from linear light L to the encoded value V, both in
    [0, 1]: "linear" (V = L; at N bits GL's own unorm conversion, gl_rules.to_unorm),
    "srgb" (IEC 61966-2-1) or "gamma" (V = L^(1/gamma)). renderer/core/quantise.py holds the
    curves and the rule that turns them into codes."""
    kind: str = "linear"
    gamma: float = 1.0

    def __str__(self) -> str:
        return f"gamma:{self.gamma:g}" if self.kind == "gamma" else self.kind


@dataclass(frozen=True)
class Halftone:
    """A clustered-dot screen per ink: square cells `cell` pixels wide, turned by `angle`
    degrees (plus each ink's INK_ANGLES)."""
    cell: float
    angle: float = 0.0

    def __str__(self) -> str:
        return f"{self.cell:g}:{self.angle:g}"


@dataclass(frozen=True)
class OutputSettings:
    """transfer, bits per channel (None: the format's own: 8 for png8, 16 for png16; float
    formats are not quantised), dither (DITHERS), halftone (None or a Halftone; it prints
    binary inks, so 1 bit per channel and no dither), format (FORMATS)."""
    transfer: Transfer = field(default_factory=Transfer)
    bits: int | None = None
    dither: str = "none"
    halftone: Halftone | None = None
    format: str = "png8"

    def __post_init__(self):
        problem = self.problem()
        if problem is not None:
            raise OptionError(*problem)

    @property
    def quantised(self) -> bool:
        """Whether the stage turns colour into integer codes (PNG) or keeps it float."""
        return self.format in INTEGER_FORMATS

    @property
    def code_bits(self) -> int:
        """Bits per channel of the codes: the given bits, else the container's (8 or 16)."""
        if not self.quantised:
            raise ValueError(f"{self.format} holds float colour, not integer codes")
        if self.halftone is not None:
            return 1
        return self.bits if self.bits is not None else INTEGER_FORMATS[self.format]

    def problem(self) -> tuple[tuple[str, ...], str] | None:
        """Why these settings cannot go together: (the fields concerned, the reason in words
        that name no front end's spelling; renderer/errors.py, OptionError), or None."""
        if self.format not in FORMATS:
            return ("format",), f"unknown; one of {', '.join(FORMATS)}"
        if self.dither not in DITHERS:
            return ("dither",), f"unknown; one of {', '.join(DITHERS)}"
        if self.bits is not None:
            if not MIN_BITS <= self.bits <= MAX_BITS:
                return ("bits",), f"must be between {MIN_BITS} and {MAX_BITS}"
            if not self.quantised:
                return ("bits", "format"), (f"{self.format} holds float colour unquantised; "
                                            "quantise to png8 or png16")
            if self.bits > INTEGER_FORMATS[self.format]:
                return ("bits", "format"), (f"{self.format} holds at most "
                                            f"{INTEGER_FORMATS[self.format]} bits per channel; use png16")
        if self.dither != "none" and not self.quantised:
            return ("dither", "format"), f"{self.format} holds float colour unquantised"
        if self.halftone is not None:
            if not self.quantised:
                return ("halftone", "format"), f"{self.format} holds float colour; half-tones are png8 or png16"
            if self.dither != "none":
                return ("halftone", "dither"), "choose one"
            if self.bits not in (None, 1):
                return ("bits", "halftone"), "a half-tone prints binary inks (1 bit per channel)"
        return None

    def check_background(self, background: str) -> None:
        """OptionError where the file format cannot hold the frame's `background` as drawn."""
        if self.format == "exr" and background == "transparent":
            raise OptionError(("format", "background"), EXR_TRANSPARENT)


# Why OpenEXR and a transparent background do not go together (OutputSettings.check_background).
EXR_TRANSPARENT = ("OpenEXR's alpha is premultiplied, and the frame's colour where nothing is "
                   "drawn is the background's under alpha 0; write format npy (straight RGBA)")


def parse_transfer(text: str) -> Transfer:
    """'linear', 'srgb' or 'gamma:G' with G a finite number > 0."""
    if text in ("linear", "srgb"):
        return Transfer(text)
    kind, _, value = text.partition(":")
    if kind == "gamma":
        try:
            gamma = float(value)
        except ValueError:
            raise ValueError(f"gamma:G needs a number G, got {value!r}") from None
        if not (math.isfinite(gamma) and gamma > 0):
            raise ValueError(f"gamma must be a finite number above 0, got {value}")
        return Transfer("gamma", gamma)
    raise ValueError("unknown; one of linear, srgb, gamma:G (e.g. gamma:2.2)")


def parse_bits(text: str) -> int:
    try:
        bits = int(text)
    except ValueError:
        raise ValueError(f"must be a whole number between {MIN_BITS} and {MAX_BITS}") from None
    if not MIN_BITS <= bits <= MAX_BITS:
        raise ValueError(f"must be between {MIN_BITS} and {MAX_BITS}")
    return bits


def parse_halftone(text: str) -> Halftone:
    """'CELL' or 'CELL:ANGLE': a cell MIN_CELL to MAX_CELL pixels wide, an angle in degrees
    within ANGLE_RANGE."""
    cell_text, _, angle_text = text.partition(":")
    try:
        cell = float(cell_text)
        angle = float(angle_text) if angle_text else 0.0
    except ValueError:
        raise ValueError("write CELL or CELL:ANGLE, e.g. 6 or 6:15") from None
    if not (math.isfinite(cell) and cell >= MIN_CELL):
        raise ValueError(f"the cell must be at least {MIN_CELL:g} pixels wide, got {cell_text}")
    if cell > MAX_CELL:
        raise ValueError(f"the cell must be {MIN_CELL:g} to {MAX_CELL:g} pixels wide, got "
                         f"{cell_text}")
    low, high = ANGLE_RANGE
    if not (math.isfinite(angle) and low <= angle <= high):
        raise ValueError(f"the angle must be {low:g} to {high:g} degrees, got {angle_text}")
    return Halftone(cell, angle)
