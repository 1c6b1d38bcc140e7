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
# Window depths closer than this may be ordered either way by GL. Its float32 vertex and
# interpolation arithmetic is exact to a few units in the last place of z_w, and a float32
# unit near z_w = 1 is 2^-24..2^-23; at a silhouette the front and back faces meet and
# their depths differ by less than that (measured: 4e-9 and 2.3e-8 on two 256x256 frames).
DEPTH_TIE_TOLERANCE = 4 * 2.0 ** -23


def depth_less(z_fragment: np.ndarray, z_stored: np.ndarray) -> np.ndarray:
    """GL_LESS: the fragment passes when strictly nearer than what is stored."""
    return z_fragment < z_stored


def drawn_earlier(order_fragment: np.ndarray, order_stored: np.ndarray) -> np.ndarray:
    """On an exact depth tie the earlier draw wins (the later one fails GL_LESS)."""
    return (order_stored != NOTHING_DRAWN) & (order_fragment < order_stored)


def nearest_two_per_pixel(pixel, z_w, order) -> tuple[np.ndarray, np.ndarray]:
    """(first, second): per pixel of the batch, the index of its nearest fragment (then the
    earliest drawn) and of the next one in the same order, -1 where it has only one."""
    by_pixel = np.lexsort((order, z_w, pixel))
    sorted_pixel = pixel[by_pixel]
    starts = np.flatnonzero(np.r_[True, sorted_pixel[1:] != sorted_pixel[:-1]])
    ends = np.r_[starts[1:], len(by_pixel)]
    second = np.where(ends - starts > 1, by_pixel[np.minimum(starts + 1, len(by_pixel) - 1)], -1)
    return by_pixel[starts], second


class DepthBuffer:
    """The z-buffer plus what the deferred fragment stage needs about each winner.

    It also keeps, per pixel, the runner-up: the nearest fragment that lost. Where the two
    are closer in window depth than DEPTH_TIE_TOLERANCE, GL's float32 arithmetic may order
    them either way, and `depth_ties()` says so (pipeline.py then shades both).
    """

    def __init__(self, width: int, height: int, dtype=np.float64):
        self.width, self.height = width, height
        self.z = np.full(width * height, DEPTH_CLEAR_VALUE, dtype=dtype)
        self.order = np.full(width * height, NOTHING_DRAWN, dtype=np.int64)
        self.payload: dict[str, np.ndarray] = {}
        self.z_second = np.full(width * height, np.inf, dtype=dtype)
        self.order_second = np.full(width * height, NOTHING_DRAWN, dtype=np.int64)
        self.payload_second: dict[str, np.ndarray] = {}

    def test_and_write(self, pixel: np.ndarray, z_w: np.ndarray, order: np.ndarray,
                       **payload: np.ndarray) -> None:
        """Depth-test one batch of fragments and write the survivors (and the runners-up)."""
        if len(pixel) == 0:
            return
        first, second = nearest_two_per_pixel(pixel, z_w, order)
        target = pixel[first]
        # Four candidates per pixel: stored winner, stored runner-up, the batch's two nearest.
        # The clear value takes part as a winner of order -1 (it wins ties: GL_LESS against
        # 1.0 fails at 1.0) but never as a runner-up.
        has_second = second >= 0
        second = np.where(has_second, second, first)
        cand_z = np.stack([self.z[target], self.z_second[target], z_w[first],
                           np.where(has_second, z_w[second], np.inf)], axis=1)
        cand_order = np.stack([self.order[target], self.order_second[target], order[first],
                               np.where(has_second, order[second], NOTHING_DRAWN)], axis=1)
        is_fragment = np.stack([self.order[target] != NOTHING_DRAWN, self.order_second[target] != NOTHING_DRAWN,
                                np.ones(len(target), bool), has_second], axis=1)
        # The clear (order -1, z 1.0) competes for first place; absent candidates sort last.
        sort_order = np.where(is_fragment | (np.arange(4) == 0), cand_order, np.iinfo(np.int64).max)
        sort_z = np.where(is_fragment | (np.arange(4) == 0), cand_z, np.inf)
        ranked = np.lexsort((sort_order, sort_z), axis=1)
        rows = np.arange(len(target))
        win = ranked[:, 0]
        # The runner-up: the best-ranked real fragment after the winner.
        later_fragment = is_fragment[rows[:, None], ranked] & (np.arange(4) > 0)
        has_runner_up = later_fragment.any(axis=1)
        runner_up = ranked[rows, np.argmax(later_fragment, axis=1)]

        self.z[target], self.order[target] = cand_z[rows, win], cand_order[rows, win]
        self.z_second[target] = np.where(has_runner_up, cand_z[rows, runner_up], np.inf)
        self.order_second[target] = np.where(has_runner_up, cand_order[rows, runner_up], NOTHING_DRAWN)
        for name, values in payload.items():
            for store in (self.payload, self.payload_second):
                if name not in store:
                    store[name] = np.zeros((len(self.z),) + values.shape[1:], dtype=values.dtype)
            cand = np.stack([self.payload[name][target], self.payload_second[name][target],
                             values[first], values[second]], axis=1)
            self.payload[name][target] = cand[rows, win]
            self.payload_second[name][target] = cand[rows, runner_up]

    @property
    def drawn(self) -> np.ndarray:
        """(H*W,) bool: pixels where some fragment passed."""
        return self.order != NOTHING_DRAWN

    def depth_ties(self, tolerance: float = None) -> np.ndarray:
        """(H*W,) bool: drawn pixels whose runner-up is within `tolerance` of the winner's z_w."""
        tolerance = DEPTH_TIE_TOLERANCE if tolerance is None else tolerance
        return self.drawn & (self.order_second != NOTHING_DRAWN) & (self.z_second - self.z <= tolerance)
