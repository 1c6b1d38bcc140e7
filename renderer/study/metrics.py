"""The errors of an image against the ground truth, as `renderer report` gives them for every
knob but the shadow knobs (report.py's module docstring; shadow_report.py for those)."""

from __future__ import annotations

import math

import numpy as np

from renderer.checks.perceptual import flip_error
from renderer.core.gl_rules import to_unorm8
from renderer.study.report_settings import MISMATCH_LEVELS


def metrics(image: np.ndarray, truth: np.ndarray) -> dict:
    """Errors of an (H, W, 3) float image in [0, 1] against the truth (report.py's module docstring)."""
    difference = image - truth
    mse = float(np.mean(difference ** 2))
    image8, truth8 = to_unorm8(image), to_unorm8(truth)
    off = np.abs(image8.astype(np.int16) - truth8.astype(np.int16)) > MISMATCH_LEVELS
    return {"rmse": math.sqrt(mse), "max_abs": float(np.max(np.abs(difference))),
            "psnr": 10.0 * math.log10(1.0 / mse) if mse > 0 else math.inf,
            "flip_mean": flip_error(truth8, image8)[0],
            "mismatched_fraction": float(off.any(axis=-1).mean())}
