"""Ordered and blue-noise dithering (reference/output/dither.py; glsl/output/dither.glsl): Bayer's
matrices by hand, the pattern's orientation on the GPU (y is the image row from the top), the
blue-noise mask's defining properties, and GPU against twin bit for bit at 1 to 16 bits on
both contexts.
"""

import numpy as np
import pytest

import reference.output
from renderer.core.blue_noise import blue_noise_ranks
from renderer.core.output_settings import OutputSettings
from reference.output.dither import bayer_matrix, thresholds
from output_cases import TRANSFERS, linear_frame

DITHERS = ("bayer2", "bayer4", "bayer8", "blue-noise")


def test_bayer_2_and_4_by_hand():
    # Bayer (1973); rows y = 0, 1, ... from the top, columns x
    assert bayer_matrix(2).tolist() == [[0, 2],
                                        [3, 1]]
    assert bayer_matrix(4).tolist() == [[0, 8, 2, 10],
                                        [12, 4, 14, 6],
                                        [3, 11, 1, 9],
                                        [15, 7, 13, 5]]


def test_bayer_8_is_the_recursive_matrix():
    # M_2n(x, y) = n^2 M_2(x mod 2, y mod 2) + M_n(x div 2, y div 2): each level splits the
    # threshold range of the level below between the four cells of a 2 x 2 block
    y, x = np.mgrid[0:8, 0:8]
    m8 = bayer_matrix(8)
    assert (m8 == 16 * bayer_matrix(2)[y % 2, x % 2] + bayer_matrix(4)[y // 2, x // 2]).all()
    assert sorted(m8.ravel().tolist()) == list(range(64))


def test_thresholds_are_exact_and_tile_from_the_origin():
    t = thresholds("bayer2", 3, 5)
    assert t.dtype == np.float32
    assert t.tolist() == [[0.125, 0.625, 0.125, 0.625, 0.125],
                          [0.875, 0.375, 0.875, 0.375, 0.875],
                          [0.125, 0.625, 0.125, 0.625, 0.125]]
    ranks = blue_noise_ranks()
    t = thresholds("blue-noise", 70, 130)
    assert t[0, 0] == (ranks[0, 0] + 0.5) / 4096 and (t[64:70, 128:130] == t[0:6, 0:2]).all()


@pytest.mark.parametrize("kind", ("egl", "osmesa"))
def test_the_gpu_pattern_runs_down_the_image(output_passes, kind):
    """A flat field of light 0.7 at 1 bit under Bayer 2: code 1 where T < 0.7, so row 0 (the
    top) is [1, 1] and row 1 is [0, 1]; upside down it would read [0, 1] first."""
    frame = np.full((4, 6, 4), 0.7, np.float32)
    codes = output_passes[kind].apply(frame, OutputSettings(bits=1, dither="bayer2"))
    assert codes[..., 0].tolist() == [[1, 1, 1, 1, 1, 1], [0, 1, 0, 1, 0, 1]] * 2
    assert (codes[..., 0] == codes[..., 1]).all() and (codes[..., 0] == codes[..., 2]).all()
    assert (codes[..., 3] == 1).all()                   # alpha 0.7: plain nearest code


# -- blue noise -------------------------------------------------------------------------------

def low_frequency_power(mask: np.ndarray, radius: float = 8.0) -> float:
    """Mean power of the (mean-free) mask's spectrum at radial frequencies 0 < |f| <= radius
    (cycles per mask side), over the mean power of all non-zero frequencies: about 1 for white
    noise, near 0 for blue noise."""
    power = np.abs(np.fft.fft2(mask - mask.mean())) ** 2
    f = np.fft.fftfreq(mask.shape[0]) * mask.shape[0]
    r = np.hypot(f[:, None], f[None, :])
    return float(power[(r > 0) & (r <= radius)].mean() / power[r > 0].mean())


def test_blue_noise_mask_is_a_permutation_and_deterministic():
    ranks = blue_noise_ranks()
    assert ranks.shape == (64, 64) and ranks.dtype == np.uint16 and not ranks.flags.writeable
    assert (np.sort(ranks.ravel()) == np.arange(4096)).all()
    assert blue_noise_ranks() is ranks                                  # made once


def test_blue_noise_has_little_power_at_low_frequencies():
    ranks = blue_noise_ranks().astype(np.float64)
    white = np.random.default_rng(0).permutation(ranks.ravel()).reshape(ranks.shape)
    assert low_frequency_power(white) > 0.5                  # the measure can fail
    assert low_frequency_power(ranks) < 0.01
    for level in (512, 2048, 3584):                          # each dot pattern it thresholds into
        assert low_frequency_power((ranks < level).astype(np.float64)) < 0.05, level


# -- GPU against twin -------------------------------------------------------------------------

# gamma's tables are searched as sRGB's are: the full run holds it (about 0.5 s)
@pytest.mark.parametrize("kind", ("egl", "osmesa"))
@pytest.mark.parametrize("transfer", [pytest.param(t, marks=[pytest.mark.slow] if t.kind == "gamma" else [])
                                      for t in TRANSFERS], ids=str)
@pytest.mark.parametrize("dither", DITHERS)
def test_dithered_codes_on_the_gpu_are_the_twins(output_passes, kind, transfer, dither):
    frame = linear_frame(width=72, height=20, seed=len(dither))     # wider than a Bayer tile
    for bits in (1, 2, 4, 8, 16):
        settings = OutputSettings(transfer=transfer, bits=bits, dither=dither, format="png16")
        np.testing.assert_array_equal(output_passes[kind].apply(frame, settings),
                                      reference.output.apply(frame, settings),
                                      err_msg=f"{bits} bits")
