"""Inputs the output stage's tests share (tests/test_output_*.py)."""

import numpy as np

from renderer.core.output_settings import Transfer

TRANSFERS = (Transfer("linear"), Transfer("srgb"), Transfer("gamma", 2.2))
SPECIALS = np.array([np.nan, np.inf, -np.inf, -0.0, -1.0, 1.0, 2.0, 1e-30, 1e-45], np.float32)


def linear_frame(width: int = 40, height: int = 24, seed: int = 0) -> np.ndarray:
    """(height, width, 4) float32 linear colour: random in [-0.1, 1.1], and in row c of
    channel c the special values (NaN, infinities, -0, out of range, tiny, a denormal)."""
    frame = np.random.default_rng(seed).uniform(-0.1, 1.1, (height, width, 4)).astype(np.float32)
    for channel in range(4):
        frame[channel, :SPECIALS.size, channel] = SPECIALS
    return frame
