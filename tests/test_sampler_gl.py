"""llvmpipe's texture sampling against the twin (reference/sampler.py), bit for bit, on EGL and
OSMesa; and the upload (renderer/gpu/textures.py).

tests/glsl/sampler.frag samples a texture at per-pixel coordinates read from an RGBA32F
texture (u, v, lod), so that each 2x2 quad's differences, which llvmpipe's implicit LOD
takes, are exactly the uploaded numbers; the twin takes the same differences at
quad_reference's pixels. The output is RGBA32F: the sampler's float32 result itself.
Coordinates mix random values, texel-centre ties (u W = k/2 and one ulp either side) and the
issue's +-1e6; per-quad derivatives are random from 1/16 to 512 texels per pixel, with
rho^2 exactly at powers of two among them.
"""

import numpy as np
import pytest

from glsl_harness import ShaderProbe
from reference.sampler import QuadDerivatives, quad_reference, sample
from renderer.core.gl_rules import MAX_TEXTURE_MAX_ANISOTROPY
from renderer.core.textures import MaterialTexture, Sampler, Texture, level_sizes
from renderer.gpu.context import activate
from renderer.gpu.textures import TextureCache

f32 = np.float32
WRAPS = ("repeat", "clamp", "mirror")
FILTERS = ("nearest", "bilinear", "mip-nearest", "trilinear")


def random_texture(rng, width, height):
    levels = tuple(rng.integers(0, 256, (h, w, 4), dtype=np.uint8) for w, h in level_sizes(width, height))
    return Texture(levels, f"random {width}x{height}", "linear")


def random_inputs(rng, texture, size, *, lowest=-4, highest=9, extremes=True):
    """(size, size, 4) float32 (u, v, lod, 0), GL rows: per 2x2 quad a random centre and
    random du/dx, du/dy, dv/dx, dv/dy of 2^[lowest, highest] texels per pixel (either sign),
    each pixel off the quad's plane by a little noise; the first rows' u hit texel-centre ties
    and (with `extremes`) +-1e6; quads of the first row have rho^2 = 2^k exactly; lods random
    in [-1, 9]."""
    half = size // 2
    quad = lambda a: np.repeat(np.repeat(a, 2, axis=0), 2, axis=1)
    y, x = np.mgrid[0:size, 0:size]
    inputs = np.zeros((size, size, 4), f32)
    for axis, extent in enumerate((texture.width, texture.height)):
        slopes = [quad(rng.choice([-1, 1], (half, half)) * 2.0 ** rng.uniform(lowest, highest, (half, half)))
                  / extent for _ in range(2)]
        noise = rng.normal(0, 0.2, (size, size)) * (np.abs(slopes[0]) + np.abs(slopes[1]))
        inputs[..., axis] = quad(rng.uniform(-2, 2, (half, half))) + slopes[0] * (x % 2) + slopes[1] * (y % 2) + noise
    ties = (rng.integers(-40, 40, size) / (2 * texture.width)).astype(f32)
    inputs[2:4, :, 0] = [np.nextafter(ties, f32(-9)), np.nextafter(ties, f32(9))]
    if extremes:                       # (their quads' derivatives are ~1e6: no anisotropic filter)
        inputs[4, :size // 2, 0] = f32(1e6)
        inputs[4, size // 2:, 0] = f32(-1e6)
    powers = 2.0 ** (rng.integers(-8, 16, half) / 2)                # rho = 2^(k/2) along x
    inputs[0:2, :, 0] = quad(rng.uniform(-2, 2, (1, half)))[:2] + quad(powers[None, :] / texture.width)[:2] * (x[0:2] % 2)
    inputs[0:2, :, 1] = 0.25
    inputs[..., 2] = rng.uniform(-1, 9, (size, size))
    inputs[5, :, 2] = rng.integers(-2, 18, size) / 2                # lods at .5 ties
    return inputs


def gl_sample(ctx, cache, material, inputs, explicit):
    """What sampler.frag returns (height, width, 4) float32, GL rows."""
    height, width = inputs.shape[:2]
    activate(ctx)
    with ShaderProbe(ctx, "sampler.frag", {"EXPLICIT_LOD": explicit}, (width, height), 4, dtype="f4") as probe:
        coordinates = ctx.texture((width, height), 4, np.ascontiguousarray(inputs).tobytes(), dtype="f4")
        try:
            cache.bind(material, 0)
            coordinates.use(1)
            probe.program["u_texture"], probe.program["u_inputs"] = 0, 1
            return probe.run().copy()
        finally:
            coordinates.release()


def twin_sample(material, inputs, explicit):
    height, width = inputs.shape[:2]
    y, x = np.mgrid[0:height, 0:width]
    at = [(np.floor(py).astype(int), np.floor(px).astype(int)) for px, py in quad_reference(x.ravel(), y.ravel())]
    derivatives = QuadDerivatives.from_reference(*(np.array([inputs[j, i, axis] for j, i in at]) for axis in (0, 1)))
    lod = inputs[..., 2].ravel() if explicit else None
    return sample(material.texture, material.sampler, inputs[..., 0].ravel(), inputs[..., 1].ravel(),
                  derivatives=None if explicit else derivatives, lod=lod).reshape(height, width, 4)


def mismatches(ctx, cache, material, inputs, explicit=False):
    got = gl_sample(ctx, cache, material, inputs, explicit)
    return int((got != twin_sample(material, inputs, explicit)).any(axis=-1).sum())


@pytest.fixture(scope="module")
def caches(gl_contexts):
    made = {kind: TextureCache(ctx) for kind, ctx in gl_contexts.items()}
    yield made
    for kind, cache in made.items():
        activate(gl_contexts[kind])
        cache.release()


# --- bit for bit ---------------------------------------------------------------------------

@pytest.mark.parametrize("wrap", WRAPS)
def test_every_filter_matches_the_twin_bit_for_bit(wrap, gl_contexts, caches):
    """POT 16 x 16 and NPOT 7 x 5, texture() and textureLod, 32 x 32 lookups each."""
    rng = np.random.default_rng(17)
    found = {}
    for width, height in ((16, 16), (7, 5)):
        texture = random_texture(rng, width, height)
        inputs = random_inputs(rng, texture, 32)
        for filter_name in FILTERS:
            material = MaterialTexture(texture, Sampler(wrap, filter_name))
            for kind, ctx in gl_contexts.items():
                for explicit in (False, True):
                    found[kind, width, filter_name, explicit] = mismatches(ctx, caches[kind], material, inputs, explicit)
    assert set(found.values()) == {0}, {key: n for key, n in found.items() if n}


def test_anisotropic_matches_the_twin_and_ignores_the_degree(gl_contexts, caches):
    """llvmpipe's EWA, bit for bit, and the same image for anisotropy 2 and 16 (its level
    comes from the minor axis only). Derivatives up to 8 texels per pixel keep it cheap."""
    rng = np.random.default_rng(18)
    texture = random_texture(rng, 16, 16)
    inputs = random_inputs(rng, texture, 16, lowest=-3, highest=3, extremes=False)
    for kind, ctx in gl_contexts.items():
        images = []
        for degree in (2, MAX_TEXTURE_MAX_ANISOTROPY):
            material = MaterialTexture(texture, Sampler("repeat", "anisotropic", degree))
            images.append(gl_sample(ctx, caches[kind], material, inputs, False))
            assert (images[-1] == twin_sample(material, inputs, False)).all(), (kind, degree)
        assert (images[0] == images[1]).all()
        trilinear = gl_sample(ctx, caches[kind], MaterialTexture(texture, Sampler("repeat", "trilinear")), inputs, False)
        assert (images[0] != trilinear).any()                      # the path is really taken


@pytest.mark.slow
@pytest.mark.parametrize("wrap", WRAPS)
def test_sweep_sizes_and_derivatives_bit_for_bit(wrap, gl_contexts, caches):
    """1 x 1, 1 x 8, 5 x 3, 37 x 23, 64 x 64 and 256 x 128 textures, 64 x 64 lookups, every
    filter, derivatives to 2^12 texels per pixel; anisotropic to 2^7 (its scan grows with
    the ellipse)."""
    rng = np.random.default_rng(19)
    found = {}
    for width, height in ((1, 1), (1, 8), (5, 3), (37, 23), (64, 64), (256, 128)):
        texture = random_texture(rng, width, height)
        inputs = random_inputs(rng, texture, 64, highest=12)
        narrower = random_inputs(rng, texture, 64, highest=7, extremes=False)
        for filter_name in (*FILTERS, "anisotropic"):
            material = MaterialTexture(texture, Sampler(wrap, filter_name, 8 if filter_name == "anisotropic" else 1))
            for kind, ctx in gl_contexts.items():
                if filter_name == "anisotropic":
                    found[kind, width, filter_name] = mismatches(ctx, caches[kind], material, narrower)
                    continue
                for explicit in (False, True):
                    found[kind, width, filter_name, explicit] = mismatches(ctx, caches[kind], material, inputs, explicit)
    assert set(found.values()) == {0}, {key: n for key, n in found.items() if n}


# --- the upload ----------------------------------------------------------------------------

def test_each_texture_is_uploaded_once_with_every_level_bottom_row_first(gl_contexts):
    rng = np.random.default_rng(20)
    texture = random_texture(rng, 6, 4)                           # levels 6x4, 3x2, 1x1
    for ctx in gl_contexts.values():
        activate(ctx)
        cache = TextureCache(ctx)
        try:
            first, sampler = cache.get(MaterialTexture(texture, Sampler("mirror", "trilinear")))
            again, same_sampler = cache.get(MaterialTexture(texture, Sampler("mirror", "trilinear"), uv_scale=(2, 2)))
            other, other_sampler = cache.get(MaterialTexture(texture, Sampler("clamp", "nearest")))
            assert first is again is other and sampler is same_sampler and sampler is not other_sampler
            for k, level in enumerate(texture.levels):
                stored = np.frombuffer(first.read(level=k), np.uint8).reshape(level.shape)
                assert (stored == level[::-1]).all(), k
        finally:
            cache.release()
        assert cache.get(MaterialTexture(texture))[0] is not first      # made again after release
        cache.release()
