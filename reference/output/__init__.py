"""# Twin: glsl/output/output.comp

The output stage in NumPy (docs/conventions.md, "Output"; GPU: renderer/gpu/output.py): a
frame's linear colour, (H, W, 4) float32 with row 0 at the top and alpha = coverage, to

- quantised formats (png8, png16): (H, W, 4) uint16 codes in [0, 2^N - 1], N =
  settings.code_bits; R, G and B by the method, alpha always the plain nearest code of the
  linear transfer (coverage is neither encoded nor dithered);
- float formats (exr, npy): (H, W, 4) float32, encode() of R, G and B, alpha as it is.

The method's codes come from METHODS (one function per method, each in the module of its GLSL
twin): method(rgb, settings) -> integer codes of the (H, W, 3) colour.
"""

from __future__ import annotations

import numpy as np

from renderer.core.output_settings import ERROR_DIFFUSION, ORDERED, OutputSettings, Transfer
from reference.output import dither, error_diffusion, halftone, quantise, transfer

LINEAR = Transfer("linear")

METHODS = {
    "none": quantise.undithered,
    **{name: dither.dithered for name in ORDERED},
    "blue-noise": dither.dithered,
    **{name: error_diffusion.diffused for name in ERROR_DIFFUSION},
    "halftone": halftone.halftoned,
}


def method_name(settings: OutputSettings) -> str:
    """The key of METHODS that `settings` run: "halftone", or the dither."""
    return "halftone" if settings.halftone is not None else settings.dither


def apply(linear: np.ndarray, settings: OutputSettings) -> np.ndarray:
    """The stage's output for `linear` (see the module docstring)."""
    linear = np.asarray(linear, dtype=np.float32)
    if linear.ndim != 3 or linear.shape[2] != 4:
        raise ValueError(f"the output stage takes (H, W, 4) linear colour, got {linear.shape}")
    if not settings.quantised:
        return transfer.encoded(linear, settings.transfer)
    codes = np.empty(linear.shape, dtype=np.uint16)
    codes[..., :3] = METHODS[method_name(settings)](linear[..., :3], settings)
    codes[..., 3] = quantise.nearest_code(linear[..., 3], LINEAR, settings.code_bits)
    return codes
