"""Error diffusion (renderer/core/error_kernels.py; reference/output/error_diffusion.py and
glsl/output/error_diffusion.comp): Floyd-Steinberg by hand, the kernels as printed, the pull
form against the classic push algorithm in exact arithmetic, the wavefront order against every
dependency, and the GPU's wavefront dispatches against the twin bit for bit.
"""

from fractions import Fraction

import numpy as np
import pytest

import reference.output
from renderer.core.error_kernels import KERNELS, pull_taps, sender_weights, wavefronts
from renderer.core.output_settings import ERROR_DIFFUSION, OutputSettings, Transfer
from renderer.core.quantise import code_values
from reference.output.error_diffusion import diffuse
from reference.output.quantise import clamp_light
from output_cases import linear_frame

LINEAR, SRGB = Transfer("linear"), Transfer("srgb")


def grey(rows) -> np.ndarray:
    """(H, W, 3) float32 with R = G = B = rows."""
    return np.repeat(np.asarray(rows, np.float32)[..., None], 3, axis=-1)


def test_floyd_steinberg_by_hand():
    # 1 bit, linear: code 1 iff L' > 1/2, e = L' - code. A source on an edge shares its error
    # among its receivers inside the image: (2,0) sends 3/8 and 5/8 down, the bottom row all
    # of it right. (0,0)'s shares would be 13ths, so its error is made 0 (L = 1), and every
    # number here is a short binary fraction: float32 is exact and the hand's sums are the
    # twin's. The taps of a pixel in the order they are added: (x-1,y-1), (x,y-1), (x+1,y-1),
    # (x-1,y).
    #   (0,0) L' = 1                                           -> 1, e = 0
    #   (1,0) L' = 5/8 + 7/16 (0) = 0.625                      -> 1, e = -0.375
    #   (2,0) L' = 1/8 + 7/16 (-0.375) = -0.0390625            -> 0, e = -0.0390625
    #   (0,1) L' = 1/2 + 5/13 (0) + 3/16 (-0.375) = 0.4296875  -> 0, e = 0.4296875
    #   (1,1) L' = 3/8 + 1/13 (0) + 5/16 (-0.375) + 3/8 (-0.0390625) + 1 (0.4296875)
    #            = 0.6728515625                                -> 1, e = -0.3271484375
    #   (2,1) L' = 3/4 + 1/16 (-0.375) + 5/8 (-0.0390625) + 1 (-0.3271484375)
    #            = 0.375                                       -> 0, e = 0.375 (the last)
    # Plain rounding would give (1,1) 0 and (2,1) 1: the diffused error decides them; and the
    # codes' light, 3, is the image's 3.375 less the last pixel's error.
    codes, error = diffuse(grey([[1.0, 0.625, 0.125], [0.5, 0.375, 0.75]]),
                           "floyd-steinberg", LINEAR, 1)
    np.testing.assert_array_equal(codes[..., 0], [[1, 1, 0], [0, 1, 0]])
    reach = KERNELS["floyd-steinberg"].reach
    np.testing.assert_array_equal(error[reach:, reach:-reach, 0],
                                  [[0.0, -0.375, -0.0390625], [0.4296875, -0.3271484375, 0.375]])
    assert not error[:reach].any() and not error[:, :reach].any() and not error[:, -reach:].any()


def test_the_kernels_are_the_printed_ones():
    fs, jjn = KERNELS["floyd-steinberg"], KERNELS["jarvis-judice-ninke"]
    assert fs.push == {(1, 0): 7, (-1, 1): 3, (0, 1): 5, (1, 1): 1} and fs.divisor == 16
    rows = [[jjn.push.get((dx, dy), 0) for dx in range(-2, 3)] for dy in range(3)]
    assert rows == [[0, 0, 0, 7, 5], [3, 5, 7, 5, 3], [1, 3, 5, 3, 1]] and jjn.divisor == 48


@pytest.mark.parametrize("name", ERROR_DIFFUSION)
def test_the_shares_sum_to_one(name):
    kernel = KERNELS[name]
    reach, taps = kernel.reach, pull_taps(name)
    assert sum(kernel.push.values()) == kernel.divisor          # all the error is passed on
    shares = sender_weights(name)
    # inside the image: the printed weights, reversed into pull form
    assert {(-dx, -dy): np.float32(w / kernel.divisor) for (dx, dy), w in kernel.push.items()} \
        == {tuple(map(int, tap)): share for tap, share in zip(taps, shares[reach, reach, reach])}
    if name == "floyd-steinberg":                               # sixteenths: exact
        assert sum(Fraction(float(w)) for w in shares[reach, reach, reach]) == 1
    # at every edge and corner a source passes all its error on to its receivers inside, each
    # share rounded once (within half an ulp), but the bottom-right pixel, which has none
    for left, right, below in np.ndindex(shares.shape[:3]):
        row = shares[left, right, below]
        if (right, below) == (0, 0):
            assert not row.any()
            continue
        total = sum(Fraction(float(share)) for share in row)
        assert abs(total - 1) <= Fraction(int((row > 0).sum()), 2 ** 25), (left, right, below)


@pytest.mark.parametrize("name", ERROR_DIFFUSION)
def test_the_taps_are_in_raster_order(name):
    taps = pull_taps(name)
    assert [(dy, dx) for dx, dy in taps] == sorted((dy, dx) for dx, dy in taps)
    assert (taps[:, 1] <= 0).all() and ((taps[:, 1] < 0) | (taps[:, 0] < 0)).all()


@pytest.mark.parametrize("name", ERROR_DIFFUSION)
def test_the_wavefronts_order_every_dependency(name):
    skew = KERNELS[name].skew
    assert skew == {"floyd-steinberg": 2, "jarvis-judice-ninke": 3}[name]
    offsets = pull_taps(name)
    # every source lies on an earlier wavefront t - (dx + s dy) ... and s is the least skew
    # that does it (with s - 1 some source would be on the same or a later wavefront)
    assert all(dx + skew * dy < 0 for dx, dy in offsets)
    assert not all(dx + (skew - 1) * dy < 0 for dx, dy in offsets)
    for width, height in ((9, 7), (1, 5), (6, 1), (2, 9)):
        order = np.full((height, width), -1)
        for step, (t, first, last) in enumerate(wavefronts(width, height, skew)):
            y = np.arange(first, last + 1)
            x = t - skew * y
            assert ((x >= 0) & (x < width)).all() and (order[y, x] == -1).all()
            order[y, x] = step
        assert (order >= 0).all(), "every pixel on one wavefront"
        assert step == width + skew * (height - 1) - 1
        y, x = np.mgrid[0:height, 0:width]
        for dx, dy in offsets:
            inside = (x + dx >= 0) & (x + dx < width) & (y + dy >= 0)
            source = order[np.clip(y + dy, 0, None), np.clip(x + dx, 0, width - 1)]
            assert (source[inside] < order[inside]).all(), f"tap {dx, dy} at {width}x{height}"


def push_algorithm(light: np.ndarray, name: str, transfer: Transfer, bits: int):
    """The classic algorithm (Floyd and Steinberg 1976) in exact rational arithmetic, pixel by
    pixel in raster order, each error pushed forward to the receivers inside the image in
    proportion to their weights: (codes, the least distance of any target from its decision,
    which must be clear of float32 rounding for the comparison to mean anything)."""
    kernel = KERNELS[name]
    values = [Fraction(float(v)) for v in code_values(transfer, bits)]
    height, width = light.shape
    pending = [[Fraction(0)] * width for _ in range(height)]
    codes = np.zeros((height, width), np.int64)
    margin = Fraction(1)
    for y in range(height):
        for x in range(width):
            target = min(max(Fraction(float(light[y, x])), Fraction(0)), Fraction(1)) + pending[y][x]
            clamped = min(max(target, Fraction(0)), Fraction(1))
            low = max(k for k, v in enumerate(values) if v <= clamped)
            code = low
            if low < len(values) - 1:
                middle = (values[low] + values[low + 1]) / 2
                margin = min(margin, abs(clamped - middle))
                code = low + 1 if clamped > middle else low
            codes[y, x] = code
            receivers = {(x + dx, y + dy): w for (dx, dy), w in kernel.push.items()
                         if 0 <= x + dx < width and y + dy < height}
            for (u, v), w in receivers.items():
                pending[v][u] += (target - values[code]) * w / sum(receivers.values())
    return codes, margin


@pytest.mark.parametrize("name", ERROR_DIFFUSION)
@pytest.mark.parametrize("transfer, bits", ((LINEAR, 1), (SRGB, 2)), ids=("linear-1", "srgb-2"))
def test_the_pull_form_is_the_classic_push_algorithm(name, transfer, bits):
    light = np.random.default_rng(3).uniform(-0.05, 1.05, (6, 9)).astype(np.float32)
    for shape in ((6, 9), (6, 1), (1, 9), (2, 2)):           # the edges, and a row or column alone
        part = light[:shape[0], :shape[1]]
        expected, margin = push_algorithm(part, name, transfer, bits)
        assert margin > 1e-6, "a target within float32 rounding of its decision: another seed"
        codes, _ = diffuse(grey(part), name, transfer, bits)
        np.testing.assert_array_equal(codes[..., 0], expected, err_msg=shape)


@pytest.mark.parametrize("name", ERROR_DIFFUSION)
@pytest.mark.parametrize("transfer, bits", ((LINEAR, 1), (SRGB, 2), (LINEAR, 4)), ids=str)
def test_the_codes_keep_the_light_but_for_the_last_pixels_error(name, transfer, bits):
    light = np.random.default_rng(5).uniform(-0.2, 1.2, (31, 37, 3)).astype(np.float32)
    codes, error = diffuse(light, name, transfer, bits)
    shown = code_values(transfer, bits)[codes].astype(np.float64).sum(axis=(0, 1))
    kept = clamp_light(light).astype(np.float64).sum(axis=(0, 1))
    last = error[-1, -1 - KERNELS[name].reach].astype(np.float64)
    assert np.abs(last).max() > 1e-3                    # the check below sees it
    # each pixel's error and incoming sum are rounded to float32: 1e-5 allows ~100 ulps at 1
    np.testing.assert_allclose(shown, kept - last, rtol=0, atol=1e-5 * light.size / 3)


# The levels k/64 of a flat field (the means an 8x8 block can hold at 1 bit), and the worst
# deviation of any aligned 8x8 block's mean from its level, measured over every level on 64x64
# fields: Floyd-Steinberg 3/64, Jarvis-Judice-Ninke 5/64 (2026-12-02). The default run takes
# every seventh level on 32x32 fields, the full run all of them on 64x64 (three at a time).
FLAT_BLOCK_BOUND = {"floyd-steinberg": 3 / 64, "jarvis-judice-ninke": 5 / 64}


@pytest.mark.parametrize("name", ERROR_DIFFUSION)
@pytest.mark.parametrize("levels, side", [
    pytest.param(np.arange(2, 64, 7), 32, id="some-levels"),
    pytest.param(np.arange(1, 64), 64, id="every-level", marks=pytest.mark.slow)])
def test_a_flat_fields_blocks_keep_its_level(name, levels, side):
    for three in (levels / np.float32(64)).astype(np.float32).reshape(-1, 3):
        field = np.broadcast_to(three, (side, side, 3))          # a level in each channel
        codes, _ = diffuse(np.ascontiguousarray(field), name, LINEAR, 1)
        np.testing.assert_array_equal(codes.mean(axis=(0, 1)), three)   # the light: exact
        blocks = codes.reshape(side // 8, 8, side // 8, 8, 3).mean(axis=(1, 3))
        assert np.abs(blocks - three).max() <= FLAT_BLOCK_BOUND[name], three * 64


# On OSMesa (the same llvmpipe) the default run keeps the last kernel in sRGB; the other three
# OSMesa cases are the full run's (--all). EGL runs every kernel and transfer by default.
OSMESA_BY_DEFAULT = (SRGB, ERROR_DIFFUSION[-1])


@pytest.mark.parametrize("transfer, name, kind", [
    pytest.param(transfer, name, kind, id=f"{transfer}-{name}-{kind}", marks=[pytest.mark.slow] if (
        kind == "osmesa" and (transfer, name) != OSMESA_BY_DEFAULT) else [])
    for transfer in (LINEAR, SRGB) for name in ERROR_DIFFUSION for kind in ("egl", "osmesa")])
def test_the_gpu_wavefronts_are_the_twin(output_passes, kind, name, transfer):
    frame = linear_frame(width=23, height=17)
    for bits in (1, 2, 4, 8):
        settings = OutputSettings(transfer=transfer, bits=bits, dither=name)
        np.testing.assert_array_equal(output_passes[kind].apply(frame, settings),
                                      reference.output.apply(frame, settings),
                                      err_msg=f"{name}, {transfer} at {bits} bits")
    # 3 x 5 and 5 x 5: (nearly) every source at an edge. Sizes whose images (the frame and the
    # bordered error image) are, like 23 x 17's, no power of two along either axis: llvmpipe
    # compiles a shader again (0.3 to 0.5 s) for each new pattern of power-of-two sizes among
    # the images it binds. A single row or column (a side of 1 = 2^0): the twin's tests above.
    settings = OutputSettings(transfer=transfer, bits=1, dither=name)
    for small in (frame[:5, :3], frame[:5, :5]):
        small = np.ascontiguousarray(small)
        np.testing.assert_array_equal(output_passes[kind].apply(small, settings),
                                      reference.output.apply(small, settings), err_msg=small.shape)
