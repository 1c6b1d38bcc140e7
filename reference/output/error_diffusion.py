"""# Twin: glsl/output/error_diffusion.comp

Error diffusion (Floyd-Steinberg, Jarvis-Judice-Ninke) in linear light, in raster order, in the
"pull" form of renderer/core/error_kernels.py, vectorised within each wavefront t = x + s y (a
Python loop over the W + s (H - 1) wavefronts, none over pixels). Per pixel and channel, float32
op for op as the GLSL:
    incoming = sum over the taps, in their fixed order, of f32(w_k e_k)   (from 0, one add each;
               w_k the share the source sends, sender_weights: renormalised at the edges)
    L'       = f32(clamp_light(L) + incoming)          clamp_light: to [0, 1], NaN -> 0
    code     = bracketed_code(L', 1/2): of the two codes whose linear values bracket
               clamp_light(L'), c0 + 1 iff f32(clamp_light(L') - l_c0) > f32(0.5 f32(l_c0+1 - l_c0))
    e        = f32(L' - l_code)                        (from the unclamped L': nothing is lost)
(reference/output/quantise.py: clamp_light, bracketed_code; l = the codes' linear values.) The
input is clamped first so that light beyond the display's range (a highlight above 1) is not
spread as error over its neighbourhood.

The error image has a zero border `reach` pixels wide (left, right and top), so every tap reads
without a test: a tap outside the image adds f32(w 0) = 0. No error leaves the image: a source
near an edge sends its whole error to the receivers it has inside (sender_weights renormalises
its shares), so the frame keeps its light but for the last pixel's error.
"""

from __future__ import annotations

import numpy as np

from renderer.core.error_kernels import KERNELS, pull_taps, sender_sides, sender_weights, wavefronts
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
    taps = pull_taps(kernel)
    values = code_values(transfer, bits)
    light = clamp_light(rgb).reshape(-1, 3)
    # Pixel (x, y) is y W + x in `light`, `shares` and `codes`, and (reach + y) stride + reach
    # + x in the bordered error image, where each tap's source is a fixed step away from it.
    stride = width + 2 * reach
    steps = taps[:, 1] * stride + taps[:, 0]
    error = np.zeros(((height + reach) * stride, 3), dtype=np.float32)
    columns, rows = np.arange(width)[None, :, None], np.arange(height)[:, None, None]
    sides = sender_sides(columns + taps[:, 0], rows + taps[:, 1], width, height, reach)
    shares = sender_weights(kernel)[(*sides, np.arange(len(taps)))].reshape(-1, len(taps), 1)
    codes = np.zeros((height * width, 3), dtype=np.int64)
    for t, first, last in wavefronts(width, height, skew):
        y = np.arange(first, last + 1)
        x = t - skew * y
        pixel = y * width + x
        here = (reach + y) * stride + reach + x
        terms = np.zeros((y.size, len(taps) + 1, 3), dtype=np.float32)     # 0, then each tap
        terms[:, 1:] = shares[pixel] * error[here[:, None] + steps]
        incoming = np.add.accumulate(terms, axis=1)[:, -1]                 # in the taps' order
        target = light[pixel] + incoming
        code = bracketed_code(target, HALF, transfer, bits)
        error[here] = target - values[code]
        codes[pixel] = code
    return codes.reshape(height, width, 3), error.reshape(height + reach, stride, 3)


def diffused(rgb: np.ndarray, settings: OutputSettings) -> np.ndarray:
    """Codes of an (H, W, 3) linear colour under settings.dither (an error-diffusion kernel)."""
    return diffuse(rgb, settings.dither, settings.transfer, settings.code_bits)[0]
