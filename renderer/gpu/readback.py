"""Frames read back from GL (window rows bottom-up) as the arrays we hand out: row 0 at the top
(docs/conventions.md, "Window"), C-contiguous, written into a caller's arrays when they fit
(a frame passed as `out`: a loop over many frames skips allocating them). GpuRenderer
(renderer/gpu/pipeline.py) and RayTracer (renderer/gpu/raytracer.py) read through these."""

from __future__ import annotations

import numpy as np


def usable(out: np.ndarray | None, like: np.ndarray) -> np.ndarray | None:
    """`out` if it can take a result shaped and typed like `like`, else None (a new array)."""
    if out is not None and out.shape == like.shape and out.dtype == like.dtype and out.flags.c_contiguous:
        return out
    return None


def flip_into(bottom_up: np.ndarray, out: np.ndarray | None) -> np.ndarray:
    """Rows reversed (row 0 at the top), written into `out` when usable, else a new array."""
    target = usable(out, bottom_up)
    if target is None:
        return bottom_up[::-1].copy()
    np.copyto(target, bottom_up[::-1])
    return target
