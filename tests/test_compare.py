"""The comparison rules of renderer/checks/compare.py on hand-made images."""

import math

import numpy as np

from renderer.checks.compare import (compare_frames, depth_max_rel, heat_map,
                              position_deviation_mismatch, raw_mismatch)


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
