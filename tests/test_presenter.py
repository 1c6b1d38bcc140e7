"""How the viewer puts images on the screen (renderer/viewer/presenter.py, renderer/viewer/overlay.py):
letterboxing, copies between framebuffers, CPU images, double and triple buffering. All of it
runs on a headless context: a window's default framebuffer is one more target."""

import numpy as np
import pytest

from renderer.viewer.overlay import BACKGROUND, text_panel
from renderer.viewer.presenter import Blitter, CpuImage, Presenter, fit


# -- letterboxing -------------------------------------------------------------------------------
def test_fit_keeps_the_aspect_ratio_and_centres():
    # A 4:3 image in a 200 x 100 region: as high as the region, 133 wide, centred
    # (67 columns over: 33 on the left, 34 on the right).
    assert fit((640, 480), (0, 0, 200, 100)) == (33, 0, 166, 100)
    # The same image in a tall region: as wide as it, centred vertically.
    assert fit((640, 480), (0, 0, 100, 200)) == (0, 62, 100, 137)


def test_fit_at_the_images_own_size_is_the_identity():
    assert fit((320, 240), (0, 0, 320, 240)) == (0, 0, 320, 240)


def test_fit_in_the_right_half():
    assert fit((100, 50), (100, 0, 200, 100)) == (100, 25, 200, 75)


# -- copies -------------------------------------------------------------------------------------
def _framebuffer(ctx, size):
    colour = ctx.renderbuffer(size, 4)
    return ctx.framebuffer([colour]), colour


def _read_top_down(fbo):
    w, h = fbo.size
    return np.frombuffer(fbo.read(components=4, alignment=1), np.uint8).reshape(h, w, 4)[::-1]


@pytest.fixture
def ctx(gl_contexts):
    from renderer.gpu.context import activate
    ctx = gl_contexts["egl"]
    activate(ctx)
    return ctx


def test_cpu_image_keeps_row_0_at_the_top(ctx):
    image = np.zeros((4, 6, 3), np.uint8)
    image[0] = (255, 0, 0)                       # top row red
    image[-1] = (0, 0, 255)                      # bottom row blue
    source = CpuImage(ctx)
    fbo = source.upload(image)
    target, colour = _framebuffer(ctx, (6, 4))
    Blitter(ctx).copy(fbo, target)
    out = _read_top_down(target)
    assert (out[0, :, :3] == (255, 0, 0)).all() and (out[-1, :, :3] == (0, 0, 255)).all()
    assert (out[..., 3] == 255).all()            # RGB images are made opaque
    for item in (target, colour):
        item.release()
    source.release()


def test_blit_into_a_rectangle_leaves_the_rest(ctx):
    source = CpuImage(ctx)
    fbo = source.upload(np.full((2, 2, 3), 200, np.uint8))
    target, colour = _framebuffer(ctx, (8, 8))
    target.use()
    target.clear(0.0, 0.0, 0.0, 1.0)
    Blitter(ctx).copy(fbo, target, (2, 2, 6, 6))         # scaled 2x, GL window coordinates
    out = _read_top_down(target)[..., 0]
    assert (out[2:6, 2:6] == 200).all()
    assert out.sum() == 16 * 200
    for item in (target, colour):
        item.release()
    source.release()


# -- double and triple buffering ------------------------------------------------------------------
@pytest.fixture
def frames(ctx):
    """frames(count): `count` framebuffers, frame k filled with the grey level 10 k;
    released after the test."""
    made = []

    def make(count, size=(4, 4)):
        fbos = []
        for k in range(count):
            fbo, colour = _framebuffer(ctx, size)
            fbo.use()
            fbo.clear(10 * k / 255, 10 * k / 255, 10 * k / 255, 1.0)
            made.extend((fbo, colour))
            fbos.append(fbo)
        return fbos

    yield make
    for item in made:
        item.release()


def _level(fbo):
    return int(_read_top_down(fbo)[0, 0, 0])


def test_double_buffering_shows_the_frame_just_drawn(ctx, frames):
    presenter = Presenter(ctx, buffering=2)
    for k, fbo in enumerate(frames(3)):
        presenter.submit(fbo, started=float(k))
        assert _level(presenter.shown) == 10 * k
        presenter.swapped(now=k + 0.004)
    assert presenter.latency_ms == pytest.approx(4.0)
    presenter.release()


def test_triple_buffering_shows_the_frame_before_one_frame_later(ctx, frames):
    presenter = Presenter(ctx, buffering=3)
    shown = []
    for k, fbo in enumerate(frames(5)):
        presenter.submit(fbo, started=float(k))
        shown.append(_level(presenter.shown))
        presenter.swapped(now=k + 0.004)            # each frame takes 1 s here
    # The first frame has nothing before it; then always the previous frame.
    assert shown == [0, 0, 10, 20, 30]
    # Frame k is on the screen at the swap of frame k + 1: 1.004 s after it began.
    assert presenter.latency_ms == pytest.approx(1004.0)
    assert presenter.name == "triple"
    presenter.release()


def test_switching_buffering_starts_afresh(ctx, frames):
    presenter = Presenter(ctx, buffering=3)
    first, second = frames(2)
    presenter.submit(first, 0.0)
    presenter.set_buffering(2)
    presenter.submit(second, 1.0)
    assert _level(presenter.shown) == 10 and presenter.latency_ms is None
    with pytest.raises(ValueError, match="2 .double. or 3 .triple."):
        presenter.set_buffering(4)
    presenter.release()


# -- text ---------------------------------------------------------------------------------------
def test_text_panel_is_an_opaque_dark_box_with_light_text():
    panel = text_panel(["H  help", "Esc  quit"], 400, 300)
    assert panel.dtype == np.uint8 and panel.shape[2] == 3
    assert tuple(panel[0, 0]) == BACKGROUND
    assert panel.max() > 200                     # some text was drawn
    assert panel.shape[0] < 60 and panel.shape[1] < 200


def test_text_panel_is_cut_to_what_fits():
    panel = text_panel(["a long line of help text that does not fit"] * 40, 120, 50)
    assert panel.shape[:2] == (50, 120)
    assert text_panel(["x"], 8, 8) is None and text_panel([], 100, 100) is None
