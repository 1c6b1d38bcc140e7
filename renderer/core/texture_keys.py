"""A scene file's material `texture` table (docs/scene-format.md, "Textures") read into a
`MaterialTexture`, every mistake one SceneError line through the scene reader's `fail`:

    texture = { image = "textures/globe.png", colorspace = "srgb", wrap = "repeat",
                filter = "trilinear", anisotropy = 8, uv_scale = [1, 1], uv_offset = [0, 0],
                modulate = ["kd"] }
    texture = { checker = { squares = 8, colors = [[0.9, 0.9, 0.9], [0.1, 0.1, 0.1]],
                            resolution = 256 } }

The reader (renderer/core/scene_file.py `_Reader`) supplies the checks of values (`table`,
`choice`, `integer`, `numbers`, `colour`, `describe`, `fail`) and finds image files as it finds
mesh files (`find_file`: the scene's folder, then the built-in assets). A texture is made
once per scene for each image and colorspace, and each checker, so that materials sharing
it share one Texture (one upload).
"""

from __future__ import annotations

from typing import Any

from renderer.core import gl_rules, memory
from renderer.core.textures import (ANISOTROPY_RANGE, COLORSPACES, DEFAULT_ANISOTROPY, FILTERS,
                                    MODULATED, TEXTURE_BYTES_PER_TEXEL, WRAPS, MaterialTexture,
                                    Sampler, Texture, checkerboard, load_texture)

TEXTURE_KEYS = ("image", "checker", "colorspace", "wrap", "filter", "anisotropy", "uv_scale",
                "uv_offset", "modulate")
CHECKER_KEYS = ("squares", "colors", "resolution")
CHECKER_DEFAULTS = {"squares": 8, "colors": ((0.9, 0.9, 0.9), (0.1, 0.1, 0.1)), "resolution": 256}


def read_texture(reader, raw: Any, path: str, cache: dict) -> MaterialTexture:
    """The MaterialTexture of `raw` at key `path`; `cache` holds the scene's textures."""
    raw = reader.table(raw, path, TEXTURE_KEYS)
    key = lambda k: f"{path}.{k}"   # noqa: E731
    if ("image" in raw) == ("checker" in raw):
        reader.fail(path, "give either image = \"FILE\" or checker = { ... }, not both"
                    if "image" in raw else "needs image = \"FILE\" or checker = { ... }")
    if "image" in raw:
        colorspace = "srgb"
        if "colorspace" in raw:
            colorspace = reader.choice(raw["colorspace"], key("colorspace"), "colorspace",
                                       COLORSPACES)
        texture = _image(reader, raw["image"], key("image"), colorspace, cache)
    else:
        if "colorspace" in raw:
            reader.fail(key("colorspace"), "is for images; a checker's colors are linear RGB")
        texture = _checker(reader, raw["checker"], key("checker"), cache)
    return MaterialTexture(texture, _sampler(reader, raw, path),
                           reader.numbers(raw.get("uv_scale", (1.0, 1.0)), key("uv_scale"), 2),
                           reader.numbers(raw.get("uv_offset", (0.0, 0.0)), key("uv_offset"), 2),
                           _modulate(reader, raw.get("modulate", ["kd"]), key("modulate")))


def read_image(reader, value: Any, path: str, colorspace: str, cache: dict) -> Texture:
    """The Texture of the image file `value` names at key `path`, read once per scene."""
    return _image(reader, value, path, colorspace, cache)


def _image(reader, value: Any, path: str, colorspace: str, cache: dict) -> Texture:
    file = reader.find_file(value, path, "image")
    cache_key = ("image", str(file.resolve()), colorspace)
    if cache_key not in cache:
        cache[cache_key] = load_texture(file, colorspace, source=reader.source, key=path)
    return cache[cache_key]


def _checker(reader, raw: Any, path: str, cache: dict) -> Texture:
    raw = reader.table(raw, path, CHECKER_KEYS)
    key = lambda k: f"{path}.{k}"   # noqa: E731
    largest = gl_rules.GL_MIN_MAX_TEXTURE_SIZE
    resolution = CHECKER_DEFAULTS["resolution"]
    if "resolution" in raw:
        resolution = reader.integer(raw["resolution"], key("resolution"), 1, largest)
    too_much = memory.over_limit(resolution * resolution * TEXTURE_BYTES_PER_TEXEL, loading=True)
    if too_much:
        reader.fail(key("resolution"), f"a {resolution} x {resolution} texture {too_much}")
    squares = CHECKER_DEFAULTS["squares"]
    if "squares" in raw:
        squares = reader.integer(raw["squares"], key("squares"), 1, resolution)
    elif squares > resolution:
        reader.fail(key("resolution"), f"must be at least squares ({squares}), got {resolution}")
    colors = CHECKER_DEFAULTS["colors"]
    if "colors" in raw:
        value = raw["colors"]
        if not isinstance(value, (list, tuple)) or len(value) != 2:
            reader.fail(key("colors"), f"expected a list of 2 colours [[r, g, b], [r, g, b]], "
                                       f"got {reader.describe(value)}")
        colors = tuple(reader.colour(c, f"{key('colors')}[{i}]") for i, c in enumerate(value))
        for i, colour in enumerate(colors):
            if max(colour) > 1.0:
                reader.fail(f"{key('colors')}[{i}]", f"must be <= 1 in every component (a "
                                                     f"texel holds 0..1), got {list(colour)}")
    cache_key = ("checker", squares, colors, resolution)
    if cache_key not in cache:
        cache[cache_key] = checkerboard(squares, colors, resolution)
    return cache[cache_key]


def _sampler(reader, raw: dict, path: str) -> Sampler:
    key = lambda k: f"{path}.{k}"   # noqa: E731
    wrap = reader.choice(raw["wrap"], key("wrap"), "wrap mode", WRAPS) if "wrap" in raw \
        else Sampler.wrap
    filter_ = reader.choice(raw["filter"], key("filter"), "filter", FILTERS) if "filter" in raw \
        else Sampler.filter
    anisotropy = 1
    if filter_ == "anisotropic":
        anisotropy = DEFAULT_ANISOTROPY
        if "anisotropy" in raw:
            anisotropy = reader.integer(raw["anisotropy"], key("anisotropy"), *ANISOTROPY_RANGE)
    elif "anisotropy" in raw:
        reader.fail(key("anisotropy"), f"needs filter = \"anisotropic\" (the filter here is "
                                       f"{filter_!r})")
    return Sampler(wrap, filter_, anisotropy)


def _modulate(reader, value: Any, path: str) -> tuple:
    if not isinstance(value, (list, tuple)) or not value:
        reader.fail(path, f"expected a list of coefficient names from {', '.join(MODULATED)}, "
                          f"such as [\"kd\"], got {reader.describe(value)}")
    names = tuple(reader.choice(name, f"{path}[{i}]", "coefficient", MODULATED)
                  for i, name in enumerate(value))
    for i, name in enumerate(names):
        if name in names[:i]:
            reader.fail(f"{path}[{i}]", f"{name!r} is named twice")
    return names
