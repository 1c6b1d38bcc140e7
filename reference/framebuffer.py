"""# Twin: fixed-function GL (OpenGL 4.5 core spec §2.3.5.1 conversion of floating-point to normalized fixed-point; §18.2 ReadPixels)

The framebuffer as the caller sees it: colour clamped and converted to unorm8 as GL does
(renderer/core/gl_rules.py, to_unorm8); the background is the scene's background colour with
alpha 0; rows flipped once so that row 0 is the top (GL's row 0 is the bottom).

Inputs:  color (H*W, 4) linear colour of the surviving fragment per pixel (GL row order,
         bottom row first), drawn (H*W,) bool, view_depth (H*W,) -z_eye, background (3,).
Outputs: `renderer.core.frame.Frame`: rgba8 (H, W, 4) uint8, linear (H, W, 4) float32 or None,
         depth (H, W) float32 (+inf where nothing was drawn) or None.
"""

from __future__ import annotations

import numpy as np

from renderer.core.frame import Frame
from renderer.core.gl_rules import to_unorm8


def flip_rows(image: np.ndarray) -> np.ndarray:
    """GL row order (bottom first) -> image row order (top first)."""
    return np.ascontiguousarray(image[::-1])


def compose_frame(color: np.ndarray, drawn: np.ndarray, view_depth: np.ndarray | None,
                  background, width: int, height: int, *, linear: bool,
                  milliseconds: float = 0.0) -> Frame:
    """Fill the background, convert, flip; see the module docstring."""
    clear = np.concatenate([np.asarray(background, dtype=color.dtype), [0.0]])
    color = np.where(drawn[:, None], color, clear).reshape(height, width, 4)
    rgba8 = flip_rows(to_unorm8(color))
    linear_image = flip_rows(color.astype(np.float32)) if linear else None
    depth_image = None
    if view_depth is not None:
        depth = np.where(drawn, view_depth, np.inf).astype(np.float32)
        depth_image = flip_rows(depth.reshape(height, width))
    return Frame(rgba8, linear_image, depth_image, milliseconds)
