"""Supersampling by accumulation, on either pipeline (notes 2.2: super-sampling and adaptive
super-sampling).

A *pass* renders the whole image with every pixel sampled at one offset (dx, dy) from its
centre (renderer/core/sampling.py; docs/conventions.md, "Sample positions") and returns its linear
colour, (H, W, 3) float. `gpu_pass` and `reference_pass` make passes for the two pipelines;
both move the projection by the same jitter (transforms.jitter), so with the same offsets
their accumulated images agree pixel by pixel.

    supersample(pass_, offsets)                     mean of the clamped passes, (H, W, 3)
    adaptive_supersample(pass_, 4, 16, 0.05)        more samples only where a first pass varies
    msaa_image(gpu, 4)                              GL's MSAA, resolved (GPU only)
"""

from __future__ import annotations

from typing import Callable

import numpy as np

from renderer.core.gl_rules import SUBPIXEL_BITS
from renderer.core.sampling import DEFAULT_SEED, jittered
from renderer.methods import open_renderer

Pass = Callable[[tuple], np.ndarray]          # (dx, dy) -> (H, W, 3) linear colour


def gpu_pass(gpu) -> Pass:
    """Passes through a GpuRenderer: only u_projection changes between them, and each pass
    reads back into the previous pass's arrays (so a pass's result is valid until the next)."""
    frame = None

    def render(offset) -> np.ndarray:
        nonlocal frame
        frame = gpu.render(linear=True, depth=False, sample_offset=tuple(offset), out=frame)
        return frame.linear[..., :3]
    return render


def reference_pass(scene, width: int, height: int, *, dtype=np.float64,
                   subpixel_bits: int = SUBPIXEL_BITS) -> Pass:
    """Passes through the NumPy reference, in `dtype`."""
    twin = open_renderer(scene, (width, height), backend="reference",
                         precision=np.dtype(dtype).name, subpixel_bits=subpixel_bits)

    def render(offset) -> np.ndarray:
        return twin.render(linear=True, depth=False, sample_offset=tuple(offset)).linear[..., :3]
    return render


def clamped(colour: np.ndarray) -> np.ndarray:
    """What a display shows of a linear colour: clamped to [0, 1], as float64."""
    return np.clip(colour, 0.0, 1.0, dtype=np.float64)


def supersample(pass_: Pass, offsets: np.ndarray) -> np.ndarray:
    """(H, W, 3) float64: the mean over `offsets` of each pass's clamped linear colour."""
    total = None
    for offset in offsets:
        colour = clamped(pass_(offset))
        total = colour if total is None else np.add(total, colour, out=total)
    return total / len(offsets)


def adaptive_supersample(pass_: Pass, first: int, total: int, threshold: float,
                         seed: int = DEFAULT_SEED) -> tuple[np.ndarray, float]:
    """(image, mean samples per pixel). A first pass of `first` jittered samples; a pixel whose
    samples' range (max - min, largest over R, G, B) exceeds `threshold` gets `total - first`
    more (jittered, another seed) and the mean of all `total`; the others keep the first mean.
    Each extra sample is a full-frame pass whose result is used only at the flagged pixels."""
    samples = np.stack([clamped(pass_(offset)) for offset in jittered(first, seed)])
    flagged = (samples.max(axis=0) - samples.min(axis=0)).max(axis=-1) > threshold
    accumulated = samples.sum(axis=0)
    image = accumulated / first
    if total > first and flagged.any():
        for offset in jittered(total - first, seed + 1):
            accumulated += clamped(pass_(offset))
        image[flagged] = accumulated[flagged] / total
    return image, first + (total - first) * float(flagged.mean())


def msaa_image(gpu, samples: int) -> np.ndarray:
    """(H, W, 3) float64 in [0, 1]: GL's MSAA with `samples` per pixel (1: none), resolved into
    the RGBA8 buffer, so quantised to 1/255."""
    return gpu.render(depth=False, samples=samples).rgba8[..., :3] / 255.0
