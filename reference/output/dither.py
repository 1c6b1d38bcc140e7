"""# Twin: glsl/output/dither.glsl

Ordered and blue-noise dithering: a threshold T in (0, 1) per pixel, the same for R, G and B,
and each channel's code bracketed_code(L, T) (reference/output/quantise.py). Pixel (x, y) is
(column, image row from the top), the frame's row 0 at the top (docs/conventions.md,
"Output"); the patterns tile from (0, 0).

- Bayer (B. E. Bayer, "An optimum method for two-level rendition of continuous-tone
  pictures", 1973), side n = 2, 4, 8: M(x, y) interleaves the bits of x XOR y and of y, the
  lowest bits first into the highest places (the bit-reverse of the interleave), so
  M2 = [[0, 2], [3, 1]] (row y = 0 first); T = (M + 1/2) / n^2, exact in float32.
- blue noise: the void-and-cluster ranks of renderer/core/blue_noise.py (size s = 64),
  T = (rank[y mod s, x mod s] + 1/2) / s^2, exact.
"""

from __future__ import annotations

import numpy as np

from renderer.core.blue_noise import blue_noise_ranks
from renderer.core.output_settings import ORDERED, OutputSettings
from reference.output.quantise import bracketed_code


def bayer_index(x, y, n: int) -> np.ndarray:
    """uint32: Bayer's matrix of side n (a power of 2) at column x, row y (any integers >= 0;
    the matrix tiles)."""
    x = np.asarray(x, dtype=np.uint32) & np.uint32(n - 1)
    y = np.asarray(y, dtype=np.uint32) & np.uint32(n - 1)
    a = x ^ y
    m = np.zeros(np.broadcast(x, y).shape, dtype=np.uint32)
    bit = 1
    while bit < n:
        m = (m << np.uint32(2)) | np.where(a & np.uint32(bit), np.uint32(2), np.uint32(0)) \
            | np.where(y & np.uint32(bit), np.uint32(1), np.uint32(0))
        bit <<= 1
    return m


def bayer_matrix(n: int) -> np.ndarray:
    """(n, n) uint32 indexed [y, x]: bayer_matrix(2) = [[0, 2], [3, 1]]."""
    return bayer_index(np.arange(n)[None, :], np.arange(n)[:, None], n)


def thresholds(dither: str, height: int, width: int) -> np.ndarray:
    """(height, width) float32: the threshold of each pixel for an ordered or blue-noise dither."""
    rows, columns = np.arange(height)[:, None], np.arange(width)[None, :]
    if dither in ORDERED:
        n = ORDERED[dither]
        index, count = bayer_index(columns, rows, n), n * n
    elif dither == "blue-noise":
        ranks = blue_noise_ranks()
        size = ranks.shape[0]
        index, count = ranks[rows % size, columns % size], size * size
    else:
        raise ValueError(f"{dither!r} is not an ordered or blue-noise dither")
    return ((index.astype(np.float32) + np.float32(0.5)) / np.float32(count)).astype(np.float32)


def dithered(rgb: np.ndarray, settings: OutputSettings) -> np.ndarray:
    """Codes of an (H, W, 3) linear colour under an ordered or blue-noise dither."""
    threshold = thresholds(settings.dither, *rgb.shape[:2])[..., None]
    return bracketed_code(rgb, threshold, settings.transfer, settings.code_bits)
