"""Float output (exr, npy): encode() of each RGB channel, unquantised, alpha as it is
(reference/output/transfer.py; glsl/output/transfer.glsl).

The GPU evaluates the curves with GLSL's pow, which llvmpipe computes as exp2(log2(L) y) in
float32 (docs/llvmpipe/output.md, section 2): a few ulps from the exact value, and more as
|y log2 L| grows, since the product's rounding error is relative to it. The bound, against the
float64 curve rounded to float32:

    |GPU - encode(L)| <= FLOAT_OUTPUT_ULPS ulp(encode(L)) (1 + |y log2 L|) + FLT_MIN

for L = 0 and every normal float32 L (y = 1/2.4 for sRGB, 1/gamma; FLT_MIN because llvmpipe
flushes denormal results to 0). A denormal L (below FLT_MIN = 1.2e-38) is outside it under a
gamma curve: llvmpipe's log2 reads the exponent field as it stands, so pow(L, y) is that of
a number in [2^-127, 2^-126), e.g. 4.2e-18 for the exact 3.8e-19 (gamma 2.2, L = 3.0e-41):
absolutely tiny, and no rendered frame's light. Measured on this machine's llvmpipe over 3 x 2^18 inputs per curve: at most
4.9 ulp (1 + |y log2 L|), 10.2 ulps in all for sRGB. The linear transfer is exact.
"""

import numpy as np
import pytest

from renderer.core.output_settings import OutputSettings, Transfer
from renderer.core.quantise import encode
from reference.output.transfer import encoded

FLOAT_OUTPUT_ULPS = 8
FLT_MIN = float(np.finfo(np.float32).tiny)


def float_output_bound(light: np.ndarray, transfer: Transfer) -> np.ndarray:
    """The bound of the module docstring for each L (float64)."""
    light = np.nan_to_num(light.astype(np.float64), nan=0.0)
    exact = encode(light, transfer)
    exponent = 1.0 / (2.4 if transfer.kind == "srgb" else transfer.gamma)
    with np.errstate(divide="ignore"):
        spread = np.abs(exponent * np.log2(np.maximum(light, FLT_MIN)))
    ulp = np.spacing(exact.astype(np.float32)).astype(np.float64)
    return FLOAT_OUTPUT_ULPS * ulp * (1.0 + spread) + FLT_MIN


def sample_light(count: int, seed: int = 0) -> np.ndarray:
    """float32 L: an even sweep of [0, 1], random bit patterns of [2^-20, 4] (even in ulps)
    and of the tiny normal floats below."""
    rng = np.random.default_rng(seed)
    bits = lambda low, high: rng.integers(np.float32(low).view(np.int32), np.float32(high).view(np.int32),
                                          count).astype(np.int32).view(np.float32)
    return np.concatenate([np.linspace(0, 1, count, dtype=np.float32), bits(2 ** -20, 4.0),
                           bits(FLT_MIN, 2 ** -20)])


def test_the_twin_encodes_rgb_and_keeps_alpha():
    light = np.array([[[0.5, -1.0, np.nan, 0.25], [2.0, np.inf, 0.001, -3.0]]], np.float32)
    srgb = encoded(light, Transfer("srgb"))
    assert srgb.dtype == np.float32
    assert srgb[0, 0].tolist() == pytest.approx([1.055 * 0.5 ** (1 / 2.4) - 0.055, 0, 0, 0.25], rel=1e-7)
    assert srgb[0, 1, :3].tolist() == pytest.approx([1.055 * 2 ** (1 / 2.4) - 0.055, np.inf, 0.01292],
                                                    rel=1e-7)      # above 1 too: no clamp
    assert srgb[0, 1, 3] == -3.0                                     # alpha as it is
    linear = encoded(light, Transfer("linear"))
    assert linear[0, :, :3].tolist() == [[0.5, 0.0, 0.0], [2.0, np.inf, np.float32(0.001)]]


@pytest.mark.parametrize("kind", ("egl", "osmesa"))
@pytest.mark.parametrize("transfer", (Transfer("linear"), Transfer("srgb"), Transfer("gamma", 2.2),
                                      Transfer("gamma", 0.45)), ids=str)
def test_gpu_float_output_is_within_the_bound(output_passes, kind, transfer):
    light = sample_light(1 << 14).reshape(-1, 64, 4)            # 192 x 64 pixels
    light[0, :4] = [[np.nan, -1.0, np.inf, 0.5], [-np.inf, -0.0, FLT_MIN, np.nan],
                    [0.0, 1.0, 2.0, np.inf], [0.0031308, 0.0031309, 0.04, -np.inf]]
    settings = OutputSettings(transfer=transfer, format="npy")
    gpu = output_passes[kind].apply(light, settings)
    twin = encoded(light, transfer)
    assert gpu.dtype == np.float32
    np.testing.assert_array_equal(gpu[..., 3], light[..., 3])
    rgb, gpu_rgb, twin_rgb = light[..., :3], gpu[..., :3], twin[..., :3]
    assert np.array_equal(np.isinf(gpu_rgb), np.isinf(twin_rgb)) and not np.isnan(gpu_rgb).any()
    finite = np.isfinite(twin_rgb)
    if transfer.kind == "linear":
        np.testing.assert_array_equal(gpu_rgb, twin_rgb)
        return
    error = np.abs(gpu_rgb[finite].astype(np.float64) - encode(rgb[finite], transfer))
    bound = float_output_bound(rgb[finite], transfer)
    worst = np.argmax(error / bound)
    assert (error <= bound).all(), (f"L = {rgb[finite][worst]!r}: GPU {gpu_rgb[finite][worst]!r}, "
                                    f"exact {encode(rgb[finite][worst], transfer)!r}")
