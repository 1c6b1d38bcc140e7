"""GL's fixed-function rules, each written once: what both pipelines read and the tests hold
llvmpipe to (the conformance suite's rrRenderState is the model). The GPU path sets GL's state
from these values; the NumPy reference (reference/) computes with them; nothing else writes
them down.

- the depth mapping (`DepthMapping`, one for GL's default and one for reversed-Z): the clip
  volume's depth range, window depth from z_ndc and back, the depth buffer's clear value and
  compare function, and the glClipControl depth mode that selects it;
- the sub-pixel grid: vertices snap to 1 / 2^SUBPIXEL_BITS of a pixel, to nearest;
- the fill rule: pixel centres at (i + 1/2, j + 1/2), a centre on an edge belongs to the
  triangle only for a left or bottom edge;
- unorm conversion: a colour channel c in the framebuffer is floor(clamp(c, 0, 1) * 255 + 0.5).

Window coordinates are GL's (origin bottom-left, y up); docs/conventions.md states the rest.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from renderer.core.shadow_settings import scene_has_shadows

# --- depth ---------------------------------------------------------------------------------

GL_LOWER_LEFT = 0x8CA1                   # glClipControl origin: GL's default, kept always
GL_NEGATIVE_ONE_TO_ONE = 0x935E          # glClipControl depth mode: GL's default
GL_ZERO_TO_ONE = 0x935F                  # glClipControl depth mode for reversed-Z


@dataclass(frozen=True)
class DepthMapping:
    """How clip-space z becomes window depth z_w, and how the depth test reads z_w.

    The clip volume keeps ndc_min w <= z_clip <= w; after the divide, z_w maps that range
    [ndc_min, 1] linearly onto [0, 1] (glDepthRange's default). The projection puts the near
    plane at z_ndc = ndc_near and the far plane at ndc_far (core/transforms.depth_row); the
    buffer is cleared to the far plane's z_w, and a fragment passes when it is strictly
    nearer than what is stored (GL_LESS, or GL_GREATER when near has the larger z_w).
    """
    name: str
    ndc_min: float            # lower end of z_ndc: -1 (GL's default) or 0 (ZERO_TO_ONE)
    ndc_near: float           # z_ndc of the near plane
    ndc_far: float            # z_ndc of the far plane
    clip_control: int         # glClipControl depth mode that gives ndc_min

    def window_depth(self, z_ndc):
        """z_w = (z_ndc - ndc_min) / (1 - ndc_min): (z_ndc + 1) / 2, or z_ndc itself."""
        return (z_ndc - self.ndc_min) / (1.0 - self.ndc_min)

    @property
    def ndc_from_window(self) -> tuple[float, float]:
        """(s, t) with z_ndc = s z_w + t, the inverse of window_depth: (2, -1) or (1, 0)."""
        return 1.0 - self.ndc_min, self.ndc_min

    @property
    def clip_z_min_w(self) -> float:
        """The lower depth clip plane keeps clip_z_min_w * w + z_clip >= 0: 1 (-w <= z) or 0
        (0 <= z). Written 0 - ndc_min so that it is +0.0, never -0.0."""
        return 0.0 - self.ndc_min

    @property
    def clear_depth(self) -> float:
        """The depth buffer's clear value: the far plane's window depth (1, or 0 reversed)."""
        return float(self.window_depth(self.ndc_far))

    @property
    def greater(self) -> bool:
        """True when nearer means larger z_w (reversed-Z): the test is GL_GREATER."""
        return self.ndc_near > self.ndc_far

    @property
    def depth_func(self) -> str:
        """The compare function as moderngl spells it: "<" (GL_LESS) or ">" (GL_GREATER)."""
        return ">" if self.greater else "<"

    def depth_key(self, z_w):
        """What a GL_LESS comparison sees: z_w, or -z_w under GL_GREATER, so that one rule
        ("smaller key is nearer") serves both mappings."""
        return -z_w if self.greater else z_w


STANDARD_DEPTH = DepthMapping("standard", ndc_min=-1.0, ndc_near=-1.0, ndc_far=1.0,
                              clip_control=GL_NEGATIVE_ONE_TO_ONE)
# Reversed-Z: near -> 1, far -> 0 in a [0, 1] z_ndc range, so that z_w = z_ndc keeps float32's
# relative precision where distant depths crowd together (docs/conventions.md, "Depth").
REVERSED_Z_DEPTH = DepthMapping("reversed-Z", ndc_min=0.0, ndc_near=1.0, ndc_far=0.0,
                                clip_control=GL_ZERO_TO_ONE)


def depth_mapping(reversed_z: bool) -> DepthMapping:
    """The mapping a camera uses (Camera.reversed_z)."""
    return REVERSED_Z_DEPTH if reversed_z else STANDARD_DEPTH


# --- the sub-pixel grid and the fill rule ----------------------------------------------------

SUBPIXEL_BITS = 8          # GL_SUBPIXEL_BITS on llvmpipe (FIXED_ORDER in lp_rast.h)


def snap_to_subpixel_grid(coordinate: np.ndarray, subpixel_bits: int) -> np.ndarray:
    """Window coordinate -> int64 fixed point with `subpixel_bits` fraction bits, rounded to
    nearest with ties to even (llvmpipe's subpixel_snap: lrint of x * 2^bits)."""
    return np.rint(coordinate * float(1 << subpixel_bits)).astype(np.int64)


def pixel_centre(index: np.ndarray, subpixel_bits: int) -> np.ndarray:
    """Fixed-point coordinate of the centre of pixel column/row `index`: index + 1/2."""
    return (index << subpixel_bits) + (1 << (subpixel_bits - 1))


def is_left_or_bottom_edge(dx: np.ndarray, dy: np.ndarray) -> np.ndarray:
    """For an edge (dx, dy) of a counter-clockwise triangle (interior on its left):
    a left edge runs downwards (dy < 0); a bottom edge is horizontal running right.
    These are the inclusive edges of the fill rule."""
    return (dy < 0) | ((dy == 0) & (dx > 0))


def is_inside_edge(edge_value: np.ndarray, inclusive: np.ndarray) -> np.ndarray:
    """The fill rule: a centre on the edge (value 0) counts only for inclusive edges."""
    return np.where(inclusive, edge_value >= 0, edge_value > 0)


def inside_columns(k: np.ndarray, b: np.ndarray, inclusive: np.ndarray, subpixel_bits: int):
    """`is_inside_edge` solved for the pixel column along a row: the edge's value at column
    i's centre cx = pixel_centre(i) is k - b cx (k: the row's part, int64), and the columns
    where it passes the fill rule are lo <= i <= hi (int64; b = 0: every column or none,
    hi < lo for none). Exact integer arithmetic (floor division), so the same pixels."""
    half, big = 1 << (subpixel_bits - 1), np.int64(1) << 62
    positive = np.where(b != 0, np.abs(b), 1)
    k_in = np.where(inclusive, k, k - 1)           # k - b cx > 0  <=>  k - 1 - b cx >= 0
    # b > 0: cx <= k_in / b;  b < 0: cx >= -k_in / |b|, i.e. cx >= -(k_in // |b|)
    cx_max = np.where(b > 0, k_in // positive, big)
    cx_min = np.where(b < 0, -(k_in // positive), -big)
    empty = (b == 0) & (k_in < 0)
    lo = -((half - cx_min) >> subpixel_bits)       # ceil((cx_min - half) / 2^bits)
    hi = np.where(empty, lo - 1, (cx_max - half) >> subpixel_bits)
    return lo, hi


# --- output ----------------------------------------------------------------------------------

def to_unorm8(c: np.ndarray) -> np.ndarray:
    """GL's float -> unorm8 (OpenGL 4.5 §2.3.5.1, without dithering, which the GPU path
    disables): floor(clamp(c, 0, 1) * 255 + 0.5). In place on one temporary (a frame's worth
    of fresh arrays per step cost more in page faults than the arithmetic)."""
    scaled = np.asarray(np.clip(c, 0.0, 1.0) * 255.0)
    scaled += 0.5
    return np.floor(scaled, out=scaled).astype(np.uint8)


# GL's sRGB framebuffer (GL 4.5 core, "sRGB Conversion"; EXT_texture_sRGB): with
# GL_FRAMEBUFFER_SRGB enabled, RGB written to an SRGB8_ALPHA8 target is encoded by the sRGB
# curve, then converted to unorm8 (alpha is not encoded). EXT_texture_sRGB allows 0.6 of a
# level of error, so a GL may store one level off the exactly rounded code, and llvmpipe does
# on 5 % of inputs (docs/llvmpipe/output.md). The output stage therefore encodes by exact
# decision points instead (renderer/core/quantise.py); tests/test_gl_srgb.py measures the rule.
GL_SRGB8_ALPHA8 = 0x8C43
GL_FRAMEBUFFER_SRGB = 0x8DB9
SRGB_FRAMEBUFFER_LEVELS = 1              # GL's code within this many levels of the exact one



# --- textures ----------------------------------------------------------------------------------

# GL 4.5's minimum of GL_MAX_TEXTURE_SIZE (llvmpipe's own is 16384 too): a texture's largest
# side. The guaranteed minimum, as for uniforms below, so the reference holds the same rule.
GL_MIN_MAX_TEXTURE_SIZE = 16384

# --- uniform storage: how many lights a scene may have ---------------------------------------
#
# The light arrays are uniforms (renderer/core/uniforms.py, glsl/lighting.glsl) sized at
# compile time, and a shader stage has a limited number of uniform components
# (GL_MAX_{VERTEX,GEOMETRY,FRAGMENT}_UNIFORM_COMPONENTS); a program over the limit fails to
# link with a compiler log dozens of lines long. The limit here is GL's guaranteed minimum,
# not what one context reports (llvmpipe reports 16384), so that a scene that loads renders
# on every GL 4.5 implementation and the reference, which cannot ask GL, holds the same rule.
#
# Cost, counted as implementations allocate the default uniform block: each element of a
# vec3 array takes a whole vec4 slot (4 components). A directional light has two vec3 arrays
# (direction, intensity): 8 components; a point light three (position, intensity,
# attenuation): 12. A light whose shadows are on, in a scene with shadow maps
# (renderer/core/shadows.py: something casts and something receives), adds its lookup
# uniforms (renderer/core/uniforms.py SHADOW_UNIFORMS): a directional light a mat4 and two
# vec4 (24), a point light three vec4 and a vec4 per cube face (36). Lighting is computed in
# one stage (vertex for Gouraud, geometry for flat, fragment for Phong), which also holds at
# most 100 components of other uniforms (matrices, eye, ambient, material, counts, the
# maps' size, padded alike); 128 are kept for them.

GL_MIN_UNIFORM_COMPONENTS = 1024         # GL 4.5's minimum of GL_MAX_*_UNIFORM_COMPONENTS
OTHER_UNIFORM_COMPONENTS = 128           # kept for the uniforms that are not lights
LIGHT_UNIFORM_COMPONENTS = GL_MIN_UNIFORM_COMPONENTS - OTHER_UNIFORM_COMPONENTS   # 896
COMPONENTS_PER_DIRECTIONAL_LIGHT = 8     # 2 vec3 array elements, a vec4 slot each
COMPONENTS_PER_POINT_LIGHT = 12          # 3 vec3 array elements
COMPONENTS_PER_DIRECTIONAL_SHADOW = 24   # mat4 + 2 vec4
COMPONENTS_PER_POINT_SHADOW = 36         # 3 vec4 + 6 vec4 (one per cube face)


def light_components(directional: int, point: int, directional_shadows: int = 0,
                     point_shadows: int = 0) -> int:
    """Uniform components the light arrays of a scene take in the lighting stage; `*_shadows`
    lights of each kind (of those) also have shadow maps."""
    return (directional * COMPONENTS_PER_DIRECTIONAL_LIGHT + point * COMPONENTS_PER_POINT_LIGHT
            + directional_shadows * COMPONENTS_PER_DIRECTIONAL_SHADOW
            + point_shadows * COMPONENTS_PER_POINT_SHADOW)


def too_many_lights(directional: int, point: int, directional_shadows: int = 0,
                    point_shadows: int = 0) -> str | None:
    """Why a scene with these light counts cannot be drawn, or None when it can;
    `*_shadows`: how many lights of each kind have shadow maps."""
    used = light_components(directional, point, directional_shadows, point_shadows)
    if used <= LIGHT_UNIFORM_COMPONENTS:
        return None
    limit = LIGHT_UNIFORM_COMPONENTS
    costs = f"{COMPONENTS_PER_DIRECTIONAL_LIGHT} per directional light, {COMPONENTS_PER_POINT_LIGHT} per point light"
    examples = (f"e.g. {limit // COMPONENTS_PER_DIRECTIONAL_LIGHT} directional or "
                f"{limit // COMPONENTS_PER_POINT_LIGHT} point lights")
    advice = ""
    if directional_shadows or point_shadows:
        costs += (f", {COMPONENTS_PER_DIRECTIONAL_SHADOW} and {COMPONENTS_PER_POINT_SHADOW} more for "
                  f"the shadows of each; {directional_shadows} directional and {point_shadows} "
                  f"point lights have shadows")
        examples += (f" without shadows, "
                     f"{limit // (COMPONENTS_PER_DIRECTIONAL_LIGHT + COMPONENTS_PER_DIRECTIONAL_SHADOW)} or "
                     f"{limit // (COMPONENTS_PER_POINT_LIGHT + COMPONENTS_PER_POINT_SHADOW)} with")
        advice = "; set `shadows = false` on some lights"
    return (f"too many lights: {directional} directional and {point} point lights take {used} "
            f"uniform components ({costs}); the limit is {limit} (GL's guaranteed "
            f"{GL_MIN_UNIFORM_COMPONENTS} per shader stage less {OTHER_UNIFORM_COMPONENTS} for "
            f"the other uniforms), {examples}{advice}")


# --- varyings: the lights a flat or Gouraud receiver of shadows may have ---------------------
#
# A flat or Gouraud object that receives shadows hands the lighting equation to the fragment
# stage in pieces (glsl/vertex.glsl, glsl/geometry.glsl): the ambient term, each light's term
# (front, and back for a two-sided material) and the world position and normal for the lookup,
# a vec3 varying each, which takes a whole vec4 slot. GL 4.5 guarantees 64 vertex output
# components (16 slots: Gouraud's limit) and 128 geometry output and fragment input
# components (32 slots: flat's, whose vertex stage hands on the position alone); llvmpipe
# allows 32 everywhere. As with the uniforms, the guarantee is the rule. A textured material
# hands each term on in two parts (the coefficients its texel modulates and the others,
# glsl/lighting.glsl's TERM_PARTS) and its UV beside them.

GL_MIN_VERTEX_OUTPUT_COMPONENTS = 64     # GL 4.5's minimum of GL_MAX_VERTEX_OUTPUT_COMPONENTS
GL_MIN_FRAGMENT_INPUT_COMPONENTS = 128   # ... of GL_MAX_{GEOMETRY_OUTPUT,FRAGMENT_INPUT}_COMPONENTS
VARYING_SLOT_LIMITS = {"gouraud": GL_MIN_VERTEX_OUTPUT_COMPONENTS // 4,
                       "flat": GL_MIN_FRAGMENT_INPUT_COMPONENTS // 4}


def light_term_slots(directional: int, point: int, two_sided: bool, textured: bool = False) -> int:
    """vec4 slots the varyings of a flat or Gouraud receiver of shadows take: the ambient term
    and a term per light, per side, per part when textured, and the position and normal (and
    the UV when textured): (1 + directional + point) (2 if two-sided else 1) (2 if textured
    else 1) + 2 (+ 1 if textured)."""
    parts = 2 if textured else 1
    return (1 + directional + point) * (2 if two_sided else 1) * parts + 2 + (parts - 1)


def too_many_varyings(shading: str, directional: int, point: int, two_sided: bool,
                      textured: bool = False) -> str | None:
    """Why a `shading` receiver of shadows (of a textured material, when `textured`) cannot be
    drawn with these lights, or None."""
    limit = VARYING_SLOT_LIMITS.get(shading)
    used = light_term_slots(directional, point, two_sided, textured)
    if limit is None or used <= limit:
        return None
    sides = 2 if two_sided else 1
    stage = "vertex output" if shading == "gouraud" else "fragment input"
    kind = f"{'two-sided ' if two_sided else ''}{'textured ' if textured else ''}{shading}"
    parts = " x 2 parts (modulated by the texture and not)" if textured else ""
    uv = ", UV" if textured else ""
    return (f"too many lights for a {kind} object that "
            f"receives shadows: with {directional} directional and {point} point lights its "
            f"varyings take {used} vec4 slots ((1 + {directional + point}) terms x {sides} "
            f"side{'s' if two_sided else ''}{parts} + position{uv} and normal), the limit is "
            f"{limit} (GL's guaranteed {limit * 4} {stage} components); set `shadows = false` "
            f"on the lights, `receives_shadows = false` on the object, or use phong shading")


def scene_light_problem(scene) -> str | None:
    """too_many_lights for `scene`: its lights, and those with shadows on when the scene has
    shadow maps (the programs then declare their lookup uniforms)."""
    directional, point = scene.directional_lights, scene.point_lights
    maps = scene_has_shadows(scene)
    return too_many_lights(len(directional), len(point),
                           sum(maps and light.shadow.enabled for light in directional),
                           sum(maps and light.shadow.enabled for light in point))


def scene_varying_problem(scene) -> tuple[int, str] | None:
    """(index, too_many_varyings) of the first flat or Gouraud object of `scene` that receives
    shadows and is over the limit, when the scene has shadow maps; else None."""
    directional, point = scene.directional_lights, scene.point_lights
    if not (scene_has_shadows(scene) and any(light.shadow.enabled for light in (*directional, *point))):
        return None
    for index, obj in enumerate(scene.objects):
        problem = obj.receives_shadows and too_many_varyings(
            obj.material.shading, len(directional), len(point), obj.material.two_sided,
            obj.material.textured)
        if problem:
            return index, problem
    return None


def check_light_count(scene) -> None:
    """A SceneError (naming the scene's file, if any) when `scene` has more lights than
    too_many_lights allows, or than too_many_varyings allows a flat or Gouraud receiver of
    shadows: what GpuRenderer and the reference check before drawing."""
    from renderer.errors import SceneError
    problem = scene_light_problem(scene)
    varyings = None if problem else scene_varying_problem(scene)
    if varyings:
        index, reason = varyings
        problem = f"object {scene.objects[index].name!r}: {reason}"
    if problem:
        raise SceneError(problem, file=getattr(scene, "source", "") or None)


# --- texture sampling ------------------------------------------------------------------------
#
# How GL's sampler is set for each of renderer/core/textures.py's wraps and filters (the GPU
# path, renderer/gpu/textures.py), and the numbers llvmpipe's sampler (Mesa's gallivm,
# lp_bld_sample*.c) computes with, which the twin (reference/sampler.py) follows:
# docs/llvmpipe/texture-sampler.md, checked on this machine in tests/test_sampler_gl.py.

GL_NEAREST, GL_LINEAR = 0x2600, 0x2601
GL_LINEAR_MIPMAP_NEAREST, GL_LINEAR_MIPMAP_LINEAR = 0x2701, 0x2703
GL_REPEAT, GL_CLAMP_TO_EDGE, GL_MIRRORED_REPEAT = 0x2901, 0x812F, 0x8370
GL_TEXTURE_WRAP_S, GL_TEXTURE_WRAP_T = 0x2802, 0x2803
GL_TEXTURE_MAG_FILTER, GL_TEXTURE_MIN_FILTER = 0x2800, 0x2801
GL_TEXTURE_BASE_LEVEL, GL_TEXTURE_MAX_LEVEL = 0x813C, 0x813D
GL_TEXTURE_MAX_ANISOTROPY = 0x84FE

TEXTURE_WRAP_MODES = {"repeat": GL_REPEAT, "clamp": GL_CLAMP_TO_EDGE, "mirror": GL_MIRRORED_REPEAT}
# (min, mag) filter of each filter name. Min and mag image filters are equal in every pair:
# llvmpipe then never switches filters by the sign of the LOD (with them unequal it would
# decide for 8 pixels by the first quad's LOD, a FIXME in lp_bld_sample_aos.c).
TEXTURE_FILTER_MODES = {
    "nearest": (GL_NEAREST, GL_NEAREST),
    "bilinear": (GL_LINEAR, GL_LINEAR),
    "mip-nearest": (GL_LINEAR_MIPMAP_NEAREST, GL_LINEAR),
    "trilinear": (GL_LINEAR_MIPMAP_LINEAR, GL_LINEAR),
    "anisotropic": (GL_LINEAR_MIPMAP_LINEAR, GL_LINEAR),   # and GL_TEXTURE_MAX_ANISOTROPY
}
MAX_TEXTURE_MAX_ANISOTROPY = 16          # GL_MAX_TEXTURE_MAX_ANISOTROPY on llvmpipe

UNORM8_MAX = 255                         # an RGBA8 texel channel c means c / 255
TEXEL_WEIGHT_BITS = 8                    # llvmpipe's unorm8 filter: bilinear weights in 1/256
MIP_WEIGHT_BITS = 8                      # ... and the trilinear weight between levels


def unorm8_to_float(c: np.ndarray) -> np.ndarray:
    """An unorm8 texel channel as the sampler returns it: float32(c) * float32(1/255), one
    float32 product (llvmpipe's lp_build_unsigned_norm_to_float), which is not always the
    correctly rounded c / 255 (126 of the 256 values are one ulp off it)."""
    return np.asarray(c).astype(np.float32) * np.float32(1.0 / UNORM8_MAX)


def _float32_exponent(x: np.ndarray) -> np.ndarray:
    """The unbiased exponent field of float32 x (int32): e with x = m 2^e, m in [1, 2);
    -127 for 0 and denormals, 128 for inf and NaN."""
    bits = np.asarray(x, dtype=np.float32).view(np.int32)
    return ((bits >> 23) & 255) - 127


def fast_log2(x: np.ndarray) -> np.ndarray:
    """llvmpipe's log2 for the LOD (lp_build_fast_log2), float32, piecewise linear:
    x = m 2^e with m in [1, 2) gives (e - 1) + m, one float32 add; exact at powers of two,
    below log2 x in between by up to 0.086 (0.043 once halved for the LOD)."""
    x = np.asarray(x, dtype=np.float32)
    mantissa = ((x.view(np.int32) & 0x7FFFFF) | 0x3F800000).view(np.float32)
    return (_float32_exponent(x) - 1).astype(np.float32) + mantissa


def round_log2_sqrt(x: np.ndarray) -> np.ndarray:
    """round(log2 sqrt(x)) with halves rounded up, exactly, from float32 x's exponent
    (llvmpipe's lp_build_ilog2_sqrt, the LOD of the nearest mip filter, x = rho^2):
    (e + 1) >> 1, int32."""
    return (_float32_exponent(x) + 1) >> 1


# llvmpipe's anisotropic filter (lp_build_sample_aniso) is an elliptical weighted average
# (Heckbert's EWA) over the texels of one mip level, each texel's weight read from a table
# of exp(-2 r^2) at r^2 = i / (ANISO_WEIGHT_TABLE_SIZE - 1), i = 0..SIZE-1, the ellipse scaled
# so that its edge is r^2 = 1. The table is float32 values written to 6 decimals in Mesa's
# source (aniso_filter_table); `anisotropic_weight_table` makes the same 1024 floats.
ANISO_WEIGHT_TABLE_SIZE = 1024
ANISO_WEIGHT_ALPHA = 2.0
ANISO_WEIGHT_DECIMALS = 6


def anisotropic_weight_table() -> np.ndarray:
    """The EWA weights (float32, ANISO_WEIGHT_TABLE_SIZE): float32 r^2 = i / (SIZE - 1), the
    float32 exp(-ALPHA r^2), written with 6 decimals and read back as float32, as Mesa's table."""
    index = np.arange(ANISO_WEIGHT_TABLE_SIZE, dtype=np.float32)
    r2 = index / np.float32(ANISO_WEIGHT_TABLE_SIZE - 1)
    weights = np.exp((np.float32(-ANISO_WEIGHT_ALPHA) * r2).astype(np.float64)).astype(np.float32)
    return np.array([float(f"{float(w):.{ANISO_WEIGHT_DECIMALS}f}") for w in weights], dtype=np.float32)
