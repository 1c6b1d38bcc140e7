"""Munsell hue, value and chroma of a linear RGB colour (notes 1.2 "Colour"), by
colour-science's inversion of the Munsell renotation (Newhall, Nickerson and Judd 1943):
`colour.notation.munsell.xyY_to_munsell_colour`.

The renotation is measured under CIE illuminant C; our colours are relative to D65 (white is
D65 at Y = 1: renderer/core/colour.py). So XYZ is first adapted from D65 to C (von Kries with
the Bradford cone responses, what colour-science's `chromatic_adaptation` does by default),
which makes RGB white neutral (N10) instead of a faint green-yellow.

The renotation data cover values 1 to 10 and, at each hue and value, chromas up to the real
surface colours measured (inside the MacAdam limits). A colour beyond them is said in words:
`Munsell.note`, with the notation left out where colour-science gives none. colour-science
is imported here, so only `renderer colour` pays for it.
"""

from __future__ import annotations

import re
import warnings
from dataclasses import dataclass

import colour
import numpy as np
from colour.notation.munsell import munsell_value, xyY_to_munsell_colour

from renderer.core.colour import RGB_TO_XYZ

OBSERVER = "CIE 1931 2 Degree Standard Observer"
_NOTATION = re.compile(r"(?P<hue>[0-9.]+[A-Z]+) (?P<value>[0-9.]+)/(?P<chroma>[0-9.]+)")
_NEUTRAL = re.compile(r"N(?P<value>[0-9.]+)")


@dataclass(frozen=True)
class Munsell:
    """A colour's Munsell notation ("5R 4/14", "N9.2"; None when the renotation data hold
    none), its hue ("5R", "N" for a neutral), value (0 black .. 10 white, ASTM D1535, always
    given) and chroma (None without a notation), and a note in words when the colour lies
    outside the renotation data ("" inside)."""
    notation: str | None
    hue: str | None
    value: float
    chroma: float | None
    note: str = ""


def xyy_under_c(rgb) -> np.ndarray:
    """xyY of linear RGB after adapting its XYZ from D65 to illuminant C (module docstring)."""
    white_d65 = RGB_TO_XYZ @ np.ones(3)
    white_c = colour.xy_to_XYZ(colour.CCS_ILLUMINANTS[OBSERVER]["C"])
    xyz = RGB_TO_XYZ @ np.asarray(rgb, dtype=np.float64)
    adapted = colour.adaptation.chromatic_adaptation_VonKries(xyz, white_d65, white_c, "Bradford")
    return colour.XYZ_to_xyY(adapted)


def munsell_of(rgb) -> Munsell:
    """The Munsell notation of a linear RGB colour (module docstring)."""
    xyy = xyy_under_c(rgb)
    luminance = float(xyy[2])
    if not luminance > 0.0:
        return Munsell("N0", "N", 0.0, 0.0, "black: no light, so no hue (value 0; the "
                                            "renotation data start at value 1)")
    if luminance > 1.0:
        return Munsell(None, None, 10.0, None, f"brighter than white (Y = {luminance:.3g}): no "
                       "surface reflects more than all the light, so the renotation has none")
    value = float(munsell_value(luminance * 100.0))
    darker = "darker than value 1, where the renotation data end"
    with warnings.catch_warnings(record=True) as caught:
        warnings.simplefilter("always")
        try:
            notation = str(xyY_to_munsell_colour(xyy))
        except (ValueError, RuntimeError, AssertionError):
            reason = darker if value < 1.0 else (
                "beyond the Munsell renotation data: its chroma is too high for this hue and "
                "value (more saturated than any surface colour measured)")
            return Munsell(None, None, round(value, 1), None, f"{reason}; no notation")
    extrapolated = f"{darker}: extrapolated" if value < 1.0 else ""
    neutral = _NEUTRAL.fullmatch(notation)
    if neutral:               # colour-science's MacAdam check trips at white: no note there
        return Munsell(notation, "N", float(neutral["value"]), 0.0, extrapolated)
    if not extrapolated and any("MacAdam" in str(w.message) for w in caught):
        extrapolated = "outside the MacAdam limits (no surface colour is this saturated): extrapolated"
    parts = _NOTATION.fullmatch(notation)
    return Munsell(notation, parts["hue"], float(parts["value"]), float(parts["chroma"]),
                   extrapolated)
