"""# Twin: fixed-function GL (OpenGL 4.5 core spec §17.3.6 Depth Buffer Test, GL_LESS)

A depth buffer that keeps, per pixel, the fragment GL would keep: the depth test and the
clear value are the depth mapping's (renderer/core/gl_rules.py): GL_LESS on window depth z_w
against a buffer cleared to 1.0, or under reversed-Z GL_GREATER against a buffer cleared to
0.0, run here as GL_LESS on the mapping's key -z_w (`DepthMapping.depth_key`); fragments
are tested in draw order, so among exact ties the fragment drawn first stays. Batches of fragments are
resolved with a sort (pixel, z_w, draw order) instead of a loop: within a batch the first
fragment per pixel is the one that would survive sequential testing, and it then faces the
stored one with the same rule. Draw order is an explicit key, so batches may even arrive out of order.

Inputs (per batch): pixel (N,) int64 flat index row * W + column (GL rows, bottom first),
         z_w (N,) float, order (N,) int64 draw order (>= 0), and payload arrays (N, ...)
         to keep with the winner (which object and triangle, weights, facing).
State:   z (H*W,) float depth keys, cleared to the clear value's key, order (H*W,) int64
         cleared to -1 (nothing drawn), payload arrays (H*W, ...) valid where order >= 0.
"""

from __future__ import annotations

import numpy as np

from renderer.core.gl_rules import depth_mapping

NOTHING_DRAWN = -1
# Window depths closer than this may be ordered either way by GL. Its float32 vertex and
# interpolation arithmetic is exact to a few units in the last place of z_w, and a float32
# unit near z_w = 1 is 2^-24..2^-23; at a silhouette the front and back faces meet and
# their depths differ by less than that (measured: 4e-9 and 2.3e-8 on two 256x256 frames).
# Under reversed-Z, z_w is small far away and float32 keeps its relative precision there, so
# the tolerance is relative: 4 units in the last place of the winner's z_w.
DEPTH_TIE_TOLERANCE = 4 * 2.0 ** -23


_LAST = np.iinfo(np.int64).max       # the order of a missing candidate: it sorts after all


def _sort_key(order: np.ndarray) -> np.ndarray:
    return np.where(order == NOTHING_DRAWN, _LAST, order)


def _before(z_a, order_a, z_b, order_b) -> np.ndarray:
    """Fragment a is kept over b: nearer, or as near and drawn earlier."""
    return (z_a < z_b) | ((z_a == z_b) & (order_a < order_b))


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

    def __init__(self, width: int, height: int, dtype=np.float64, reversed_z: bool = False):
        self.width, self.height = width, height
        self.reversed_z = reversed_z
        self.mapping = depth_mapping(reversed_z)
        self.z = np.full(width * height, self.mapping.depth_key(self.mapping.clear_depth), dtype=dtype)
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
        z_w = self.mapping.depth_key(z_w)
        first, second = nearest_two_per_pixel(pixel, z_w, order)
        target = pixel[first]
        has_second = second >= 0
        second = np.where(has_second, second, first)
        # Candidates, each sorted already: (stored winner w, stored runner-up r) and (the
        # batch's nearest b1, its next b2). The clear value is a winner of z 1.0 and order -1,
        # so it wins ties (GL_LESS against 1.0 fails at 1.0), but it is never a runner-up.
        # Missing candidates sort last.
        wz, wo = self.z[target], self.order[target]
        rz, ro = self.z_second[target], _sort_key(self.order_second[target])
        b1z, b1o = z_w[first], order[first]
        b2z, b2o = np.where(has_second, z_w[second], np.inf), np.where(has_second, order[second], _LAST)
        b1_wins = _before(b1z, b1o, wz, wo)
        # Runner-up: the better of (r, b1) if w stays; if b1 wins, of (w, b2), where w is
        # replaced by r when w is only the clear value (r then lost to the clear).
        w_real = wo != NOTHING_DRAWN
        kz, ko = np.where(w_real, wz, rz), np.where(w_real, wo, ro)
        b1_over_r = _before(b1z, b1o, rz, ro)
        k_over_b2 = _before(kz, ko, b2z, b2o)
        second_z = np.where(b1_wins, np.where(k_over_b2, kz, b2z), np.where(b1_over_r, b1z, rz))
        second_o = np.where(b1_wins, np.where(k_over_b2, ko, b2o), np.where(b1_over_r, b1o, ro))

        for name, values in payload.items():
            for store in (self.payload, self.payload_second):
                if name not in store:
                    store[name] = np.zeros((len(self.z),) + values.shape[1:], dtype=values.dtype)
            stored_w, stored_r = self.payload[name][target], self.payload_second[name][target]
            pick = lambda mask, a, b: np.where(mask.reshape((-1,) + (1,) * (values.ndim - 1)), a, b)
            stored_k = pick(w_real, stored_w, stored_r)
            self.payload[name][target] = pick(b1_wins, values[first], stored_w)
            self.payload_second[name][target] = pick(
                b1_wins, pick(k_over_b2, stored_k, values[second]), pick(b1_over_r, values[first], stored_r))
        self.z[target] = np.where(b1_wins, b1z, wz)
        self.order[target] = np.where(b1_wins, b1o, wo)
        self.z_second[target] = second_z
        self.order_second[target] = np.where(second_o == _LAST, NOTHING_DRAWN, second_o)

    @property
    def drawn(self) -> np.ndarray:
        """(H*W,) bool: pixels where some fragment passed."""
        return self.order != NOTHING_DRAWN

    def depth_ties(self, tolerance: float = None) -> np.ndarray:
        """(H*W,) bool: drawn pixels whose runner-up is within `tolerance` of the winner's z_w."""
        tolerance = DEPTH_TIE_TOLERANCE if tolerance is None else tolerance
        if self.reversed_z:
            tolerance = tolerance * np.abs(self.z)
        return self.drawn & (self.order_second != NOTHING_DRAWN) & (self.z_second - self.z <= tolerance)
