"""The viewer's reference view (renderer/viewer/reference_view.py): the NumPy reference of the view
made in a background process, only the newest request kept, and the difference figures."""

from dataclasses import replace

import numpy as np
import pytest

import reference
from renderer.core.builtin import resolve_scene
from renderer.viewer.reference_view import BackgroundReference, ReferenceResult, difference_view
from renderer.core.scene_file import load_scene


@pytest.fixture(scope="module")
def background():
    worker = BackgroundReference()
    yield worker
    worker.close()


def test_the_background_render_is_the_reference(background):
    scene = load_scene(resolve_scene("point_light_plane"))
    background.request(scene, 40, 30, version=7)
    assert background.busy
    result = background.wait(timeout=60)
    assert result.version == 7
    assert np.array_equal(result.rgba8, reference.render(scene, 40, 30).rgba8)
    assert not background.busy and background.poll() is None


def test_only_the_newest_waiting_request_is_rendered(background):
    scene = load_scene(resolve_scene("point_light_plane"))
    moved = replace(scene, camera=replace(scene.camera, eye=(1.0, 2.0, 6.0)))
    background.request(scene, 40, 30, version=1)       # starts at once
    background.request(scene, 40, 30, version=2)       # waits, then is replaced by
    background.request(moved, 40, 30, version=3)       # this one
    versions = []
    while background.busy:
        result = background.wait(timeout=60)
        if result is not None:
            versions.append(result.version)
    assert versions[-1] == 3 and 2 not in versions
    assert np.array_equal(result.rgba8, reference.render(moved, 40, 30).rgba8)


def test_poll_never_blocks(background):
    scene = load_scene(resolve_scene("sphere"))
    background.request(scene, 64, 48, version=1)
    assert background.poll() is None                   # the worker has not finished yet
    background.wait(timeout=60)


def test_identical_images_make_a_black_heat_map_and_zero_figures():
    image = np.zeros((6, 8, 4), np.uint8)
    image[2:4, 2:6] = (200, 100, 50, 255)
    heat, figures = difference_view(image, ReferenceResult(1, image.copy(), None, 12.0))
    assert heat.shape == (6, 8, 3) and heat.max() == 0
    assert figures["rmse"] == 0 and figures["max_abs"] == 0 and figures["mismatched"] == 0
    assert figures["reference_ms"] == 12.0


def test_a_pixel_far_off_is_counted_and_shown_magenta():
    image = np.zeros((6, 8, 4), np.uint8)
    other = image.copy()
    other[3, 4] = (255, 255, 255, 255)
    heat, figures = difference_view(image, ReferenceResult(1, other, None, 1.0))
    assert figures["max_abs"] == 255 and figures["mismatched"] == 1
    assert tuple(heat[3, 4]) == (255, 0, 255)


def test_close_stops_a_render_in_progress():
    """Closing the viewer must not leave a worker rendering for seconds (the process would
    wait for it at exit)."""
    import multiprocessing
    import time
    before = {p.pid for p in multiprocessing.active_children()}
    worker = BackgroundReference()
    worker.request(load_scene(resolve_scene("near_plane")), 1600, 1200, version=1)   # seconds
    time.sleep(1.0)                                  # the worker has started and is rendering
    ours = [p for p in multiprocessing.active_children() if p.pid not in before]
    assert ours and all(p.is_alive() for p in ours)
    worker.close()
    assert not worker.busy
    time.sleep(0.2)
    assert not any(p.is_alive() for p in ours)
