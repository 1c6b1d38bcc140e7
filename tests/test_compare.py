"""The comparison rules of renderer/checks/compare.py on hand-made images."""

import math

import numpy as np

from renderer.checks.compare import (Envelope, channel_difference, compare_frames, depth_max_rel,
                                     either_precision, grazing_ray_pixels, heat_map,
                                     position_deviation_mismatch, raw_mismatch)
from renderer.core.frame import Frame


def blank(h=8, w=8, value=0):
    image = np.zeros((h, w, 4), dtype=np.uint8)
    image[...] = value
    return image


def test_identical_images_have_no_error_and_infinite_psnr():
    a = blank(value=77)
    result = compare_frames(a, a.copy())
    assert result.max_abs == 0 and result.rmse == 0 and math.isinf(result.psnr)
    assert result.mismatched_pixels == 0 and result.raw_mismatched_pixels == 0


def test_threshold_is_inclusive():
    a, b = blank(), blank()
    b[2, 3, 0] = 2
    assert not raw_mismatch(a, b, threshold=2).any()
    b[2, 3, 0] = 3
    assert raw_mismatch(a, b, threshold=2).sum() == 1


def test_an_edge_moved_by_one_pixel_passes_with_deviation_only():
    a, b = blank(), blank()
    a[:, 4:] = 200            # a vertical edge between columns 3 and 4
    b[:, 5:] = 200            # the same edge one pixel to the right
    assert raw_mismatch(a, b).sum() == 8
    assert not position_deviation_mismatch(a, b, deviation=1).any()
    assert position_deviation_mismatch(a, b, deviation=0).sum() == 8


def test_a_missing_pixel_fails_in_one_direction_so_it_fails():
    a, b = blank(), blank()
    a[4, 4] = 255             # a single bright pixel only the result has
    mask = position_deviation_mismatch(a, b)
    assert mask.sum() == 1 and mask[4, 4]


def test_metrics_on_a_hand_computed_difference():
    a, b = blank(2, 2), blank(2, 2)
    b[0, 0, :3] = 12          # one pixel, three channels off by 12 of 12 channel values
    result = compare_frames(a, b)
    assert result.max_abs == 12
    assert math.isclose(result.mean_abs, 3 * 12 / 12)
    assert math.isclose(result.rmse, math.sqrt(3 * 144 / 12))
    assert math.isclose(result.psnr, 20 * math.log10(255 / math.sqrt(36)))
    assert result.raw_mismatched_fraction == 0.25


def test_depth_relative_error_allows_a_silhouette_to_move_one_pixel():
    a = np.full((4, 4), 10.0, dtype=np.float32)   # a far wall ...
    b = a.copy()
    a[:, 1:] = 2.0            # ... with an object in front whose edge is at column 1 in a
    b[:, 2:] = 2.0            # and at column 2 in b
    a[0, 0] = b[0, 0] = np.inf
    assert depth_max_rel(a, b) == 0.0
    b[:, 3] = 2.2             # b now puts the object's right part 10 % farther
    assert math.isclose(depth_max_rel(a, b), 0.1, rel_tol=1e-5)


def test_depth_at_an_edge_on_silhouette_is_held_against_the_surface_continued_one_pixel():
    """A surface seen edge-on changes depth by 1 % a pixel: where one image covers one more
    pixel of it than the other, that pixel's depth is the other's surface continued, not its
    neighbour's; a depth off that line still fails."""
    a = np.full((3, 5), 20.0)                        # the floor behind ...
    a[1, :4] = [10.0, 10.1, 10.2, 10.3]              # ... a surface rising 0.1 a pixel
    b = a.copy()
    b[1, 3] = 20.0                                   # b's silhouette one pixel to the left
    assert math.isclose(depth_max_rel(a, b), 0.0, abs_tol=1e-12)     # 10.2 + 0.1 = 10.3
    a[1, 3] = 10.4                                   # not on the surface's line
    assert math.isclose(depth_max_rel(a, b), 0.1 / 10.3, rel_tol=1e-6)


def test_heat_map_marks_failing_pixels_magenta():
    a, b = blank(), blank()
    a[4, 4] = 255
    image = heat_map(a, b)
    assert image.shape == (8, 8, 3) and tuple(image[4, 4]) == (255, 0, 255)
    assert tuple(image[0, 0]) == (0, 0, 0)


def test_a_depth_tie_accepts_either_surface_and_nothing_else():
    """Where the reference's rgba8_tie differs (two surfaces closer than GL can order), a
    pixel matching either colour passes; a third colour still fails, and so does the tie
    colour anywhere the reference has no tie."""
    reference, tie = blank(value=40), blank(value=40)
    tie[4, 4] = (200, 10, 10, 255)
    result = reference.copy()
    result[4, 4] = (200, 10, 10, 255)                   # the other surface won
    assert position_deviation_mismatch(result, reference).sum() == 1
    assert position_deviation_mismatch(result, reference, reference_tie=tie).sum() == 0
    figures = compare_frames(result, reference, reference_tie=tie)
    assert figures.mismatched_pixels == 0 and figures.raw_mismatched_pixels == 0 and figures.max_abs == 0
    result[4, 4] = (10, 200, 10, 255)                    # neither surface
    assert compare_frames(result, reference, reference_tie=tie).mismatched_pixels == 1
    result[4, 4] = reference[4, 4]
    result[1, 1] = (200, 10, 10, 255)                    # the tie's colour where there is no tie
    assert compare_frames(result, reference, reference_tie=tie).mismatched_pixels == 1
    assert not heat_map(reference, reference, reference_tie=tie).any()


def test_grazing_rays_accept_either_precision_there_and_nothing_else():
    """Where the float32 and float64 references' ray trees differ (a grazing ray hit in one
    precision and missed in the other), the GPU may show either one's colour and depth; a
    third colour there fails, and so does the float64 colour anywhere else."""
    trees32, trees64 = np.zeros((8, 8), np.uint64), np.zeros((8, 8), np.uint64)
    trees64[4, 4] = 7                                    # one pixel's tree differs
    depth = np.full((8, 8), 5.0, np.float32)
    ref32 = Frame(blank(value=40), depth=depth, ray_tree=trees32)
    ref64 = Frame(blank(value=40), depth=depth.copy(), ray_tree=trees64)
    ref64.rgba8[4, 4] = (200, 10, 10, 255)
    ref64.depth[4, 4] = 9.0                              # another surface behind
    assert grazing_ray_pixels(ref32, ref64).sum() == 1
    tie, tie_depth, pixels = either_precision(ref32, ref64)
    assert pixels == 1 and tuple(tie[4, 4]) == (200, 10, 10, 255) and tie_depth[4, 4] == 9.0
    assert either_precision(ref32, ref32) == (None, None, 0)
    result, result_depth = ref64.rgba8.copy(), ref64.depth.copy()    # the GPU took float64's side
    figures = compare_frames(result, ref32.rgba8, result_depth, ref32.depth,
                             reference_tie=tie, reference_tie_depth=tie_depth)
    assert figures.mismatched_pixels == 0 and figures.raw_mismatched_pixels == 0
    assert figures.depth_max_rel == 0.0
    assert compare_frames(result, ref32.rgba8, result_depth, ref32.depth).mismatched_pixels == 1
    assert depth_max_rel(result_depth, ref32.depth) > 0.5
    result[4, 4] = (10, 200, 10, 255)                    # neither precision's colour
    assert compare_frames(result, ref32.rgba8, reference_tie=tie).mismatched_pixels == 1
    result[4, 4], result[1, 1] = ref32.rgba8[4, 4], (200, 10, 10, 255)   # float64's, elsewhere
    assert compare_frames(result, ref32.rgba8, reference_tie=tie).mismatched_pixels == 1


def test_an_envelope_accepts_its_range_widened_by_the_threshold_and_nothing_more():
    """Against an Envelope (several acceptable references: the twin over the texture
    verifier's coordinate bound, renderer/checks/texture_bounds.py) a channel matches within
    the threshold of [low, high] and differs by its distance outside; an envelope of one
    image is that image; the ±1 px allowance and both directions hold as for an image."""
    low, high = blank(value=100), blank(value=100)
    high[4, 4, 0] = 110                                  # one channel may be 100..110
    envelope = Envelope(low, high)
    result = blank(value=100)
    for red, outside in [(90, 10), (97, 3), (98, 2), (105, 0), (112, 2), (113, 3)]:
        result[4, 4, 0] = red
        assert channel_difference(result, envelope)[4, 4, 0] == outside
        assert compare_frames(result, envelope).max_abs == outside
        assert raw_mismatch(result, envelope).sum() == (outside > 2)
    result[4, 4, 0] = 113                                # beyond high + 2: fails, even within ±1 px
    assert position_deviation_mismatch(result, envelope).sum() == 1
    result[4, 4, 0], result[4, 5, 0] = 100, 112          # the neighbour's range holds it
    assert raw_mismatch(result, envelope).sum() == 1
    assert not position_deviation_mismatch(result, envelope).any()
    image = blank(value=60)
    image[2, 2] = 61
    same = Envelope.of([image, image])
    for other in (image, blank(value=64)):
        assert (position_deviation_mismatch(other, same) == position_deviation_mismatch(other, image)).all()
        assert (channel_difference(other, same) == channel_difference(other, image)).all()
    both = Envelope.of([blank(value=10), blank(value=30)])
    assert (both.low == 10).all() and (both.high == 30).all()
    assert compare_frames(blank(value=20), both).max_abs == 0
