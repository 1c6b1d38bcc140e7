"""The output stage's files (renderer/core/image_formats.py): N-bit codes in 8- and 16-bit
PNG by the PNG specification's linear scaling with an sBIT chunk, float32 OpenEXR and NumPy
files; every round trip exact, written through imageio's all-or-none `outputs()`."""

import io
import struct
import zlib

import numpy as np
import png
import pytest
from PIL import Image

from renderer.core.image_formats import read_exr, read_png, scale_codes, unscale_codes, write_exr, write_png
from renderer.core.imageio import outputs


def containers(bits):
    return [m for m in (8, 16) if bits <= m]


def every_code(bits, planes=4):
    """Every code of `bits` bits once, as a (H, W, planes) image (the last row padded)."""
    codes = np.arange(1 << bits, dtype=np.uint16)
    width = 64
    codes = np.resize(codes, -(-codes.size // (width * planes)) * width * planes)
    return codes.reshape(-1, width, planes)


def png_bytes(codes, bits, container):
    buffer = io.BytesIO()
    write_png(buffer, codes, bits, container)
    return buffer.getvalue()


def chunk(data, name):
    """The payload of the first chunk `name` of a PNG, or None."""
    for kind, payload in png.Reader(bytes=data).chunks():
        if kind == name:
            return payload
    return None


# -- the scaling, by hand ------------------------------------------------------------------------

def test_one_bit_codes_are_the_containers_ends():
    assert scale_codes([0, 1], 1, 8).tolist() == [0, 255]
    assert scale_codes([0, 1], 1, 16).tolist() == [0, 65535]


def test_three_bit_codes_scale_to_the_nearest_of_255_sevenths():
    # 255 k / 7 = 0, 36.43, 72.86, 109.29, 145.71, 182.14, 218.57, 255
    assert scale_codes(range(8), 3, 8).tolist() == [0, 36, 73, 109, 146, 182, 219, 255]
    assert unscale_codes([0, 36, 73, 109, 146, 182, 219, 255], 3, 8).tolist() == list(range(8))


def test_bits_that_divide_the_container_scale_by_bit_replication():
    assert scale_codes([0x5, 0xF], 4, 8).tolist() == [0x55, 0xFF]          # x 17
    assert scale_codes([0x2], 2, 8).tolist() == [0xAA]                      # x 85
    assert scale_codes([0xA3], 8, 16).tolist() == [0xA3A3]                  # x 257


def test_codes_out_of_range_are_refused():
    with pytest.raises(ValueError, match=r"\[0, 7\]"):
        scale_codes([8], 3, 8)
    with pytest.raises(ValueError, match="do not fit"):
        scale_codes([0], 9, 8)


@pytest.mark.parametrize("bits", range(1, 17))
def test_every_code_of_every_depth_comes_back(bits):
    codes = np.arange(1 << bits)
    for container in containers(bits):
        samples = scale_codes(codes, bits, container)
        assert np.array_equal(unscale_codes(samples, bits, container), codes)
        assert samples[0] == 0 and samples[-1] == (1 << container) - 1
        assert np.all(np.diff(samples.astype(np.int64)) > 0)            # distinct, in order


# -- PNG files -----------------------------------------------------------------------------------

@pytest.mark.parametrize("bits", range(1, 17))
def test_png_files_round_trip_every_code(bits):
    codes = every_code(bits)
    for container in containers(bits):
        data = png_bytes(codes, bits, container)
        back = read_png(data)
        assert back.container_bits == container and back.bits == (bits,) * 4
        assert np.array_equal(back.codes, codes)
        assert chunk(data, b"sBIT") == (bytes([bits] * 4) if bits < container else None)
        width, height, rows, info = png.Reader(bytes=data).asDirect()     # a reader honouring sBIT
        assert info["bitdepth"] == bits
        assert np.array_equal(np.vstack([np.asarray(row) for row in rows]).reshape(codes.shape), codes)


@pytest.mark.parametrize("bits", range(1, 17))
def test_pypngs_own_writer_at_n_bits_writes_the_same_bytes(bits):
    """pypng's Writer(bitdepth=N) scales by its own rule into 8 bits (N <= 8) or 16 and adds
    sBIT: the same file as ours, so the rule is the library's too."""
    top = (1 << bits) - 1                 # its writer scales in Python: about 1024 codes
    codes = np.resize(np.linspace(0, top, min(top + 1, 1024)).round().astype(np.uint16), (4, 64, 4))
    container = 8 if bits <= 8 else 16
    theirs = io.BytesIO()
    height, width, planes = codes.shape
    png.Writer(width, height, greyscale=False, alpha=True, bitdepth=bits).write(theirs, codes.reshape(height, -1).tolist())
    assert png_bytes(codes, bits, container) == theirs.getvalue()


@pytest.mark.parametrize("planes", [1, 2, 3])
def test_grey_grey_alpha_and_rgb_pngs_round_trip(planes):
    codes = every_code(5, planes)
    back = read_png(png_bytes(codes, 5, 8))
    assert back.bits == (5,) * planes and np.array_equal(back.codes, codes)


def test_other_readers_see_the_scaled_samples_row_0_at_the_top():
    codes = np.zeros((2, 3, 3), np.uint16)
    codes[0, 0] = [7, 3, 1]                                 # the top-left pixel
    with Image.open(io.BytesIO(png_bytes(codes, 3, 8))) as image:
        pixels = np.asarray(image)
    assert pixels[0, 0].tolist() == [255, 109, 36] and not pixels[1:].any()


def test_a_16_bit_png_is_big_endian_on_disk():
    data = png_bytes(np.full((1, 1, 3), 0x0102, np.uint16), 16, 16)
    assert chunk(data, b"IHDR")[8] == 16
    raw = zlib.decompress(chunk(data, b"IDAT"))
    assert raw == b"\x00" + struct.pack(">3H", 0x0102, 0x0102, 0x0102)


# -- float files -----------------------------------------------------------------------------------

SPECIAL = np.array([0.0, -0.0, 1.0, -1.5, 7.25, np.inf, -np.inf, np.nan, 1e-45, 3.4e38, 0.1, 0.5],
                   dtype=np.float32)


def float_image(channels):
    rng = np.random.default_rng(18)
    image = rng.normal(0.5, 2.0, (5, 7, channels)).astype(np.float32)
    image.reshape(-1)[:SPECIAL.size] = SPECIAL
    return image


def same_bits(a, b):
    return a.dtype == b.dtype and a.shape == b.shape and np.array_equal(a.view(np.uint32), b.view(np.uint32))


def test_floats_round_trip_bit_for_bit_in_exr_and_npy(tmp_path):
    colour, rgb, depth = float_image(4), float_image(3), float_image(1)[..., 0]
    depth[0, 0] = np.inf                                   # nothing drawn
    with outputs() as out:
        out.exr(tmp_path / "colour.exr", colour)
        out.exr(tmp_path / "rgb.exr", rgb)
        out.exr(tmp_path / "depth.exr", depth)
        out.npy(tmp_path / "colour.npy", colour)
    assert same_bits(read_exr(tmp_path / "colour.exr"), colour)
    assert same_bits(read_exr(tmp_path / "rgb.exr"), rgb)
    assert same_bits(read_exr(tmp_path / "depth.exr"), depth)
    assert same_bits(np.load(tmp_path / "colour.npy"), colour)


def test_exr_channels_are_named_and_row_0_is_the_top(tmp_path):
    import OpenEXR
    image = np.zeros((3, 2, 4), np.float32)
    image[0, 1] = [1, 2, 3, 4]
    with outputs() as out:
        out.exr(tmp_path / "c.exr", image)
        out.exr(tmp_path / "z.exr", image[..., 0])
    parts = OpenEXR.File(str(tmp_path / "c.exr"), separate_channels=True).channels()
    assert sorted(parts) == ["A", "B", "G", "R"]
    assert parts["B"].pixels[0, 1] == 3 and parts["B"].pixels.sum() == 3
    assert list(OpenEXR.File(str(tmp_path / "z.exr")).channels()) == ["Z"]


def test_png_codes_go_through_the_transaction(tmp_path):
    codes = every_code(10)
    with pytest.raises(RuntimeError), outputs() as out:
        out.png_codes(tmp_path / "a.png", codes, 10, 16)
        raise RuntimeError("a later output failed")
    assert list(tmp_path.iterdir()) == []
    with outputs() as out:
        out.png_codes(tmp_path / "a.png", codes, 10, 16)
    assert np.array_equal(read_png(tmp_path / "a.png").codes, codes)


def test_shapes_a_format_cannot_hold_are_refused():
    with pytest.raises(ValueError, match="H, W, 1"):
        write_png(io.BytesIO(), np.zeros((2, 2)), 8, 8)
    with pytest.raises(ValueError, match="OpenEXR"):
        write_exr(io.BytesIO(), np.zeros((2, 2, 2), np.float32))


@pytest.mark.parametrize("suffix", [".exr", ".npy"])
def test_the_suffix_alone_names_a_float_format(tmp_path, suffix):
    """`render -o x.exr` (the README's example, with --depth and --alpha) writes the frame's
    linear colour as float32, with no --format: the format follows -o's suffix."""
    from renderer import cli
    out = tmp_path / f"s{suffix}"
    assert cli.main(["render", "sphere", "--size", "16x12", "-q", "-o", str(out),
                     "--depth", str(tmp_path / "depth.exr"), "--alpha", str(tmp_path / "alpha.png")]) == 0
    image = read_exr(out) if suffix == ".exr" else np.load(out)
    assert image.dtype == np.float32 and image.shape == (12, 16, 3)
    assert (tmp_path / "depth.exr").exists() and (tmp_path / "alpha.png").exists()
    with_format = tmp_path / f"f{suffix}"
    assert cli.main(["render", "sphere", "--size", "16x12", "-q", "-o", str(with_format),
                     "--format", suffix[1:]]) == 0
    again = read_exr(with_format) if suffix == ".exr" else np.load(with_format)
    assert same_bits(image, again)
