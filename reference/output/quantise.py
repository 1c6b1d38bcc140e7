"""# Twin: glsl/output/quantise.glsl

Codes from linear light by exact comparisons with the tables of renderer/core/quantise.py
(the rule, written once there), in float32 operation for operation with the GLSL:

- `count_at_or_below(L, table)`: how many entries of an ascending float32 table are <= L
  (np.searchsorted(table, L, 'right'); the GLSL walks to the same count from the transfer
  curve's guess). A comparison with NaN is false, so NaN counts 0; L and L clamped to
  [0, 1] have the same count (the tables lie in [0, 1]).
- the undithered code (the baseline): `nearest_code(L) = count_at_or_below(L, t)` over the
  decision points t of the transfer; alpha always over the linear transfer's.
- `bracketed_code(L, T)`, dithering's choice, in linear light: L' = L clamped to [0, 1] (NaN
  -> 0); c0 = the largest k with l_k <= L' over the codes' linear values l (count over
  l_1 ..); the top code stays; else c0 + 1 where f32(L' - l_c0) > f32(T f32(l_c0+1 - l_c0)),
  else c0. Over thresholds T spread evenly in (0, 1) the expected code value is L' exactly,
  so dithering keeps a block's mean light (in the encoded domain it would not: the curve is
  not linear; see renderer/study/code_value_dither.py).
"""

from __future__ import annotations

import numpy as np

from renderer.core.output_settings import OutputSettings, Transfer
from renderer.core.quantise import code_values, decision_points


def count_at_or_below(light, table: np.ndarray) -> np.ndarray:
    """int64: the number of entries of the ascending float32 `table` that are <= each L."""
    light = np.asarray(light, dtype=np.float32)
    return np.searchsorted(table, np.where(np.isnan(light), -np.inf, light), side="right")


def nearest_code(light, transfer: Transfer, bits: int) -> np.ndarray:
    """int64: the undithered code of each float32 L (renderer/core/quantise.py, code_of)."""
    return count_at_or_below(light, decision_points(transfer, bits))


def clamp_light(light) -> np.ndarray:
    """float32: L clamped to [0, 1], NaN -> 0."""
    light = np.asarray(light, dtype=np.float32)
    return np.where(light >= 0, np.minimum(light, np.float32(1)), np.float32(0))


def bracketed_code(light, threshold, transfer: Transfer, bits: int) -> np.ndarray:
    """int64: c0 or c0 + 1 as the module docstring says; `threshold` broadcasts against L."""
    values = code_values(transfer, bits)
    top = len(values) - 1
    clamped = clamp_light(light)
    low = count_at_or_below(clamped, values[1:])
    low_value = values[low]
    step_value = values[np.minimum(low + 1, top)] - low_value
    up = (clamped - low_value) > (np.asarray(threshold, dtype=np.float32) * step_value)
    return np.where(low == top, top, low + up)


def undithered(rgb: np.ndarray, settings: OutputSettings) -> np.ndarray:
    """The baseline method "none": each channel's nearest code."""
    return nearest_code(rgb, settings.transfer, settings.code_bits)
