"""The texture verifier's coordinate bound, written once, and the twin's envelope over it: what
a comparison accepts from GL's anisotropic lookups (issue 17: where GL leaves freedom, "exactly
the range ... dEQP's texture verifier allow, and nothing wider").

The twin samples as llvmpipe does, texel for texel, given the same coordinates; but GL
interpolates a fragment's UV in float32 with its own arithmetic, a few units in the last place
(ulps) from the twin's (docs/conventions.md, "Where the twins part"). Other filters turn that
into less than the threshold; llvmpipe's anisotropic EWA (reference/anisotropic.py) weighs
hundreds of texels, each in or out of its ellipse by a truncated index, and near a horizon
turns it into several levels of 255.

dEQP's verifier lets each normalised coordinate u of a lookup be anywhere in
[u - e(u), u + e(u)], subtracted and added in float32 (VK-GL-CTS c57d29f,
framework/common/tcuTexVerifierUtil.cpp: computeNonNormalizedCoordBounds, l.58-72), with
e(u) = computeFloatingPointError(u, coordBits) (l.32-42):

    e(u) = float32(2^E (1 + m 2^-23)) - 2^E = m 2^(E - 23),   m = 2^(23 - coordBits) - 1,

E being u's float32 exponent (tcuFloat.hpp l.146-149; a denormal's and zero's give
m 2^-149), and coordBits = 20 in the GLES3 texture filtering tests
(modules/gles3/functional/es3fTextureFilteringTests.cpp l.350: `lookupPrecision.coordBits =
tcu::IVec3(20, 20, 0)`). So e(u) is 7 ulps of u, 4.2e-7 to 8.3e-7 of |u|. The verifier's
other widenings (2^-uvwBits texel, the LOD bits) are not taken: the twin's addressing and
level selection are llvmpipe's own.

dEQP has no verifier for anisotropic results, so the bound is held the one way the twin can:
it renders the frame again with every anisotropic lookup's (s, t) moved within the box, to
(s + a e(s), t + b e(t)), at the fragment and at its quad's reference pixels alike (the
derivatives move with it), and a GPU pixel is held to the range of those renders and the
twin's own (compare.Envelope), widened by the pipeline threshold, with the ±1 px allowance
and the raw-mismatch limit as ever. (a, b) are the box's 4 corners and the 4 corners of the
box half its size (DISPLACEMENTS). The corners alone are not enough: near a horizon the EWA's
colour changes with single ulps of t, not monotonically. On checker_horizon at 320x240
(anisotropic 16), pixel (row 101, column 43)'s texel is 100.3/255 at the centre and 100.2 to
100.4 at the 4 corners, but runs from 99.6 to 103.8 over a 9 x 9 grid of the box; GL's pixel
is 80, the twin's 77, the corners' range 77 and this envelope's 76 to 79. Samples of the box
never widen it beyond what the verifier allows; they may miss some of it. Lookups under
other filters stay at their own coordinates, held to the twin's own image.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from renderer.checks.compare import Envelope
from renderer.core.frame import Frame
from renderer.methods import open_renderer

COORDINATE_BITS = 20                       # dEQP's coordBits for 2D filtering (see above)
# (a, b): (s, t) moved by (a e(s), b e(t)); the box's corners, then the half box's.
DISPLACEMENTS = tuple((scale * a, scale * b) for scale in (1.0, 0.5) for a in (-1, 1) for b in (-1, 1))


def coordinate_error(u) -> np.ndarray:
    """e(u) float32, dEQP's computeFloatingPointError(u, COORDINATE_BITS): (2^(23 - bits) - 1)
    units in the last place of float32(u) (the exponent at least -126, as above)."""
    bits = np.asarray(u, dtype=np.float32).view(np.int32)
    exponent = np.maximum(((bits >> 23) & 0xFF) - 127, -126)
    garbage = (1 << (23 - COORDINATE_BITS)) - 1
    return np.ldexp(np.float32(garbage), exponent - 23).astype(np.float32)


def displaced_lookup(displacement):
    """The twin's `displace_lookup` (reference/texture.py) for one displacement (a, b): an
    anisotropic sampler's st (N, 2) float32 moved to st + (a, b) * e(st), in float32 (as
    dEQP's coord ± coordErr); every other sampler's left as it is."""
    fractions = np.asarray(displacement, dtype=np.float32)

    def displace(sampler, st: np.ndarray) -> np.ndarray:
        if sampler.filter != "anisotropic":
            return st
        return (st + fractions * coordinate_error(st)).astype(np.float32)

    return displace


def has_anisotropic(scene) -> bool:
    """Whether some object's material samples its texture with the anisotropic filter."""
    return any(obj.material.texture is not None and obj.material.texture.sampler.filter == "anisotropic"
               for obj in scene.objects)


@dataclass
class AcceptedColours:
    """The colours a GPU frame is held to: `rgba8` and `tie` (the twin's alternative at depth
    and shadow ties, or None), the twin frame's own images, or for a scene with anisotropic
    lookups the Envelopes of its renders over the coordinate bound."""
    rgba8: np.ndarray | Envelope
    tie: np.ndarray | Envelope | None
    displaced_renders: int                # twin renders at displaced lookups (0: the exact compare)


def accepted_colours(scene, frame: Frame, width: int, height: int,
                     subpixel_bits: int | None = None) -> AcceptedColours:
    """What the twin accepts for `scene`, given its own `frame` (the reference rasteriser's
    at width x height with the GPU's `subpixel_bits`): that frame's colours, or where some
    material samples anisotropically, their envelope with the renders at DISPLACEMENTS."""
    if not has_anisotropic(scene):
        return AcceptedColours(frame.rgba8, frame.rgba8_tie, 0)
    twin = open_renderer(scene, (width, height), backend="reference", subpixel_bits=subpixel_bits)
    frames = [frame] + [twin.render(displace_lookup=displaced_lookup(d)) for d in DISPLACEMENTS]
    tie = None
    if any(f.rgba8_tie is not None for f in frames):
        tie = Envelope.of([f.rgba8 if f.rgba8_tie is None else f.rgba8_tie for f in frames])
    return AcceptedColours(Envelope.of([f.rgba8 for f in frames]), tie, len(DISPLACEMENTS))
