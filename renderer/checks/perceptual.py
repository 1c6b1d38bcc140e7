"""Perceptual error: NVIDIA's ꟻLIP (the flip-evaluator package), for what a person would see.

ꟻLIP gives each pixel an error in [0, 1] from a model of how people compare two images
flipped back and forth (67 pixels per degree: a desktop monitor at arm's length). Its mean
over the image summarises how visible a change is; it averages, so a small defect in a large
image has a small mean (docs/goldens.md has measured figures).
"""

from __future__ import annotations

import numpy as np

from renderer.core.gl_rules import to_unorm8


def flip_error(expected_rgba8: np.ndarray, actual_rgba8: np.ndarray) -> tuple[float, np.ndarray]:
    """(mean ꟻLIP error, (H, W, 3) uint8 error map in the magma colour map).

    Alpha is left out: ꟻLIP compares colours as shown, and the background's colour is what
    a viewer sees where alpha is 0. Inputs are sRGB-encoded 8-bit images, as ꟻLIP's LDR
    mode expects.
    """
    import flip_evaluator        # imported here: only failing or ꟻLIP-policy comparisons pay for it

    expected = np.ascontiguousarray(expected_rgba8[..., :3], dtype=np.float32) / 255.0
    actual = np.ascontiguousarray(actual_rgba8[..., :3], dtype=np.float32) / 255.0
    error_map, mean, _ = flip_evaluator.evaluate(expected, actual, "LDR")
    return float(mean), to_unorm8(np.asarray(error_map))


def flip_mean(expected_srgb: np.ndarray, actual_srgb: np.ndarray,
              pixels_per_degree: float | None = None) -> float:
    """The mean ꟻLIP error of two sRGB-encoded float images (H, W, 3) in [0, 1] (LDR), not
    quantised to 8 bits first (the report's output section compares 8-bit outputs with the
    float image), at ꟻLIP's default viewing condition or `pixels_per_degree`."""
    import flip_evaluator

    parameters = {} if pixels_per_degree is None else {"ppd": float(pixels_per_degree)}
    _, mean, _ = flip_evaluator.evaluate(np.ascontiguousarray(expected_srgb, dtype=np.float32),
                                         np.ascontiguousarray(actual_srgb, dtype=np.float32),
                                         "LDR", applyMagma=False, parameters=parameters)
    return float(mean)
