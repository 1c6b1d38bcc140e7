"""Dithering in the encoded domain: the mistake the output stage avoids, kept for the study
(the report's output section, tests/test_output_mean_light.py) and for nothing else.

The stage dithers in linear light (reference/output/quantise.py, bracketed_code): over
thresholds T spread evenly in (0, 1) the light it shows averages L. Applying the same
thresholds to the encoded value V = encode(L) instead, c = floor(V (2^N - 1)) + 1 where the
fraction above that code exceeds T, averages the codes to V, and the light shown to the
mean of decode(code / (2^N - 1)): not L, since the curve is not linear. At 1 bit the light
shown averages V itself, which sRGB puts above L everywhere in (0, 1): mid-grey L = 0.214
shows as 0.5, so the picture brightens. The eye averages the light of neighbouring pixels,
not their codes, so the average a dither keeps must be light's (on dithering and what it
averages: R. Ulichney, "Digital Halftoning", MIT Press 1987).
"""

from __future__ import annotations

import numpy as np

from renderer.core.output_settings import OutputSettings, Transfer
from renderer.core.quantise import encode
from reference.output.dither import thresholds
from reference.output.quantise import clamp_light, nearest_code


def code_value_dither(linear: np.ndarray, settings: OutputSettings) -> np.ndarray:
    """(H, W, 4) uint16 codes: `settings`' ordered or blue-noise thresholds applied to the
    encoded values of R, G and B (float64); alpha as the stage has it."""
    bits = settings.code_bits
    top = (1 << bits) - 1
    scaled = encode(clamp_light(linear[..., :3]), settings.transfer) * top
    low = np.minimum(np.floor(scaled), top)
    threshold = thresholds(settings.dither, *linear.shape[:2])[..., None]
    codes = np.empty(linear.shape, dtype=np.uint16)
    codes[..., :3] = low + ((scaled - low) > threshold)
    codes[..., 3] = nearest_code(linear[..., 3], Transfer("linear"), bits)
    return codes
