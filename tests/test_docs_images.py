"""Every picture in the docs is one the current code made: each PNG in docs/images/ has a
maker, a script in tools/ (MAKERS), and making it again now, into a temporary folder (never
over docs/images/), gives the committed picture: the same size and the same pixels within
TOLERANCE. A new picture without a maker fails test_every_picture_has_a_maker; a change to
the renderer that changes a picture fails its test until the picture is made again with the
command its maker's docstring gives (and the page's words about it still hold)."""

import importlib
import io
import sys
from pathlib import Path

import numpy as np
import pytest

ROOT = Path(__file__).resolve().parents[1]
IMAGES = ROOT / "docs" / "images"
TOOLS = ROOT / "tools"

# Each picture in docs/images/ -> the script in tools/ that makes it (its module docstring
# says what the picture is and how to run it).
MAKERS = {
    "output-methods.png": "make_output_figure",
    "pathtrace-vs-radiosity.png": "make_pathtrace_figure",
    "texture-filters.png": "make_texture_figure",
    "classic-raytrace.png": "make_docs_images",
    "distributed-soft_shadows.png": "make_docs_images",
    "distributed-depth_of_field.png": "make_docs_images",
    "distributed-motion_blur.png": "make_docs_images",
    "distributed-glossy.png": "make_docs_images",
    "shadow-scenes.png": "make_docs_images",
    "gallery.png": "make_docs_images",
}
GALLERY_MAX_BYTES = 300_000      # the README's gallery: a page's picture, not a download

# Made again, a picture may differ from the committed one by at most LEVELS / 255 per channel
# in all but SHARE of its pixels. On the machine that made it the pictures come out equal
# (llvmpipe and the NumPy reference are deterministic: measured 0 differing pixels), but
# llvmpipe's code depends on the CPU's vector width and the LLVM and Mesa versions, so that
# on another machine a float may round the other way: a colour one code value off, and the
# odd pixel whose decision sits on a tie (a shadow-map lookup, a 1-bit dither threshold, a
# sample meeting an edge) goes the other way entirely. 0.1 % allows a few hundred such pixels
# in a large picture, fewer than any real change to what a page shows.
LEVELS = 2
SHARE = 0.001


def tool(name: str):
    """The tools/ script `name`, imported with tools/ first on sys.path, as running it puts
    it (its `from contact_sheet import ...`)."""
    sys.path.insert(0, str(TOOLS))
    try:
        return importlib.import_module(name)
    finally:
        sys.path.remove(str(TOOLS))


def make(image: str, folder: Path) -> Path:
    """Make `image` with its maker into `folder`, as its command line does; the file's path."""
    script = MAKERS[image]
    if script == "make_docs_images":
        tool(script).main([image, "--folder", str(folder)])
    else:
        tool(script).main(["--out", str(folder / image)])
    return folder / image


def pixels(path_or_bytes) -> np.ndarray:
    from PIL import Image
    source = io.BytesIO(path_or_bytes) if isinstance(path_or_bytes, bytes) else path_or_bytes
    with Image.open(source) as image:
        return np.asarray(image.convert("RGB")).astype(np.int16)


def differences(made: np.ndarray, committed: np.ndarray) -> str | None:
    """None when `made` is `committed` within TOLERANCE (LEVELS, SHARE), else what differs."""
    if made.shape != committed.shape:
        return f"size {made.shape[1]}x{made.shape[0]}, committed {committed.shape[1]}x{committed.shape[0]}"
    off = np.abs(made - committed).max(axis=-1)
    beyond = int((off > LEVELS).sum())
    if beyond > SHARE * off.size:
        return (f"{beyond:,} of {off.size:,} pixels ({beyond / off.size:.3%}) differ by more than "
                f"{LEVELS}/255, at most {int(off.max())}/255")
    return None


def test_every_picture_has_a_maker():
    pictures = sorted(path.name for path in IMAGES.glob("*.png"))
    assert [name for name in pictures if name not in MAKERS] == [], \
        "a picture in docs/images/ with no maker: add a script in tools/ and name it in MAKERS"
    assert [name for name in MAKERS if name not in pictures] == []


def test_every_maker_is_a_script_in_tools():
    for script in set(MAKERS.values()):
        assert (TOOLS / f"{script}.py").is_file(), script
        assert tool(script).__doc__, f"tools/{script}.py says what it makes in its docstring"
    assert sorted(tool("make_docs_images").IMAGES) == sorted(
        name for name, script in MAKERS.items() if script == "make_docs_images")


def test_the_gallery_is_small():
    assert (IMAGES / "gallery.png").stat().st_size < GALLERY_MAX_BYTES


def test_the_check_sees_a_changed_picture():
    committed = pixels(IMAGES / "classic-raytrace.png")
    assert differences(committed.copy(), committed) is None
    assert differences(np.clip(committed + LEVELS, 0, 255), committed) is None
    changed = committed.copy()
    changed[:2] = 255 - changed[:2]                         # two rows of 640: 0.42 %
    assert f"differ by more than {LEVELS}/255" in differences(changed, committed)
    assert differences(committed[:, :-1], committed).startswith("size 639x480")


@pytest.mark.slow
@pytest.mark.parametrize("image", sorted(MAKERS))
def test_the_picture_is_what_its_maker_makes_now(image, tmp_path):
    made = make(image, tmp_path)
    problem = differences(pixels(made), pixels(IMAGES / image))
    assert problem is None, (f"docs/images/{image} is not what tools/{MAKERS[image]}.py makes now: "
                             f"{problem}; make it again (the script's docstring) and check its page")
