"""`renderer colour IMAGE-or-SCENE --out DIR` (renderer/study/colour_report.py): what it reads,
what it measures, its four files written all or none, Munsell notation in words where the
renotation has none, and bad input as one line with nothing written."""

import json

import numpy as np
import pytest

from renderer.core.image_formats import write_png
from renderer.core.output_settings import Transfer
from renderer.core.quantise import decode

pytest.importorskip("colour")

FILES = ("chromaticity.png", "colour.json", "luminance.png", "munsell.md")


def png_of(path, codes, bits, container_bits):
    with open(path, "wb") as handle:
        write_png(handle, codes, bits, container_bits)
    return path


def test_a_16_bit_png_is_read_exactly_and_measured(tmp_path, cli_here):
    """Two grey codes and a transparent pixel: the luminance is the sRGB decode of each 16-bit
    code (white's Y is 1), the transparent pixel is not counted."""
    codes = np.array([[[65535] * 3 + [65535], [30000] * 3 + [65535], [0, 0, 0, 0]]], np.uint16)
    result = cli_here("colour", png_of(tmp_path / "grey.png", codes, 16, 16),
                      "--out", tmp_path / "out", "--backend", "reference")
    assert result.returncode == 0, result.stderr
    assert sorted(p.name for p in (tmp_path / "out").iterdir()) == list(FILES)
    figures = json.loads((tmp_path / "out" / "colour.json").read_text())
    assert figures["pixels"] == {"total": 3, "counted": 2, "lit": 2}
    assert figures["colorspace"] == "srgb"
    grey = decode(30000 / 65535, Transfer("srgb"))
    assert figures["luminance"]["min"] == pytest.approx(grey, abs=1e-6)
    assert figures["luminance"]["max"] == pytest.approx(1.0, abs=1e-6)
    assert figures["mean_colour"]["xy"] == pytest.approx([0.3127, 0.3290], abs=1e-6)   # grey: D65


def test_colorspace_says_whether_the_values_are_encoded_or_light(tmp_path):
    from renderer.study.colour_source import read_image
    codes = np.full((2, 2, 3), 8, np.uint16)                  # 8 of 15 at 4 bits (sBIT 4)
    image = png_of(tmp_path / "four.png", codes, 4, 8)
    linear, colorspace = read_image(image, "linear")
    assert colorspace == "linear" and (linear[..., :3] == np.float32(8 / 15)).all()
    encoded, colorspace = read_image(image)                   # an integer image: sRGB
    assert colorspace == "srgb"
    assert (encoded[..., :3] == np.float32(decode(8 / 15, Transfer("srgb")))).all()
    assert (encoded[..., 3] == 1).all()                       # no alpha: opaque
    np.save(tmp_path / "light.npy", np.full((1, 2, 4), 2.5, np.float32))
    assert read_image(tmp_path / "light.npy")[1] == "linear"  # a float image: light


def test_munsell_notation_of_greys_and_in_words_outside_the_renotation():
    from renderer.study.munsell import munsell_of
    grey = munsell_of((0.8, 0.8, 0.8))         # Y = 0.8: value 9.2 (ASTM D1535), neutral
    assert (grey.notation, grey.hue, grey.value, grey.chroma) == ("N9.2", "N", 9.2, 0.0)
    assert munsell_of((1.0, 1.0, 1.0)).notation == "N10.0"       # D65 adapted to C: neutral
    blue = munsell_of((0.0, 0.0, 1.0))        # sRGB blue: beyond any measured surface colour
    assert blue.notation is None and blue.value == pytest.approx(3.3, abs=0.05)
    assert "beyond the Munsell renotation data" in blue.note
    assert munsell_of((0.0, 0.0, 0.0)).note.startswith("black")
    assert munsell_of((2.0, 2.0, 2.0)).note.startswith("brighter than white")


@pytest.mark.slow                              # colour-science's search: 0.2 to 1 s a colour
def test_munsell_notation_of_chromatic_colours():
    from renderer.study.munsell import munsell_of
    violet = munsell_of((0.3, 0.3, 0.6))
    assert violet.hue.endswith("PB") and 6 < violet.value < 7 and violet.chroma > 5
    red = munsell_of((0.75, 0.12, 0.08))
    assert red.hue.endswith("R") and 5 < red.value < 6 and red.chroma > 10
    assert violet.note == red.note == ""
    deep = munsell_of((0.05, 0.02, 0.3))      # extrapolated past the MacAdam limits
    assert deep.hue.endswith("PB") and "MacAdam" in deep.note


@pytest.mark.slow
def test_a_scene_on_the_gpu_marks_its_materials_and_lights(tmp_path, cli_here):
    result = cli_here("colour", "classic", "--out", tmp_path, "--size", "64x48")
    assert result.returncode == 0, result.stderr
    figures = json.loads((tmp_path / "colour.json").read_text())
    assert figures["kind"] == "scene" and figures["backend"] == "gpu"
    diffuse = next(m for m in figures["materials"] if m["object"] == "diffuse")
    assert diffuse["rgb"] == [0.75, 0.12, 0.08] and diffuse["munsell"]["hue"].endswith("R")
    assert [light["light"] for light in figures["lights"]][0] == "ambient"
    assert "| diffuse |" in (tmp_path / "munsell.md").read_text()
    assert 0 < figures["pixels"]["lit"] <= figures["pixels"]["counted"] < 64 * 48


@pytest.mark.parametrize("args, line", [
    (("missing.png",), "missing.png: no such image file"),
    (("bad.png",), "bad.png: cannot read it as an image: "),
    (("no_such_scene",), "no_such_scene: no such scene file or built-in scene"),
    (("classic", "--colorspace", "srgb"), "renderer colour: --colorspace says how an image is encoded"),
])
def test_bad_input_is_one_line_and_writes_nothing(tmp_path, cli_here, args, line):
    (tmp_path / "bad.png").write_bytes(b"not a png")
    result = cli_here("colour", *args, "--out", "out", cwd=tmp_path)
    assert result.returncode == 2
    assert result.stderr.splitlines()[0].removeprefix("renderer: ").startswith(line)
    assert not (tmp_path / "out").exists()
