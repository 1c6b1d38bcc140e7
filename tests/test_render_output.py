"""`renderer render` with the output stage's options (--transfer, --bits, --dither,
--halftone, --format, --alpha; docs/conventions.md, "Output"): without them the file is what
it always was, with them it is the stage's array of the frame's linear colour in the
format; every bad option is one line, status 2, nothing written."""

import re

import numpy as np
import pytest
from PIL import Image

import reference
import reference.output
from renderer.core.builtin import resolve_scene
from renderer.core.image_formats import read_exr, read_png
from renderer.core.output_settings import OutputSettings, Transfer
from renderer.core.scene_file import load_scene

SIZE = (32, 24)
ARGS = ("render", "sphere", "--size", f"{SIZE[0]}x{SIZE[1]}", "--context", "osmesa")


def pixels(path):
    with Image.open(path) as image:
        return np.asarray(image)


def reference_linear():
    frame = reference.render(load_scene(resolve_scene("sphere")), *SIZE, linear=True)
    return frame.linear


# The default run takes each backend and each background once (opaque on the GPU, transparent
# through the reference); the other two pairings are the full run's (--all).
@pytest.mark.parametrize("background, backend", [
    pytest.param(background, backend, id=f"{background}-{backend}", marks=[] if (background, backend) in (
        ("opaque", "gpu"), ("transparent", "reference")) else [pytest.mark.slow])
    for background in ("opaque", "transparent") for backend in ("gpu", "reference")])
def test_linear_8_bits_writes_the_pixels_render_always_wrote(backend, background, tmp_path, cli_here):
    """Without output options a render writes the frame's rgba8 (GL's unorm8 conversion);
    the stage at --transfer linear --bits 8 is that same conversion (renderer/core/quantise.py)."""
    plain, staged = tmp_path / "plain.png", tmp_path / "staged.png"
    common = (*ARGS, "--backend", backend, "--background", background)
    assert cli_here(*common, "-o", plain).returncode == 0
    result = cli_here(*common, "-o", staged, "--transfer", "linear", "--bits", "8")
    assert result.returncode == 0, result.stderr
    assert np.array_equal(pixels(staged), pixels(plain))
    assert pixels(plain).shape == (SIZE[1], SIZE[0], 3 if background == "opaque" else 4)


def test_the_file_holds_the_stages_codes_of_the_linear_frame(tmp_path, cli_here):
    linear = reference_linear()
    settings = OutputSettings(Transfer("srgb"), bits=12, dither="bayer4", format="png16")
    out = tmp_path / "o.png"                                  # .png with 12 bits: png16
    result = cli_here(*ARGS, "--backend", "reference", "-o", out, "--transfer", "srgb", "--bits", "12",
                      "--dither", "bayer4", "--background", "transparent")
    assert result.returncode == 0, result.stderr
    back = read_png(out)
    assert back.container_bits == 16 and back.bits == (12,) * 4
    assert np.array_equal(back.codes, reference.output.apply(linear, settings))
    assert re.fullmatch(r"wrote \S+o\.png \(32x24, reference, \d+\.\d ms; output srgb, 12 bits, "
                        r"bayer4, png16, \d+\.\d ms\)\n", result.stderr)


def test_float_formats_hold_the_encoded_colour(tmp_path, cli_here):
    linear = reference_linear()
    exr, npy = tmp_path / "o.exr", tmp_path / "o.npy"
    common = (*ARGS, "--backend", "reference", "--transfer", "gamma:2.2")
    assert cli_here(*common, "-o", exr).returncode == 0
    assert cli_here(*common, "-o", npy, "--background", "transparent").returncode == 0
    expected = reference.output.apply(linear, OutputSettings(Transfer("gamma", 2.2), format="exr"))
    assert np.array_equal(read_exr(exr), expected[..., :3])             # opaque: RGB
    assert np.array_equal(np.load(npy), expected)                       # transparent: RGBA


def test_depth_and_alpha_planes(tmp_path, cli_here):
    names = {name: tmp_path / name for name in ("o.png", "d.npy", "d.exr", "a.png", "a.npy")}
    common = (*ARGS, "--backend", "reference", "-o", names["o.png"])
    assert cli_here(*common, "--depth", names["d.npy"], "--alpha", names["a.png"]).returncode == 0
    assert cli_here(*common, "--depth", names["d.exr"], "--alpha", names["a.npy"]).returncode == 0
    frame = reference.render(load_scene(resolve_scene("sphere")), *SIZE, linear=True)
    depth = np.load(names["d.npy"])
    assert np.array_equal(read_exr(names["d.exr"]).view(np.uint32), depth.view(np.uint32))
    assert np.isinf(depth).any() and np.array_equal(depth, frame.depth)
    assert np.array_equal(read_png(names["a.png"]).codes[..., 0], frame.rgba8[..., 3])
    assert np.array_equal(np.load(names["a.npy"]), frame.linear[..., 3])


def test_the_default_name_takes_the_formats_suffix(tmp_path, cli_here):
    result = cli_here(*ARGS, "--backend", "reference", "--format", "exr", cwd=tmp_path)
    assert result.returncode == 0, result.stderr
    assert [p.relative_to(tmp_path).as_posix() for p in tmp_path.rglob("*")] == ["out", "out/sphere.exr"]


def test_the_gpu_pass_runs_on_the_renderers_own_context(tmp_path, cli_here, monkeypatch):
    """One context per render: the output pass is made on the rasteriser's."""
    from renderer.gpu import base, output
    made, passes = [], []
    make_context, output_pass = base.make_context, output.OutputPass
    monkeypatch.setattr(base, "make_context", lambda kind: made.append(make_context(kind)) or made[-1])
    monkeypatch.setattr(output, "OutputPass", lambda ctx: passes.append(ctx) or output_pass(ctx))
    result = cli_here(*ARGS, "-o", tmp_path / "o.png", "--bits", "2", "--dither", "bayer2")
    assert result.returncode == 0, result.stderr
    assert len(made) == 1 and passes == made


# -- bad input: one line naming the option, status 2, nothing written ---------------------------

DITHERS = "none, bayer2, bayer4, bayer8, blue-noise, floyd-steinberg, jarvis-judice-ninke"


@pytest.mark.parametrize("args, line", [
    (["--bits", "0"], "--bits 0: must be between 1 and 16"),
    (["--bits", "17"], "--bits 17: must be between 1 and 16"),
    (["--bits", "1.5"], "--bits 1.5: must be a whole number between 1 and 16"),
    (["--transfer", "rec709"], "--transfer rec709: unknown; one of linear, srgb, gamma:G (e.g. gamma:2.2)"),
    (["--transfer", "gamma:-2"], "--transfer gamma:-2: gamma must be a finite number above 0, got -2"),
    (["--transfer", "gamma"], "--transfer gamma: gamma:G needs a number G, got ''"),
    (["--dither", "bayer16"], f"--dither bayer16: unknown; one of {DITHERS}"),
    (["--halftone", "1.5"], "--halftone 1.5: the cell must be at least 2 pixels wide, got 1.5"),
    (["--halftone", "6:x"], "--halftone 6:x: write CELL or CELL:ANGLE, e.g. 6 or 6:15"),
    (["--format", "tiff"], "--format tiff: unknown; one of png8, png16, exr, npy"),
    (["--format", "png8", "--bits", "12"], "--bits 12 --format png8: png8 holds at most 8 bits per channel; use png16"),
    (["-o", "{D}/o.exr", "--bits", "4"],
     "--bits 4: exr holds float colour unquantised; quantise to png8 or png16"),
    (["-o", "{D}/o.npy", "--dither", "bayer8"], "--dither bayer8: npy holds float colour unquantised"),
    (["--halftone", "6", "--dither", "bayer4"], "--halftone 6 --dither bayer4: choose one"),
    (["--halftone", "6", "--bits", "2"], "--bits 2 --halftone 6: a half-tone prints binary inks (1 bit per channel)"),
    (["--halftone", "6", "--format", "exr"],
     "--halftone 6 --format exr: exr holds float colour; half-tones are png8 or png16"),
    (["-o", "{D}/o.jpg", "--transfer", "srgb"],
     "{D}/o.jpg: --transfer writes .png (png8, png16), .exr or .npy files, not .jpg; name it o.png, "
     "or leave out --transfer for an image Pillow writes"),
    (["-o", "{D}/o.png", "--format", "npy"], "{D}/o.png: --format npy writes .npy files; name it o.npy"),
    (["--format", "exr", "--background", "transparent"],
     "--format exr --background transparent: OpenEXR's alpha is premultiplied, and the frame's "
     "colour where nothing is drawn is the background's under alpha 0; write format npy "
     "(straight RGBA)"),
    (["--alpha", "{D}/a.jpg"],
     "{D}/a.jpg: --alpha writes the coverage as .png (8-bit grey) or .npy (float32); name the file e.g. alpha.png"),
    (["--depth", "{D}/d.png"],
     "{D}/d.png: --depth writes float32 depth as .npy (NumPy) or .exr (OpenEXR); name the file e.g. depth.npy"),
    (["-o", "{D}/o.png", "--alpha", "{D}/o.png"], "{D}/o.png: the same file as {D}/o.png; give each output its own name"),
])
def test_bad_output_options_are_one_line_and_write_nothing(args, line, tmp_path, cli_here, monkeypatch):
    monkeypatch.setattr(reference, "render", lambda *a, **k: pytest.fail("rendered before refusing"))
    args = [arg.replace("{D}", str(tmp_path)) for arg in args]
    result = cli_here(*ARGS, "--backend", "reference", *args, cwd=tmp_path)
    assert result.returncode == 2
    assert result.stderr.splitlines() == ["renderer: " + line.replace("{D}", str(tmp_path))]
    assert list(tmp_path.iterdir()) == []
