"""# Twin: fixed-function GL (OpenGL 4.5 core spec §17.3.6 Depth Buffer Test, GL_LESS)

A depth buffer that keeps, per pixel, the fragment GL would keep: the depth test is GL_LESS
on window depth z_w against a buffer cleared to 1.0, fragments are tested in draw order, so
among exact ties the fragment drawn first stays. Batches of fragments are resolved with a
sort (pixel, z_w, draw order) instead of a loop: within a batch the first fragment per pixel
is the one that would survive sequential testing, and it then faces the stored one with the
same rule. Draw order is an explicit key, so batches may even arrive out of order.

Inputs (per batch): pixel (N,) int64 flat index row * W + column (GL rows, bottom first),
         z_w (N,) float, order (N,) int64 draw order (>= 0), and payload arrays (N, ...)
         to keep with the winner (which object and triangle, weights, facing).
State:   z (H*W,) float cleared to 1.0, order (H*W,) int64 cleared to -1 (nothing drawn),
         payload arrays (H*W, ...) valid where order >= 0.
"""

from __future__ import annotations

import numpy as np

DEPTH_CLEAR_VALUE = 1.0
NOTHING_DRAWN = -1


def depth_less(z_fragment: np.ndarray, z_stored: np.ndarray) -> np.ndarray:
    """GL_LESS: the fragment passes when strictly nearer than what is stored."""
    return z_fragment < z_stored


def drawn_earlier(order_fragment: np.ndarray, order_stored: np.ndarray) -> np.ndarray:
    """On an exact depth tie the earlier draw wins (the later one fails GL_LESS)."""
    return (order_stored != NOTHING_DRAWN) & (order_fragment < order_stored)


def nearest_per_pixel(pixel: np.ndarray, z_w: np.ndarray, order: np.ndarray) -> np.ndarray:
    """Indices of the fragment that survives per pixel within one batch: nearest, then first."""
    by_pixel = np.lexsort((order, z_w, pixel))
    sorted_pixel = pixel[by_pixel]
    first = np.ones(len(by_pixel), dtype=bool)
    first[1:] = sorted_pixel[1:] != sorted_pixel[:-1]
    return by_pixel[first]


class DepthBuffer:
    """The z-buffer plus what the deferred fragment stage needs about each winner."""

    def __init__(self, width: int, height: int, dtype=np.float64):
        self.width, self.height = width, height
        self.z = np.full(width * height, DEPTH_CLEAR_VALUE, dtype=dtype)
        self.order = np.full(width * height, NOTHING_DRAWN, dtype=np.int64)
        self.payload: dict[str, np.ndarray] = {}

    def test_and_write(self, pixel: np.ndarray, z_w: np.ndarray, order: np.ndarray,
                       **payload: np.ndarray) -> None:
        """Depth-test one batch of fragments and write the survivors."""
        if len(pixel) == 0:
            return
        best = nearest_per_pixel(pixel, z_w, order)
        target = pixel[best]
        z_new, order_new = z_w[best], order[best]
        passes = depth_less(z_new, self.z[target]) | (
            (z_new == self.z[target]) & drawn_earlier(order_new, self.order[target]))
        best, target = best[passes], target[passes]
        self.z[target] = z_w[best]
        self.order[target] = order[best]
        for name, values in payload.items():
            if name not in self.payload:
                self.payload[name] = np.zeros((len(self.z),) + values.shape[1:], dtype=values.dtype)
            self.payload[name][target] = values[best]

    @property
    def drawn(self) -> np.ndarray:
        """(H*W,) bool: pixels where some fragment passed."""
        return self.order != NOTHING_DRAWN
