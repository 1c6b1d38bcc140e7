"""The texture knobs of `renderer report` (issue 17): how a textured scene's error against the
ground truth, and its frame time, move with the texture filter and the texture's resolution.

    knob                settings                                  drawn with
    filter              nearest, bilinear, mip-nearest,           the scene's textures as authored
                        trilinear, anisotropic 2, 4, 8, 16        (their wrap modes)
    texture_resolution  every texture resampled to R texels on    the scene's filters
                        its long side, R in TEXTURE_RESOLUTIONS
                        (textures.resampled: the area rule; a
                        checker stays the same checkerboard)

A setting applies to every textured material of the scene; a scene without one gets neither
knob. Both draw the scene as authored otherwise, one sample at each pixel's centre, and time a
frame: what a real-time frame costs and shows with that texture (one lookup per pixel). The
error every setting of a scene shares is that sample's aliasing at the silhouettes, and the
authored shading and tessellation against the truth's (the built-in textured scenes are Phong
shaded; of them only the globe is curved, 64 x 32 segments against the truth's 256 x 128).

The ground truth of a textured scene (`truth_textures`, applied by ground_truth.truth_scene)
is the texture integrated over each pixel:
- the texture is its texels, each a square of constant colour (what a checkerboard is):
  level 0 enlarged k times, the least whole number bringing its long side to TRUTH_TEXELS
  (a repeat of each texel, exactly the same image), so that the truth's bilinear magnification
  blurs a texel's edge over 1/k of a texel. What is left of that blur: at 2048 texels
  checker_horizon's truth at 160 x 120 moves by an RMSE of 0.0007 (at most 0.023 in a pixel
  near the camera), 1.5 % of the error of its best setting; 2048 costs 1.5 GB at the peak;
- sampled with TRUTH_FILTER (trilinear) at the truth's 16 x 16 samples per pixel, each with
  the level of detail of its own 1/16-pixel footprint: where a sample still spans several
  texels the mip chain's area averages integrate them, where it spans less than one the
  lookup is the texel's colour (bilinear at level 0). Trilinear rather than anisotropic:
  llvmpipe's EWA (reference/anisotropic.py) weights NEAREST texels by a Gaussian of at least
  a texel's radius, which blurs a magnified texel's edge, while the truth's sub-samples
  already resolve the anisotropic footprint that the EWA approximates;
- the lookup is the twin's (llvmpipe's 8-bit weights); its rounding, under 1/255 a lookup,
  averages over the 256 samples, and everything else (interpolation, lighting, the average)
  is float64.
"""

from __future__ import annotations

import functools
import math
from dataclasses import replace

from renderer.core.textures import Sampler, resampled

KNOBS = ("filter", "texture_resolution")
FILTER_SETTINGS = (("nearest", 1), ("bilinear", 1), ("mip-nearest", 1), ("trilinear", 1),
                   ("anisotropic", 2), ("anisotropic", 4), ("anisotropic", 8), ("anisotropic", 16))
TEXTURE_RESOLUTIONS = (64, 128, 256, 512, 1024)
TRUTH_TEXELS = 1024                # the truth's textures are at least this long (whole-number repeats)
TRUTH_FILTER = "trilinear"


def filter_name(filter_setting: tuple[str, int]) -> str:
    """'trilinear', 'anisotropic 16': a filter setting as results.csv names it."""
    name, anisotropy = filter_setting
    return f"{name} {anisotropy}" if name == "anisotropic" else name


def texture_variants(filters, resolutions) -> list[tuple[str, str, tuple]]:
    """(knob, setting, variant) of each texture setting; variant = ("texture", field, value)."""
    return ([("filter", filter_name(f), ("texture", "filter", f)) for f in filters]
            + [("texture_resolution", f"{r} texels", ("texture", "resolution", r)) for r in resolutions])


def is_textured(scene) -> bool:
    return any(obj.material.textured for obj in scene.objects)


def with_textures(scene, change):
    """`scene` with every textured material's MaterialTexture replaced by change(it)."""
    objects = [replace(obj, material=replace(obj.material, texture=change(obj.material.texture)))
               if obj.material.textured else obj for obj in scene.objects]
    return replace(scene, objects=objects)


@functools.lru_cache(maxsize=32)
def _resampled(texture, width: int, height: int):
    """textures.resampled, made once per Texture object and size (a Texture hashes by identity,
    so materials that share a texture share its resampled one, uploaded once)."""
    return texture if (width, height) == (texture.width, texture.height) else resampled(texture, width, height)


def long_side(texture, texels: int) -> tuple[int, int]:
    """(width, height) with `texels` on the texture's long side and its aspect ratio kept."""
    width, height = texture.width, texture.height
    short = max(1, round(texels * min(width, height) / max(width, height)))
    return (texels, short) if width >= height else (short, texels)


def with_texture_setting(scene, field: str, value):
    """`scene` with a texture setting on every textured material: field "filter" (value:
    (filter, anisotropy)) or "resolution" (value: texels on the long side)."""
    if field == "filter":
        name, anisotropy = value
        return with_textures(scene, lambda t: replace(t, sampler=Sampler(t.sampler.wrap, name, anisotropy)))
    if field == "resolution":
        return with_textures(scene, lambda t: replace(t, texture=_resampled(t.texture, *long_side(t.texture, value))))
    raise ValueError(f"no texture setting {field!r}")


def truth_textures(scene):
    """`scene` with every texture as the ground truth samples it (module docstring): level 0
    repeated k times (k the least whole number bringing the long side to TRUTH_TEXELS),
    TRUTH_FILTER, the authored wrap."""
    def truth(material_texture):
        texture = material_texture.texture
        k = max(1, math.ceil(TRUTH_TEXELS / max(texture.width, texture.height)))
        return replace(material_texture, texture=_resampled(texture, k * texture.width, k * texture.height),
                       sampler=Sampler(material_texture.sampler.wrap, TRUTH_FILTER))
    return with_textures(scene, truth)


# ------------------------------------------------------------------------------- report.md

def truth_bullet() -> str:
    return (f"- **A textured scene's truth** is its texture integrated over each pixel: the "
            f"texels as squares of constant colour (level 0 repeated a whole number of times to "
            f"at least {TRUTH_TEXELS} texels on its long side: the same image), sampled "
            f"{TRUTH_FILTER} at each of the 16x16 sub-samples, so that each sub-sample averages "
            "what its own footprint covers (renderer/study/texture_report.py says why this filter).")


def method_bullet() -> str:
    return ("- **filter** (nearest, bilinear, mip-nearest, trilinear, anisotropic 2 to 16) and "
            "**texture_resolution** (every texture resampled by the mip chain's area rule to R "
            "texels on its long side, the aspect kept; the scene's filter), textured scenes only: "
            "each setting on every textured material, the scene otherwise as authored, one "
            "sample at each pixel's centre (a real-time frame's one lookup per pixel), timed per "
            "frame. The error all of a scene's settings share is that sample's aliasing at "
            "silhouettes and the authored shading and tessellation's.")


def texture_line(scene) -> str:
    """The scene's textures as authored, each once: 'globe.png (512x256, trilinear, repeat)'."""
    seen = {}
    for obj in scene.objects:
        if obj.material.textured:
            t = obj.material.texture
            seen.setdefault(id(t.texture), f"{t.texture.source.split('/')[-1]} ({t.texture.width}x"
                                           f"{t.texture.height}, {t.sampler.filter}, {t.sampler.wrap})")
    return "; ".join(seen.values())
