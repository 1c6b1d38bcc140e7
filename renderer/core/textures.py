"""Textures as plain data: the images (every mip level) and how a material samples them.

Both pipelines read these objects: the GPU path uploads `Texture.levels` as they are
(renderer/gpu/textures.py) and the twin samples the same arrays (reference/sampler.py), so
neither makes a level of its own. Conventions (docs/conventions.md, "Texture coordinates"):

- `Texture.levels[k]` is (H_k, W_k, 4) uint8 with row 0 at the TOP, as every array we hand
  out; GL's v runs from the bottom row (v = 0) to the top row (v = 1), so GL upload flips
  the rows and texel row j (counted from the bottom) is array row H_k - 1 - j. Level k is
  max(1, W >> k) x max(1, H >> k), down to 1 x 1.
- Values are LINEAR unorm8: an sRGB image is decoded to linear light in float64
  (`srgb_to_linear`, IEC 61966-2-1), the mip chain is made from that, and each level is
  rounded to unorm8 once (gl_rules.to_unorm8). GL's filters then blend linear light, as its
  sRGB textures would, while the sampler stays on llvmpipe's exact unorm8 path.
- Alpha is ignored (255): textures colour surfaces, they do not cut them.
- The mip chain (`mip_chain`): level k's texel is the area average of level 0 over that
  texel's footprint, never glGenerateMipmap (whose filter GL leaves open).
"""

from __future__ import annotations

from dataclasses import dataclass, field
from pathlib import Path

import numpy as np

from renderer.core import gl_rules
from renderer.core.user_files import IMAGE_FILE, FileRefused, open_image, read_user_file
from renderer.errors import SceneError

WRAPS = ("repeat", "clamp", "mirror")      # GL_REPEAT, GL_CLAMP_TO_EDGE, GL_MIRRORED_REPEAT
FILTERS = ("nearest", "bilinear", "mip-nearest", "trilinear", "anisotropic")
# GL (min, mag) filters: nearest (NEAREST, NEAREST); bilinear (LINEAR, LINEAR);
# mip-nearest (LINEAR_MIPMAP_NEAREST, LINEAR); trilinear (LINEAR_MIPMAP_LINEAR, LINEAR);
# anisotropic: trilinear with GL_TEXTURE_MAX_ANISOTROPY = anisotropy. The min and mag image
# filters are always equal, so llvmpipe never switches filters within a quad.
MIPMAPPED_FILTERS = ("mip-nearest", "trilinear", "anisotropic")
COLORSPACES = ("srgb", "linear")           # what an image file's values are
MODULATED = ("ka", "kd", "ks")             # the coefficients a texel may multiply
ANISOTROPY_RANGE = (2, gl_rules.MAX_TEXTURE_MAX_ANISOTROPY)
DEFAULT_ANISOTROPY = 16                    # "anisotropic" without a degree: the most there is

# Decoding an image, at the peak (NumPy's allocations, measured with tracemalloc on 1024² and
# 2048² PNGs: 127 bytes a texel), with room for Pillow's own buffers: the decoded linear RGB
# (24), float64 RGBA level 0 (32), its running sums along the rows (32), the first level's
# half-width passes (16 each) and the uint8 levels (about 6).
TEXTURE_BYTES_PER_TEXEL = 160


@dataclass(frozen=True)
class Sampler:
    """How a texture is sampled: wrap mode (both axes), filter, anisotropy (2..16 with the
    "anisotropic" filter, 1 with any other)."""
    wrap: str = "repeat"
    filter: str = "trilinear"
    anisotropy: int = 1

    def __post_init__(self):
        if self.wrap not in WRAPS:
            raise ValueError(f"wrap must be one of {', '.join(WRAPS)}, got {self.wrap!r}")
        if self.filter not in FILTERS:
            raise ValueError(f"filter must be one of {', '.join(FILTERS)}, got {self.filter!r}")
        low, high = ANISOTROPY_RANGE
        if self.filter == "anisotropic" and not low <= self.anisotropy <= high:
            raise ValueError(f"anisotropy must be in {low}..{high}, got {self.anisotropy!r}")
        if self.filter != "anisotropic" and self.anisotropy != 1:
            raise ValueError(f"anisotropy {self.anisotropy!r} needs the anisotropic filter")

    @property
    def mipmapped(self) -> bool:
        """Whether the filter reads mip levels beyond level 0."""
        return self.filter in MIPMAPPED_FILTERS


@dataclass(frozen=True, eq=False, repr=False)
class Texture:
    """A texture's mip levels, (H_k, W_k, 4) uint8, row 0 at the top, linear values (module
    docstring). Compared by identity: each Texture object is uploaded once."""
    levels: tuple
    source: str                            # file path or "checker 8x8 at 256", for messages
    colorspace: str = "srgb"               # what the file held: "srgb" (decoded) or "linear"

    def __repr__(self) -> str:             # short: materials are printed and hashed by repr
        return (f"Texture({self.source!r}, {self.colorspace}, {self.width}x{self.height}, "
                f"{len(self.levels)} levels)")

    @property
    def width(self) -> int:
        return int(self.levels[0].shape[1])

    @property
    def height(self) -> int:
        return int(self.levels[0].shape[0])


@dataclass(frozen=True)
class MaterialTexture:
    """A material's texture: which texture, how it is sampled, where (the lookup is at
    (u su + ou, v sv + ov)), and which coefficients (`modulate`, a subset of MODULATED) its
    texel multiplies."""
    texture: Texture
    sampler: Sampler = field(default_factory=Sampler)
    uv_scale: tuple = (1.0, 1.0)
    uv_offset: tuple = (0.0, 0.0)
    modulate: tuple = ("kd",)

    def __post_init__(self):
        if not self.modulate or any(m not in MODULATED for m in self.modulate) \
                or len(set(self.modulate)) != len(self.modulate):
            raise ValueError(f"modulate must be distinct names from {', '.join(MODULATED)}, "
                             f"got {self.modulate!r}")


# --------------------------------------------------------------------------- colour

def srgb_to_linear(c):
    """IEC 61966-2-1's decode, float64: c / 12.92 up to 0.04045, else ((c + 0.055) / 1.055)^2.4."""
    c = np.asarray(c, dtype=np.float64)
    return np.where(c <= 0.04045, c / 12.92, ((np.maximum(c, 0.04045) + 0.055) / 1.055) ** 2.4)


# --------------------------------------------------------------------------- mip chain

def level_sizes(width: int, height: int) -> list[tuple[int, int]]:
    """(W_k, H_k) of every level: max(1, W >> k) x max(1, H >> k), down to 1 x 1."""
    count = max(width, height).bit_length()
    return [(max(1, width >> k), max(1, height >> k)) for k in range(count)]


def _prefix(image: np.ndarray, axis: int) -> np.ndarray:
    """The running sums of `image` along `axis`, from 0: (n + 1) entries, moved to axis 0."""
    shape = list(image.shape)
    shape[axis] += 1
    prefix = np.zeros(shape)
    np.cumsum(image, axis=axis, out=prefix[(slice(None),) * axis + (slice(1, None),)])
    return np.moveaxis(prefix, axis, 0)


def _area_average(image: np.ndarray, size: int, axis: int, prefix=None) -> np.ndarray:
    """`image` (float64) averaged along `axis` from n to `size` cells: cell i is the mean
    over [i n/size, (i+1) n/size), a texel partly inside weighted by how much of it is.
    `prefix`: _prefix(image, axis), where the caller has it already.

    With the integral F(x) of the texels up to x, cell i is size (F(b_i+1) - F(b_i)) / n at
    the boundaries b_i = i n / size = q + r / size (q, r: the quotient and remainder of
    i n by size), where size F(b_i) = size prefix[q] + r texel[q]: whole numbers times
    sums, divided by n once, so that a region of 0.5 (the one tie of unorm8 rounding that
    float64 holds exactly) stays exactly 0.5."""
    n = image.shape[axis]
    if size == n:
        return image
    moved = np.moveaxis(image, axis, 0)
    prefix = _prefix(image, axis) if prefix is None else prefix
    q, r = np.divmod(np.arange(size + 1) * n, size)
    r = r.reshape(-1, *[1] * (moved.ndim - 1)).astype(np.float64)
    scaled = prefix[q]
    scaled *= size
    scaled += r * moved[np.minimum(q, n - 1)]
    average = np.diff(scaled, axis=0)
    average /= n
    return np.moveaxis(average, 0, axis)


def mip_chain(level0: np.ndarray) -> tuple:
    """Every level of a linear float64 image (H, W, 4), row 0 at the top, as uint8 (round
    half up, gl_rules.to_unorm8, once per level from float64).

    Level k's texel is the area average of level 0 over the texel's footprint: a separable
    box W/W_k wide (and H/H_k high), with fractional weights at its ends where the sizes are
    not powers of two. Averaging always from level 0 (not level k - 1) keeps NPOT levels true
    box filters and rounds each level once."""
    level0 = np.asarray(level0, dtype=np.float64)
    height, width = level0.shape[:2]
    along_rows = _prefix(level0, axis=1) if width > 1 else None     # shared by every level
    levels = []
    for w_k, h_k in level_sizes(width, height):
        across = _area_average(level0, w_k, axis=1, prefix=along_rows)
        levels.append(gl_rules.to_unorm8(_area_average(across, h_k, axis=0)))
    return tuple(levels)


def resampled(texture: Texture, width: int, height: int) -> Texture:
    """`texture` at width x height texels, with its own mip chain: level 0 resampled by the
    mip chain's area rule, up or down (each new texel the average, over its footprint, of the
    old texels taken as squares of constant colour: a whole-number enlargement repeats each
    texel, so a checkerboard stays the same checkerboard), in float64 from the stored unorm8
    values. The report's texture resolutions and its ground truth (renderer/study/texture_report.py)."""
    level0 = np.asarray(texture.levels[0], dtype=np.float64) / 255.0
    image = _area_average(_area_average(level0, width, axis=1), height, axis=0)
    return Texture(mip_chain(image), f"{texture.source} at {width}x{height}", texture.colorspace)


# --------------------------------------------------------------------------- sources

def texture_from_image(rgb: np.ndarray, source: str, colorspace: str = "srgb",
                       tint=(1.0, 1.0, 1.0)) -> Texture:
    """A Texture from float RGB (H, W, 3) in [0, 1], row 0 at the top, decoded by
    `colorspace` ("srgb": srgb_to_linear; "linear": as it is), then multiplied by the linear
    `tint` (glTF's baseColorFactor); alpha 1."""
    if colorspace not in COLORSPACES:
        raise ValueError(f"colorspace must be one of {', '.join(COLORSPACES)}, got {colorspace!r}")
    rgb = np.clip(np.asarray(rgb, dtype=np.float64), 0.0, 1.0)
    return texture_from_linear(srgb_to_linear(rgb) if colorspace == "srgb" else rgb, source,
                               colorspace, tint)


def texture_from_linear(linear: np.ndarray, source: str, colorspace: str,
                        tint=(1.0, 1.0, 1.0)) -> Texture:
    """A Texture from linear RGB (H, W, 3) float64, times `tint`; alpha 1. `colorspace`
    records what the source held."""
    rgba = np.ones((*linear.shape[:2], 4))
    np.multiply(linear, np.asarray(tint, dtype=np.float64), out=rgba[..., :3])
    return Texture(mip_chain(rgba), source, colorspace)


def checkerboard(squares: int, colors, resolution: int) -> Texture:
    """A `resolution`² texture of squares x squares checks, colours (RGB, linear) alternating
    from colors[0] at the texture's origin (u = v = 0: the bottom-left texel). Texel (i, j),
    j from the bottom, is in square (i squares // resolution, j squares // resolution)."""
    if not 1 <= squares <= resolution:
        raise ValueError(f"squares must be in 1..resolution ({resolution}), got {squares}")
    index = np.arange(resolution) * squares // resolution
    parity = (index[::-1, None] + index[None, :]) % 2           # row 0 is the top: j = R-1-row
    palette = np.asarray(colors, dtype=np.float64).reshape(2, 3)
    return texture_from_image(palette[parity], f"checker {squares}x{squares} at {resolution}",
                              "linear")


def load_texture(path, colorspace: str = "srgb", *, source: str | None = None,
                 key: str | None = None) -> Texture:
    """An image file (PNG or JPEG, through Pillow) as a Texture, or a one-line SceneError
    naming `source` (the scene file, if any), `key` and the image's path: missing, empty,
    not an image, truncated, too large for GL or for memory.

    8-bit images are read as c / 255 per channel (greyscale and palettes expanded to RGB);
    16-bit greyscale as c / 65535; alpha is dropped."""
    path = Path(path)
    try:
        data = read_user_file(path, IMAGE_FILE)
    except FileRefused as refused:
        _image_problem(refused.reason, path, source, key)
    return texture_from_bytes(data, str(path), colorspace, source=source, key=key)


def texture_from_bytes(data: bytes, name: str, colorspace: str = "srgb", *, tint=(1.0, 1.0, 1.0),
                       source: str | None = None, key: str | None = None) -> Texture:
    """An encoded image (PNG or JPEG bytes) as a Texture named `name`, with load_texture's
    checks and errors (`name` stands for the file in them)."""
    from PIL import Image

    if len(data) == 0:
        _image_problem("image is empty (0 bytes)", name, source, key)
    try:
        # the header's size checked (a side, the memory limit) before anything is decoded;
        # Pillow's own bomb check, which refuses sides a texture may have, is replaced
        with open_image(data, max_side=gl_rules.GL_MIN_MAX_TEXTURE_SIZE,
                        bytes_per_pixel=TEXTURE_BYTES_PER_TEXEL, what="texture",
                        side="texels on a side (GL_MAX_TEXTURE_SIZE)") as image:
            image.load()
            codes, largest_code = _codes(image)
    except FileRefused as refused:
        _image_problem(refused.reason, name, source, key)
    except (OSError, SyntaxError, ValueError, EOFError, Image.DecompressionBombError) as exc:
        reason = str(exc).strip().splitlines()[0] if str(exc).strip() else type(exc).__name__
        _image_problem(f"could not be read as an image (PNG or JPEG): {reason}", name, source, key)
    # Decoded through a table of every code's value (the same formula, once per code).
    values = np.arange(largest_code + 1) / largest_code
    table = srgb_to_linear(values) if colorspace == "srgb" else values
    return texture_from_linear(table[codes], name, colorspace, tint)


def _image_problem(reason: str, name, source: str | None, key: str | None):
    """The one-line SceneError: "SOURCE: KEY: NAME: reason", or "NAME: KEY: reason" alone."""
    if source is not None:
        raise SceneError(f"{name}: {reason}", file=source, key=key)
    raise SceneError(reason, file=str(name), key=key)


def _codes(image) -> tuple[np.ndarray, int]:
    """The integer RGB codes (H, W, 3) of a loaded Pillow image and the largest code (255,
    or 65535 for 16-bit greyscale), clipped to it."""
    if image.mode in ("I;16", "I;16B", "I;16L", "I"):            # 16-bit greyscale PNG
        grey = np.clip(np.asarray(image, dtype=np.int64), 0, 65535)
        return np.repeat(grey[:, :, None], 3, axis=2), 65535
    return np.asarray(image.convert("RGB")), 255
