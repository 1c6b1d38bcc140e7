"""# Twin: glsl/output/transfer.glsl

Float output (exr, npy): each RGB channel's encoded value V(L) = renderer/core/quantise.py's
encode in float64 (linear: L >= 0 unclamped; sRGB and gamma: the curve of max(L, 0), above 1
too; negative L and NaN -> 0), rounded to float32; alpha as it is. The GPU evaluates the same
curve with GLSL's pow in float32: tests/test_output_transfer.py holds it within a stated
bound of this, not bit for bit.
"""

from __future__ import annotations

import numpy as np

from renderer.core.output_settings import Transfer
from renderer.core.quantise import encode


def encoded(linear: np.ndarray, transfer: Transfer) -> np.ndarray:
    """(H, W, 4) float32: encode() of R, G and B, alpha unchanged."""
    out = np.array(linear, dtype=np.float32)
    out[..., :3] = encode(out[..., :3], transfer).astype(np.float32)
    return out
