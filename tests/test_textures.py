"""renderer/core/textures.py and gltf_texture.py: the texture data both pipelines read. Each
rule by a hand-checked case: the sRGB decode, the mip chain (area average from level 0,
rounded once), the checkerboard, image files (alpha ignored, bad files one line), and a
glTF's base-colour texture with its v direction."""

import json
import struct

import numpy as np
import pytest
import trimesh
from PIL import Image

from renderer.core.builtin import assets_dir
from renderer.core.gl_rules import to_unorm8
from renderer.core.gltf_texture import base_colour_texture
from renderer.core.meshio import load_mesh
from renderer.core.textures import (Sampler, Texture, checkerboard, level_sizes, load_texture,
                                    mip_chain, srgb_to_linear)
from renderer.errors import SceneError


def grey(values) -> np.ndarray:
    """An (H, W, 4) float64 level 0 with `values` (H, W) in every colour channel, alpha 1."""
    v = np.asarray(values, dtype=np.float64)
    return np.stack([v, v, v, np.ones_like(v)], axis=-1)


# --------------------------------------------------------------------------- sRGB

def test_srgb_decode_of_known_values():
    """IEC 61966-2-1: linear below 0.04045 (c / 12.92), the 2.4 power above."""
    decoded = srgb_to_linear([0.0, 0.04045, 0.5, 1.0])
    assert decoded[0] == 0.0 and decoded[3] == 1.0
    assert decoded[1] == 0.04045 / 12.92                     # 0.0031308..., the linear piece
    assert decoded[2] == pytest.approx(0.214041140482232, abs=1e-15)
    # The two pieces meet at the boundary (to the standard's 4 digits).
    assert srgb_to_linear(np.nextafter(0.04045, 1.0)) == pytest.approx(decoded[1], rel=1e-4)


# --------------------------------------------------------------------------- mip chain

def test_level_sizes_halve_down_to_one_by_one():
    assert level_sizes(4, 4) == [(4, 4), (2, 2), (1, 1)]
    assert level_sizes(5, 3) == [(5, 3), (2, 1), (1, 1)]
    assert level_sizes(1, 1) == [(1, 1)]


def test_mip_chain_of_a_power_of_two_image_averages_2x2_blocks():
    levels = mip_chain(grey([[0.0, 0.2, 0.4, 0.6],
                             [0.1, 0.3, 0.5, 0.7],
                             [1.0, 1.0, 0.0, 0.0],
                             [1.0, 0.5, 0.0, 0.25]]))
    assert [level.shape for level in levels] == [(4, 4, 4), (2, 2, 4), (1, 1, 4)]
    assert levels[0][..., 0].tolist() == [[0, 51, 102, 153], [26, 77, 128, 179],
                                          [255, 255, 0, 0], [255, 128, 0, 64]]
    # 0.15 -> 38.75, 0.55 -> 140.75, 0.875 -> 223.6, 0.0625 -> 16.4: floor(255 x + 1/2)
    assert levels[1][..., 0].tolist() == [[38, 140], [223, 16]]
    assert levels[2][..., 0].tolist() == [[104]]                  # 6.55 / 16 = 0.409375
    assert all((level[..., 3] == 255).all() for level in levels)
    assert all(level.dtype == np.uint8 for level in levels)


def test_mip_chain_of_an_npot_image_weights_partly_covered_texels():
    """5 x 3: level 1 is 2 x 1, its texels 2.5 texels of level 0 wide, so the middle column
    counts half in each; rows: all three. Level 0's top rows [0, .5, 1, .25, .75], bottom 0."""
    row = [0.0, 0.5, 1.0, 0.25, 0.75]
    levels = mip_chain(grey([row, row, [0.0] * 5]))
    assert [level.shape[:2] for level in levels] == [(3, 5), (1, 2), (1, 1)]
    # (0 + .5 + .5 x 1) / 2.5 = 0.4, then x 2/3 for the rows: 0.2667 -> 68; (.5 + .25 + .75)
    # / 2.5 = 0.6, x 2/3 = 0.4 -> 102.5 -> 102; all: 2.5 / 5 x 2/3 = 1/3 -> 85.
    assert levels[1][..., 0].tolist() == [[68, 102]]
    assert levels[2][..., 0].tolist() == [[85]]


def box_weights(n: int, size: int) -> np.ndarray:
    """(size, n): how much of texel x lies in cell i of width n / size, over the width."""
    edges = np.arange(size + 1) * n / size
    low, high = np.maximum.outer(edges[:-1], np.arange(n)), np.minimum.outer(edges[1:], np.arange(n) + 1)
    return np.clip(high - low, 0, None) / (n / size)


@pytest.mark.parametrize("height, width", [(5, 7), (3, 6), (1, 13), (8, 4)])
def test_mip_chain_is_the_box_filter_written_as_weight_matrices(height, width):
    level0 = np.random.default_rng(width).random((height, width, 4))
    for (w_k, h_k), level in zip(level_sizes(width, height), mip_chain(level0)):
        expected = np.einsum("iy,yxc,jx->ijc", box_weights(height, h_k), level0, box_weights(width, w_k))
        assert level.tolist() == to_unorm8(expected).tolist()


def test_a_region_of_one_value_keeps_it_at_every_level():
    """0.5 is the one tie of unorm8 rounding float64 holds exactly (127.5 + 0.5 = 128): the
    averages must not drift below it, at NPOT sizes neither."""
    levels = mip_chain(grey(np.full((3, 7), 0.5)))
    assert [np.unique(level[..., 0]).tolist() for level in levels] == [[128], [128], [128]]


def test_each_level_is_rounded_once_from_level_0():
    """Three texels of 0.6/255 and one of 0: level 0 rounds them to 1, 1, 1, 0; level 1 is
    the mean of the float values, 0.45/255 -> 0, not the mean of the rounded ones (0.75/255
    -> 1, what a chain made from rounded levels would store)."""
    a = 0.6 / 255
    levels = mip_chain(grey([[a, a], [a, 0.0]]))
    assert levels[0][..., 0].tolist() == [[1, 1], [1, 0]]
    assert levels[1][..., 0].tolist() == [[0]]


# --------------------------------------------------------------------------- checkerboard

def test_checkerboard_starts_with_the_first_colour_at_the_origin():
    """2 x 2 squares at 4 texels: the bottom-left texel (u = v = 0, array row 3) is colors[0];
    the rows of the array run from the top."""
    texture = checkerboard(2, ((1.0, 0.0, 0.0), (0.0, 0.0, 1.0)), 4)
    red, blue = [255, 0, 0, 255], [0, 0, 255, 255]
    assert texture.levels[0].tolist() == [[blue, blue, red, red], [blue, blue, red, red],
                                          [red, red, blue, blue], [red, red, blue, blue]]
    assert texture.levels[1].tolist() == [[blue, red], [red, blue]]
    assert texture.levels[2].tolist() == [[[128, 0, 128, 255]]]
    assert (texture.source, texture.colorspace) == ("checker 2x2 at 4", "linear")


def test_checkerboard_squares_need_not_divide_the_resolution():
    texture = checkerboard(3, ((0.0,) * 3, (1.0,) * 3), 4)      # texel i in square i*3 // 4
    assert texture.levels[0][3, :, 0].tolist() == [0, 0, 255, 0]          # squares 0, 0, 1, 2


# --------------------------------------------------------------------------- sampler, texture

def test_sampler_rules():
    assert Sampler().mipmapped and not Sampler(filter="bilinear").mipmapped
    assert Sampler(filter="anisotropic", anisotropy=8).mipmapped
    for bad in (dict(wrap="clamp_to_border"), dict(filter="linear"), dict(filter="anisotropic"),
                dict(filter="anisotropic", anisotropy=17), dict(anisotropy=4)):
        with pytest.raises(ValueError):
            Sampler(**bad)


def test_textures_compare_by_identity():
    """Each Texture object is uploaded once: equal arrays are still two textures."""
    a, b = (checkerboard(2, ((0,) * 3, (1,) * 3), 2) for _ in range(2))
    assert a != b and a == a and len({a, b}) == 2 and isinstance(a, Texture)


# --------------------------------------------------------------------------- image files

def test_an_srgb_png_is_decoded_and_its_alpha_ignored(tmp_path):
    pixels = np.array([[[0, 128, 255, 0], [255, 255, 255, 7]]], dtype=np.uint8)
    Image.fromarray(pixels, "RGBA").save(tmp_path / "a.png")
    texture = load_texture(tmp_path / "a.png")
    # 128 / 255 = 0.50196 decodes to 0.21586: 55.05 + 0.5 -> 55
    assert texture.levels[0].tolist() == [[[0, 55, 255, 255], [255, 255, 255, 255]]]
    assert load_texture(tmp_path / "a.png", "linear").levels[0][0, 0].tolist() == [0, 128, 255, 255]
    assert texture.source == str(tmp_path / "a.png") and texture.colorspace == "srgb"


def test_greyscale_images_are_read_to_rgb(tmp_path):
    Image.fromarray(np.array([[0, 255]], dtype=np.uint8), "L").save(tmp_path / "l.png")
    Image.fromarray(np.array([[0, 65535]], dtype=np.uint16)).save(tmp_path / "i16.png")
    for name in ("l.png", "i16.png"):
        assert load_texture(tmp_path / name).levels[0].tolist() == [[[0, 0, 0, 255], [255] * 4]]


@pytest.mark.parametrize("name, content, reason", [
    ("missing.png", None, "image file not found"),
    ("empty.png", b"", "image is empty (0 bytes)"),
    ("text.png", b"not an image\n", "could not be read as an image: not a format Pillow knows"),
    ("cut.png", "TRUNCATED", "is truncated: its image data holds "),
])
def test_a_bad_image_is_one_line_naming_scene_key_and_file(tmp_path, name, content, reason):
    path = tmp_path / name
    if content == "TRUNCATED":
        noise = np.random.default_rng(0).integers(0, 256, (64, 64, 3), dtype=np.uint8)
        Image.fromarray(noise).save(path)
        path.write_bytes(path.read_bytes()[:200])
    elif content is not None:
        path.write_bytes(content)
    with pytest.raises(SceneError) as info:
        load_texture(path, source="s.toml", key="materials.m.texture.image")
    assert info.value.line().startswith(f"s.toml: materials.m.texture.image: {path}: {reason}")
    assert len(info.value.line().splitlines()) == 1


# --------------------------------------------------------------------------- glTF

CORNERS = np.array([[[255, 0, 0], [0, 255, 0]],          # top row: red, green
                    [[0, 0, 255], [255, 255, 0]]],        # bottom row: blue, yellow
                   dtype=np.uint8)


def quad_glb(tmp_path, factor=(255, 255, 255, 255), sampler=None):
    """A unit quad facing +z, UVs (0, 0) at its bottom-left corner to (1, 1) at its top
    right (our convention, v up), the 2 x 2 CORNERS image as its base colour, written by
    trimesh's exporter (which writes glTF's v = 1 - ours); `sampler` patched into its JSON."""
    material = trimesh.visual.material.PBRMaterial(
        baseColorTexture=Image.fromarray(CORNERS, "RGB"), baseColorFactor=list(factor))
    uv = np.array([[0.0, 0.0], [1.0, 0.0], [1.0, 1.0], [0.0, 1.0]])
    quad = trimesh.Trimesh([[0, 0, 0], [1, 0, 0], [1, 1, 0], [0, 1, 0]], [[0, 1, 2], [0, 2, 3]],
                           process=False, visual=trimesh.visual.TextureVisuals(uv=uv, material=material))
    data = trimesh.Scene(quad).export(file_type="glb")
    if sampler is not None:
        header, binary = glb_chunks(data)
        header["samplers"] = [sampler]
        header["textures"][0]["sampler"] = 0
        text = json.dumps(header).encode()
        text += b" " * (-len(text) % 4)
        data = (struct.pack("<4sII", b"glTF", 2, 12 + 8 + len(text) + 8 + len(binary))
                + struct.pack("<II", len(text), 0x4E4F534A) + text
                + struct.pack("<II", len(binary), 0x004E4942) + binary)
    path = tmp_path / "quad.glb"
    path.write_bytes(data)
    return path


def glb_chunks(data: bytes):
    length, _ = struct.unpack_from("<II", data, 12)
    header = json.loads(data[20:20 + length])
    binary_length, _ = struct.unpack_from("<II", data, 20 + length)
    return header, data[28 + length:28 + length + binary_length]


def test_gltf_v_points_down_the_image_and_loads_as_ours(tmp_path):
    """The file holds glTF's v (0 at the image's top row): the quad's top-left corner has
    TEXCOORD_0 (0, 0). trimesh turns it into ours (v = 1 - v_gltf, checked here, not
    assumed): (0, 1), where the texture's top-left texel, red, lies."""
    path = quad_glb(tmp_path)
    header, binary = glb_chunks(path.read_bytes())
    accessor = header["accessors"][header["meshes"][0]["primitives"][0]["attributes"]["TEXCOORD_0"]]
    view = header["bufferViews"][accessor["bufferView"]]
    stored = np.frombuffer(binary, np.float32, 8, view.get("byteOffset", 0) + accessor.get("byteOffset", 0))
    assert stored.reshape(4, 2)[3].tolist() == [0.0, 0.0]               # top-left, glTF's v
    mesh = load_mesh(path)
    top_left = np.flatnonzero((mesh.positions == [0, 1, 0]).all(axis=1))
    assert mesh.uvs[top_left].tolist() == [[0.0, 1.0]]
    texture = base_colour_texture(path)
    assert texture.texture.levels[0][0, 0].tolist() == [255, 0, 0, 255]     # image row 0: red
    assert texture.texture.levels[0][1, 0].tolist() == [0, 0, 255, 255]     # v = 0: blue
    assert texture.sampler == Sampler("repeat", "trilinear")


def test_gltf_base_colour_factor_multiplies_linear_texels_and_wrap_comes_from_the_sampler(tmp_path):
    path = quad_glb(tmp_path, factor=(128, 255, 255, 255), sampler={"wrapS": 33071, "wrapT": 33071})
    texture = base_colour_texture(path)
    # trimesh writes the factor from bytes: 128/255; red 1.0 x 128/255 -> 128
    assert texture.texture.levels[0][0, 0].tolist() == [128, 0, 0, 255]
    assert texture.sampler.wrap == "clamp"


def test_gltf_wraps_that_differ_are_one_line(tmp_path):
    path = quad_glb(tmp_path, sampler={"wrapS": 33071, "wrapT": 10497})
    with pytest.raises(SceneError) as info:
        base_colour_texture(path, source="s.toml", key="objects[0].mesh.file")
    assert info.value.line() == (f"s.toml: objects[0].mesh.file: {path}: material 0's base-colour "
                                 f"sampler has wrapS 33071 and wrapT 10497; a material has one "
                                 f"wrap mode")


def test_a_gltf_without_a_base_colour_texture_has_none(tmp_path):
    path = tmp_path / "box.glb"
    path.write_bytes(trimesh.Scene(trimesh.creation.box()).export(file_type="glb"))
    assert base_colour_texture(path) is None


def test_the_textured_box_asset_shows_its_label_upright():
    """assets/meshes/textured_box.glb (tools/make_texture_assets.py): the +z face's top-left
    corner has UV (0, 1), where the label's top-left corner square is red (sRGB 220, 30, 30)."""
    path = assets_dir() / "meshes" / "textured_box.glb"
    mesh = load_mesh(path)
    corner = np.flatnonzero((mesh.normals[:, 2] == 1.0) & (mesh.positions[:, 0] < 0)
                            & (mesh.positions[:, 1] > 0))
    assert mesh.uvs[corner].tolist() == [[0.0, 1.0]]
    level0 = base_colour_texture(path).texture.levels[0]
    assert level0.shape == (96, 160, 4)
    expected = to_unorm8(srgb_to_linear(np.array([220, 30, 30]) / 255))
    assert level0[0, 0, :3].tolist() == expected.tolist()
