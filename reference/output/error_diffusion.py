"""# Twin: glsl/output/error_diffusion.comp

Error diffusion (Floyd-Steinberg, Jarvis-Judice-Ninke) in linear light, in raster order, in the
"pull" form of renderer/core/error_kernels.py, vectorised within each wavefront t = x + s y (a
Python loop over the W + s (H - 1) wavefronts, none over pixels). Per pixel and channel, float32
op for op as the GLSL:
    incoming = sum over the taps, in their fixed order, of f32(w_k e_k)   (from 0, one add each)
    L'       = f32(clamp_light(L) + incoming)          clamp_light: to [0, 1], NaN -> 0
    code     = bracketed_code(L', 1/2): of the two codes whose linear values bracket
               clamp_light(L'), c0 + 1 iff f32(clamp_light(L') - l_c0) > f32(0.5 f32(l_c0+1 - l_c0))
    e        = f32(L' - l_code)                        (from the unclamped L': nothing is lost)
(reference/output/quantise.py: clamp_light, bracketed_code; l = the codes' linear values.) The
input is clamped first so that light beyond the display's range (a highlight above 1) is not
spread as error over its neighbourhood.

The error image has a zero border `reach` pixels wide (left, right and top), so every tap reads
without a test: the error a pixel would send out of the image is dropped (the kernel's weights
are not renormalised at the edges), and a tap outside adds f32(w 0) = 0.
"""

from __future__ import annotations

import numpy as np

from renderer.core.error_kernels import KERNELS, pull_taps, wavefronts
from renderer.core.output_settings import OutputSettings, Transfer
from renderer.core.quantise import code_values
from reference.output.quantise import bracketed_code, clamp_light

HALF = np.float32(0.5)        # the threshold: the nearer of the two codes in linear light


def diffuse(rgb: np.ndarray, kernel: str, transfer: Transfer, bits: int):
    """(codes (H, W, 3) int64, error (H + reach, W + 2 reach, 3) float32) of the linear colour
    `rgb` (H, W, 3) float32, row 0 at the top, diffused by `kernel` (a name of
    error_kernels.KERNELS) at `bits` bits per channel under `transfer`. error[reach + y,
    reach + x] is pixel (x, y)'s; the border stays 0."""
    height, width = rgb.shape[:2]
    skew, reach = KERNELS[kernel].skew, KERNELS[kernel].reach
    offsets, weights = pull_taps(kernel)
    values = code_values(transfer, bits)
    light = clamp_light(rgb)
    error = np.zeros((height + reach, width + 2 * reach, 3), dtype=np.float32)
    codes = np.zeros((height, width, 3), dtype=np.int64)
    for t, first, last in wavefronts(width, height, skew):
        y = np.arange(first, last + 1)
        x = t - skew * y
        incoming = np.zeros((y.size, 3), dtype=np.float32)
        for (dx, dy), weight in zip(offsets, weights):
            incoming = incoming + weight * error[reach + y + dy, reach + x + dx]
        target = light[y, x] + incoming
        code = bracketed_code(target, HALF, transfer, bits)
        error[reach + y, reach + x] = target - values[code]
        codes[y, x] = code
    return codes, error


def diffused(rgb: np.ndarray, settings: OutputSettings) -> np.ndarray:
    """Codes of an (H, W, 3) linear colour under settings.dither (an error-diffusion kernel)."""
    return diffuse(rgb, settings.dither, settings.transfer, settings.code_bits)[0]
