"""# Twin: fixed-function GL texture sampling (OpenGL 4.5 §8.14-8.15) as llvmpipe does it

What `texture(s, uv)` (implicit LOD) and `textureLod(s, uv, lod)` return in a fragment shader
for an RGBA8 2D texture (renderer/core/textures.py: `Texture`, `Sampler`), computed as Mesa's
llvmpipe (gallivm) computes it on this machine: docs/llvmpipe/texture-sampler.md (the
source study and "Probes on this machine"), held bit for bit in tests/test_sampler_gl.py.
Constants and the LOD's log2 rules are renderer/core/gl_rules.py's; one level's texels and
filters are reference/texels.py's, the anisotropic filter reference/anisotropic.py's.

Coordinates are GL's: u along a level's columns, v from its bottom row. Every input is taken
as float32 (denormals as 0, as llvmpipe's flush-to-zero mode takes them) and every step
rounds as llvmpipe's float32 code does.

- Level of detail (`select_levels`): one per 2x2 quad from the quad's differences
  (`QuadDerivatives`, taken at `quad_reference`'s pixels), rho^2 = max(|d/dx|^2, |d/dy|^2) in
  base-level texels, no product fused; the nearest mip filter rounds log2 rho exactly (half
  up), the linear one takes 0.5 fast_log2(rho^2) (piecewise linear, up to 0.043 low). An
  explicit lod (textureLod) is used as it is: rounded half to even, or split into floor and
  fraction. Levels clamp to [0, last]; lod <= 0 reads the base level (min and mag filters
  are equal, so there is no switch).
- Two levels blend with the weight trunc(256 f) and lerp8 on the fixed-point path (repeat,
  clamp), with one fused multiply-add on the float path (mirror); then unorm8_to_float.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from reference.anisotropic import sample_anisotropic
from reference.texels import (base_level_pots, cvt_round, cvt_trunc, fixed_level, float_lerp, float_level,
                              flush_denormals, lerp8, texel_levels)
from renderer.core.gl_rules import MIP_WEIGHT_BITS, fast_log2, round_log2_sqrt, unorm8_to_float

f32 = np.float32
MIP_ONE = 1 << MIP_WEIGHT_BITS               # the trilinear weight's fixed-point one


# --------------------------------------------------------------------------- derivatives

@dataclass(frozen=True)
class QuadDerivatives:
    """The implicit derivatives GL's LOD uses, per fragment (float32 (N,) each), in normalised
    uv per pixel along GL's window axes (x right, y up): llvmpipe's differences over the
    fragment's 2x2 quad (`quad_reference`), the same for the quad's four fragments."""
    dudx: np.ndarray
    dudy: np.ndarray
    dvdx: np.ndarray
    dvdy: np.ndarray

    @classmethod
    def from_reference(cls, u, v) -> "QuadDerivatives":
        """From u and v (3, N) at quad_reference's three pixels (origin, right, up): each
        derivative one float32 difference, as llvmpipe takes it."""
        u, v = np.asarray(u, dtype=f32), np.asarray(v, dtype=f32)
        return cls(u[1] - u[0], u[2] - u[0], v[1] - v[0], v[2] - v[0])


def quad_reference(x, y):
    """The pixel centres whose values llvmpipe differences for the LOD of the fragment at pixel
    (x, y) (GL window coordinates, row 0 at the bottom; integer pixels or their centres):
    ((x0, y0), (x1, y0), (x0, y1)), float64 arrays, for the quad of pixels 2i..2i+1 x
    2j..2j+1 that holds it: x0, y0 its bottom-left pixel's centre, x1 = x0 + 1, y1 = y0 + 1.
    The derivatives are right - origin and up - origin, whichever pixel of the quad the
    fragment is (coarse derivatives; GLSL's dFdx/dFdy are the fine ones)."""
    x0 = np.floor(np.asarray(x, dtype=np.float64) / 2) * 2 + 0.5
    y0 = np.floor(np.asarray(y, dtype=np.float64) / 2) * 2 + 0.5
    return (x0, y0), (x0 + 1.0, y0), (x0, y0 + 1.0)


# --------------------------------------------------------------------------- level of detail

def rho_squared(texture, derivatives: QuadDerivatives):
    """max(|d(s, t)/dx|^2, |d(s, t)/dy|^2) in base-level texels, float32, each product and
    sum rounded apart (lp_build_rho without rho_approx)."""
    width, height = f32(texture.width), f32(texture.height)
    dsdx, dsdy = derivatives.dudx.astype(f32) * width, derivatives.dudy.astype(f32) * width
    dtdx, dtdy = derivatives.dvdx.astype(f32) * height, derivatives.dvdy.astype(f32) * height
    along_x = dsdx * dsdx + dtdx * dtdx
    along_y = dsdy * dsdy + dtdy * dtdy
    return np.where(along_x > along_y, along_x, along_y)       # maxps: NaN gives along_y


def _split_lod(lod, last):
    """(level0, level1, fraction) from a float32 LOD for the linear mip filter: floor and
    fraction, both levels clamped to [0, last] with fraction 0 where either clamps
    (lp_build_linear_mip_levels)."""
    whole = np.floor(lod)
    fraction = (lod - whole).astype(f32)
    level0 = cvt_trunc(whole)
    below, above = level0 < 0, level0 >= last
    level0 = np.clip(level0, 0, last)
    level1 = np.where(below | above, level0, level0 + 1)
    return level0, level1, np.where(below | above, f32(0), fraction)


def select_levels(texture, sampler, *, derivatives: QuadDerivatives | None = None, lod=None):
    """(level0, level1, fraction) per fragment: the mip levels the sampler reads (int64) and
    the float32 weight of level1. Non-mipmapped samplers read level 0 only (neither argument
    matters). Mipmapped: exactly one of `derivatives` (texture()) or `lod` (textureLod)."""
    if not sampler.mipmapped:
        n = len(derivatives.dudx) if derivatives is not None else np.size(lod)
        zero = np.zeros(n, dtype=np.int64)
        return zero, zero, np.zeros(n, dtype=f32)
    if (derivatives is None) == (lod is None):
        raise ValueError("a mipmapped sampler needs exactly one of derivatives and lod")
    last = len(texture.levels) - 1
    if lod is not None:
        lod = np.atleast_1d(np.asarray(lod, dtype=f32))
        if sampler.filter == "mip-nearest":
            level = np.clip(cvt_round(lod), 0, last)
            return level, level, np.zeros(lod.shape, dtype=f32)
        return _split_lod(lod, last)
    rho2 = rho_squared(texture, derivatives)
    if sampler.filter == "mip-nearest":
        level = np.clip(round_log2_sqrt(rho2).astype(np.int64), 0, last)
        return level, level, np.zeros(rho2.shape, dtype=f32)
    return _split_lod(f32(0.5) * fast_log2(rho2), last)


# --------------------------------------------------------------------------- the lookup

def sample(texture, sampler, u, v, *, derivatives: QuadDerivatives | None = None, lod=None):
    """The texel colour (N, 4) float32 that texture() (with `derivatives`) or textureLod (with
    `lod`, a scalar or (N,)) returns at (u, v) (N,). Mipmapped samplers need exactly one of
    them; nearest and bilinear read level 0 and ignore both."""
    u = flush_denormals(np.atleast_1d(np.asarray(u, dtype=f32)).ravel())
    v = flush_denormals(np.atleast_1d(np.asarray(v, dtype=f32)).ravel())
    if derivatives is not None:
        derivatives = QuadDerivatives(*(flush_denormals(d) for d in (derivatives.dudx, derivatives.dudy,
                                                                      derivatives.dvdx, derivatives.dvdy)))
    if lod is not None:
        lod = flush_denormals(lod)
    if sampler.filter == "anisotropic":
        return sample_anisotropic(texture, sampler, u, v, derivatives=derivatives, lod=lod)
    if sampler.mipmapped:
        if lod is not None:
            lod = np.broadcast_to(np.asarray(lod, dtype=f32), u.shape)
        level0, level1, fraction = select_levels(texture, sampler, derivatives=derivatives, lod=lod)
    else:
        level0 = level1 = np.zeros(u.shape, dtype=np.int64)
        fraction = np.zeros(u.shape, dtype=f32)
    store = texel_levels(texture)
    image_filter = "nearest" if sampler.filter == "nearest" else "linear"
    blend = fraction > 0                           # the second level is read only where it counts
    pots = base_level_pots(texture)
    if sampler.wrap == "mirror":
        colour = float_level(store, level0, u, v, image_filter, pots, sampler.wrap)
        if blend.any():
            upper = float_level(store, level1[blend], u[blend], v[blend], image_filter, pots, sampler.wrap)
            colour[blend] = float_lerp(fraction[blend, None], colour[blend], upper)
        return colour
    repeat = sampler.wrap == "repeat"
    colour = fixed_level(store, level0, u, v, image_filter, pots, repeat)
    if blend.any():
        weight = cvt_trunc((fraction[blend] * f32(MIP_ONE)).astype(f32))[:, None]
        upper = fixed_level(store, level1[blend], u[blend], v[blend], image_filter, pots, repeat)
        colour[blend] = lerp8(weight, colour[blend], upper)
    return unorm8_to_float(colour)
