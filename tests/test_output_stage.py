"""The output stage's two twins (renderer/gpu/output.py with glsl/output/output.comp, and
reference/output/): the contract both follow (docs/conventions.md, "Output"), and GPU against
twin bit for bit on frames made to hold every case (NaN, infinities, negatives, above 1,
each code's edges).

The rules themselves (quantisation, dithering, float encoding) have their own files:
test_output_quantise.py, test_output_dither.py, test_output_transfer.py.
"""

import numpy as np
import pytest

import reference.output
from renderer.core.output_settings import OutputSettings, Transfer

TRANSFERS = (Transfer("linear"), Transfer("srgb"), Transfer("gamma", 2.2))
SPECIALS = np.array([np.nan, np.inf, -np.inf, -0.0, -1.0, 1.0, 2.0, 1e-30, 1e-45], np.float32)


def test_frame(width=40, height=24, seed=0) -> np.ndarray:
    """(height, width, 4) float32 linear colour: random in [-0.1, 1.1], the first pixels of
    each channel the special values."""
    frame = np.random.default_rng(seed).uniform(-0.1, 1.1, (height, width, 4)).astype(np.float32)
    for channel in range(4):
        frame[channel, :SPECIALS.size, channel] = SPECIALS
    return frame


test_frame.__test__ = False          # a helper, not a test


@pytest.mark.parametrize("kind", ("egl", "osmesa"))
@pytest.mark.parametrize("transfer", TRANSFERS, ids=str)
def test_undithered_codes_on_the_gpu_are_the_twins(output_passes, kind, transfer):
    frame = test_frame()
    for bits in (1, 8, 16):
        settings = OutputSettings(transfer=transfer, bits=bits, format="png16")
        gpu = output_passes[kind].apply(frame, settings)
        assert gpu.dtype == np.uint16 and gpu.shape == frame.shape
        np.testing.assert_array_equal(gpu, reference.output.apply(frame, settings),
                                      err_msg=f"{transfer} at {bits} bits")
