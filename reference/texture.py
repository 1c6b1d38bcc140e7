"""# Twin: glsl/texture.glsl

The material lookup of a textured material (TEXTURED), per fragment: the texel of its texture
at the fragment's UV, whose RGB (linear) multiplies the coefficients the material names
(reference/lighting.py, MaterialUniforms.with_factors).

- The lookup is at st = uv * uv_scale + uv_offset, in float32 and in that order, the two
  operations rounded apart (`lookup_coordinates`; llvmpipe fuses neither).
- A mipmapped sampler's level of detail comes from st's differences over the fragment's 2x2
  quad, as llvmpipe takes them: st at the quad's reference pixels (reference/sampler.py,
  quad_reference), the UV interpolated there from the fragment's triangle even where that
  pixel is outside it (GL's helper invocations; reference/rasterizer.py,
  perspective_weights_at), differenced in float32 (QuadDerivatives.from_reference).
- The sampling itself is reference/sampler.py's, texel for texel llvmpipe's.
- `displace` is a check's, never the picture's: a function (sampler, st) -> st applied to st
  at the fragment and at its quad's reference pixels alike (so the derivatives follow), for
  holding GL against the twin at coordinates the texture verifier's bound allows
  (renderer/checks/texture_bounds.py). None, the default, is the lookup at st itself.

Inputs:  a renderer.core.textures.MaterialTexture (its UV transform as the uniforms
         u_uv_scale, u_uv_offset of renderer/core/uniforms.py); uv (N, 2) the fragments' interpolated UVs
         (the pipeline's dtype); for a mipmapped sampler, uv_quad (3, N, 2) the UVs at each
         fragment's quad reference pixels, in quad_reference's order.
Output:  texel (N, 3) linear RGB, float32 as the sampler returns it, in the pipeline's dtype.
"""

from __future__ import annotations

import numpy as np

from reference.sampler import QuadDerivatives, sample
from renderer.core.uniforms import texture_uniforms


def lookup_coordinates(uv: np.ndarray, u_uv_scale, u_uv_offset) -> np.ndarray:
    """st = uv * u_uv_scale + u_uv_offset (N, 2) float32: the UV in float32 as GL interpolates
    it, then one rounding for the product and one for the sum."""
    st = np.asarray(uv, dtype=np.float32) * np.asarray(u_uv_scale, dtype=np.float32)
    return st + np.asarray(u_uv_offset, dtype=np.float32)


def material_texel(material_texture, uv: np.ndarray, uv_quad: np.ndarray | None = None,
                   displace=None) -> np.ndarray:
    """The texel (N, 3) at the fragments' UVs (texture(u_texture, st).rgb), in uv's dtype;
    `uv_quad` is needed (and read) only when the sampler is mipmapped; `displace` (a check's,
    see above) moves st before the lookup."""
    uniforms = texture_uniforms(material_texture)
    sampler = material_texture.sampler

    def lookup(q):
        st = lookup_coordinates(q, **uniforms)
        return st if displace is None else displace(sampler, st)

    st = lookup(uv)
    derivatives = None
    if sampler.mipmapped:
        st_quad = np.stack([lookup(q) for q in uv_quad])
        derivatives = QuadDerivatives.from_reference(st_quad[..., 0], st_quad[..., 1])
    rgba = sample(material_texture.texture, sampler, st[:, 0], st[:, 1],
                  derivatives=derivatives)
    return np.asarray(rgba[:, :3], dtype=uv.dtype)
