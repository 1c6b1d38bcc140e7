"""The reference draws a large frame band by band (reference/pipeline.py, TILE_PIXELS), so its
memory beyond the output arrays stays bounded. Every stage after culling works pixel by pixel,
so the bands must give the very same frame as one pass: colour, linear colour, depth and the
depth-tie image, bit for bit."""

import numpy as np
import pytest

import reference
from reference.pipeline import TILE_PIXELS, tiles
from renderer.core.builtin import assets_dir
from renderer.core.scene_file import load_scene

SIZE = (96, 64)


def test_bands_cover_the_frame_once_in_whole_rows():
    assert tiles(640, 480) == [(0, 0, 640, 480)]                     # small: one band
    bands = tiles(1000, 30, tile_pixels=3000)
    assert bands == [(0, 0, 1000, 3), (0, 3, 1000, 6), (0, 6, 1000, 9), (0, 9, 1000, 12),
                     (0, 12, 1000, 15), (0, 15, 1000, 18), (0, 18, 1000, 21), (0, 21, 1000, 24),
                     (0, 24, 1000, 27), (0, 27, 1000, 30)]
    assert tiles(5000, 3, tile_pixels=100) == [(0, 0, 5000, 1), (0, 1, 5000, 2), (0, 2, 5000, 3)]
    assert TILE_PIXELS * 300 < 512 * 2 ** 20                 # a band's working set: well under 512 MiB


# The full run (--all) holds every scene in 7-row and in 1-row bands (the shadow maps' depth
# passes too). The default run holds hierarchy (shadow maps, their depth passes banded too)
# in 1-row bands and x_depth_ratio_1e8 (reversed z) in 7-row ones; near_plane's clipping and
# orthographic's projection are done before the frame is cut into bands (prepare_frame), so
# their bands take the path the others' do.
DEFAULT_RUN_BANDS = {("hierarchy", "1-row bands"), ("x_depth_ratio_1e8", "7-row bands")}
BANDS = [pytest.param(name, tile, id=f"{name}-{label}",
                      marks=[] if (name, label) in DEFAULT_RUN_BANDS else [pytest.mark.slow])
         for name in ("near_plane", "hierarchy", "orthographic", "x_depth_ratio_1e8")
         for tile, label in ((SIZE[0] * 7, "7-row bands"), (10, "1-row bands"))]


@pytest.mark.parametrize("name, tile_pixels", BANDS)
def test_bands_give_the_same_frame_bit_for_bit(name, tile_pixels, reference_frames):
    scene = assets_dir() / "extreme" / f"{name[2:]}.toml" if name.startswith("x_") else name
    whole = reference_frames(scene, *SIZE, linear=True)
    banded = reference.render(load_scene(scene), *SIZE, linear=True, tile_pixels=tile_pixels)
    for field in ("rgba8", "linear", "depth"):
        np.testing.assert_array_equal(getattr(banded, field), getattr(whole, field), err_msg=field)
    assert (banded.rgba8_tie is None) == (whole.rgba8_tie is None)
    if whole.rgba8_tie is not None:
        np.testing.assert_array_equal(banded.rgba8_tie, whole.rgba8_tie)


@pytest.mark.slow
def test_depth_ties_are_pasted_band_by_band(reference_frames):
    """flat_shading at 256x256 has two pixels where the reference accepts another surface
    (a depth tie); drawn in 1-row bands, the tie image is the same."""
    whole = reference_frames("flat_shading", 256, 256)
    assert int((whole.rgba8_tie != whole.rgba8).any(axis=-1).sum()) == 2
    banded = reference.render(load_scene("flat_shading"), 256, 256, tile_pixels=256)
    np.testing.assert_array_equal(banded.rgba8, whole.rgba8)
    np.testing.assert_array_equal(banded.rgba8_tie, whole.rgba8_tie)
