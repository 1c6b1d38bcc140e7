"""Shadow-map settings: what a light's map is made with (scene file: the light's `shadows`,
`shadow_resolution`, `shadow_filter`, `shadow_bias` keys), the filters' tap pattern and the bias
rule. The scene model holds a `Shadow` per light (renderer/core/scene.py); the layers and each
frame's light views are renderer/core/shadows.py. docs/conventions.md, "Shadows", states the rules.
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np

# --- settings --------------------------------------------------------------------------------

# filter name -> kernel k: "hard" is one nearest-texel comparison (k = 1); "pcfKxK" is the mean
# of (K-1)^2 bilinear comparisons (GL's LINEAR depth compare) on a unit grid centred on the
# point, so that together they read a K x K block of texels (`tap_offsets`).
FILTERS = {"hard": 1, "pcf2x2": 2, "pcf3x3": 3, "pcf5x5": 5}
DEFAULT_FILTER = "pcf2x2"

RESOLUTIONS = (64, 128, 256, 512, 1024, 2048, 4096)   # texels on a side of a map; powers of two
MAX_SHADOW_TEXELS = 1 << 26                    # all layers together: 256 MiB of float32 depth
# An automatic map (a cube's six faces together) holds at most this many texels per image
# pixel. A map sized by the image's longer side is square, so an image far longer than wide
# (1 x 16384) would get 29 M texels for 16 K pixels; an image of a usual shape and any filter
# stays under it (at most 100 for a directional map with pcf5x5, 37.5 for a cube).
MAX_AUTO_TEXELS_PER_PIXEL = 128


@dataclass(frozen=True)
class BiasRule:
    """How far a receiver's lookup point moves before it is compared, in texels of its map
    (t, the world size of one texel at the point): along the surface normal N by
    normal * (|N.X| + |N.Y|) (X, Y the map's axes: the normal offset), and towards the light
    by constant + slope * min(tan(theta), MAX_SLOPE) (a depth bias; theta is the angle
    between N and the light). `auto_bias(filter)` is the rule that needs no tuning."""
    normal: float = 0.0
    constant: float = 0.0
    slope: float = 0.0

    def as_vec4(self) -> np.ndarray:
        return np.array([self.normal, self.constant, self.slope, 0.0])


MAX_SLOPE = 16.0                       # tan(theta) is capped here in the slope term (86.4 deg)
# sqrt 2 as the lookup's GLSL writes it (SHADOW_SQRT2): the normal offset moves the point at most
# normal * sqrt 2 texels across the map (|N.X| + |N.Y| <= sqrt 2).
SQRT2 = 1.41421356
CONSTANT_BIAS_TEXELS = 0.5             # towards the light: rounding; facets off the smooth normal
# The most a bias term may be (scene files refuse more): far beyond any useful bias (the
# automatic one is at most 2.5 texels), and the guard band it asks for (guard_texels: at most
# ceil(2.5 + 8 sqrt 2) + 1 = 15 texels at each edge) leaves the smallest map (64 texels) more
# than half its side.
MAX_BIAS_TEXELS = 8.0


def footprint_radius(kernel: int) -> float:
    """How far (texels, along each map axis) from the lookup point the centres of the texels a
    filter reads may lie: 1/2 for the nearest texel, K/2 for K x K PCF (bilinear taps reach
    1 texel past their own position; the taps lie within (K-2)/2 of the point)."""
    return 0.5 if kernel == 1 else kernel / 2.0


def auto_bias(filter_name: str) -> BiasRule:
    """The automatic bias: a normal offset of the filter's footprint radius.

    For a planar receiver, moving the lookup point o texels along N lifts it o cos(theta)
    towards the light and moves it o sin(theta) across the map, where the plane lies
    o sin(theta) tan(theta) further away: a margin of o / cos(theta) in depth. A texel centre
    the filter reads lies at most r = radius (|n_x| + |n_y|) / sin(theta) across the map in
    the plane's downhill direction (n_x, n_y: N on the map's axes; the bound is exact for the
    square of centres), where the plane is r tan(theta) nearer. No texel of the receiver itself
    then shadows the point when o / cos(theta) >= r tan(theta), i.e. o >= radius (|n_x| + |n_y|):
    finite at every angle, unlike a slope-scaled depth bias (tan(theta) is unbounded at grazing
    light). N is the facet's normal (renderer/core/facets.py), for which the planar argument
    is exact, and the normal term is taken only where the map holds the receiver's own texels
    (ShadowPlan.self_masks). CONSTANT_BIAS_TEXELS more towards the light covers rounding (depth
    stored in float32, positions interpolated in float32) and the neighbouring facets of a
    concave part rising above the facet's plane."""
    return BiasRule(normal=footprint_radius(FILTERS[filter_name]), constant=CONSTANT_BIAS_TEXELS)


BIAS_RULES = ("auto", "slope", "constant", "none")   # the report's knob (renderer/study)


def named_bias(rule: str, filter_name: str) -> BiasRule:
    """The report's bias rules: "auto" (above), "slope" (the classic slope-scaled depth bias
    with the same footprint: no normal offset), "constant" (a fixed depth bias of one texel),
    "none" (nothing: acne everywhere a surface faces the light)."""
    radius = footprint_radius(FILTERS[filter_name])
    if rule == "auto":
        return auto_bias(filter_name)
    if rule == "slope":
        return BiasRule(constant=CONSTANT_BIAS_TEXELS, slope=radius * math.sqrt(2.0))
    if rule == "constant":
        return BiasRule(constant=1.0)
    if rule == "none":
        return BiasRule()
    raise ValueError(f"bias rule must be one of {', '.join(BIAS_RULES)}, got {rule!r}")


@dataclass(frozen=True)
class Shadow:
    """A light's shadow-map settings (scene file: the light's `shadows`, `shadow_resolution`,
    `shadow_filter`, `shadow_bias` keys). resolution None: `auto_resolution`; bias None:
    `auto_bias(filter)`."""
    enabled: bool = True
    resolution: int | None = None
    filter: str = DEFAULT_FILTER
    bias: BiasRule | None = None

    @property
    def kernel(self) -> int:
        return FILTERS[self.filter]

    def bias_rule(self) -> BiasRule:
        return self.bias if self.bias is not None else auto_bias(self.filter)


def scene_has_shadows(scene) -> bool:
    """Whether any object casts and any receives: otherwise no light needs a map (and the
    light budget, renderer/core/gl_rules.py, counts no shadow uniforms)."""
    return (any(o.casts_shadows and o.mesh.triangle_count for o in scene.objects)
            and any(o.receives_shadows for o in scene.objects))


def shared_kernel(scene) -> int:
    """The filter kernel of every light with shadows on, when they all have the same; else 0
    (or no light has shadows). The GPU path compiles it into the lookup (SHADOW_KERNEL)."""
    kernels = {light.shadow.kernel for light in [*scene.directional_lights, *scene.point_lights]
               if light.shadow.enabled}
    return kernels.pop() if len(kernels) == 1 else 0


def auto_resolution(width: int, height: int, point: bool, kernel: int = FILTERS[DEFAULT_FILTER]) -> int:
    """The default map side: for a directional light the power of two at or above twice the
    image's longer side, so that a map spread over the view has about two texels per pixel on
    a side; for a point light's cube face (90 degrees of directions, about twice a usual
    camera's field of view) the power of two at or above half the longer side, about one
    texel per pixel where the camera looks at what the light lights; times the filter's reach
    in texels (footprint_radius: 1 for the default pcf2x2, 2.5 for pcf5x5; not less than 1),
    so that a wider filter reads as far in pixels, and a shadow thinner than its footprint,
    which it washes out, is as thin on the screen; within RESOLUTIONS; halved while the map
    (all six faces of a cube) holds more than MAX_AUTO_TEXELS_PER_PIXEL texels per image pixel
    (only images far longer than wide: their long side's sharpness is given up for time and
    memory). (Held against ray-cast truth: renderer compare --shadows-vs-truth and
    benchmarks/shadow_truth_table.py give each built-in scene's figures at these sizes.)"""
    target = (max(width, height) / 2 if point else max(width, height) * 2) * max(1.0, footprint_radius(kernel))
    side = min(max(1 << max(0, math.ceil(math.log2(max(target, 1)))), RESOLUTIONS[0]), RESOLUTIONS[-1])
    faces = 6 if point else 1
    while side > RESOLUTIONS[0] and faces * side * side > MAX_AUTO_TEXELS_PER_PIXEL * width * height:
        side //= 2
    return side


def tap_offsets(kernel: int) -> np.ndarray:
    """(T, 2) tap positions in texels from the lookup point, in the order both twins sum them:
    the nearest texel's comparison at 0 for "hard"; for K x K, every (i - (K-2)/2, j - (K-2)/2)
    with i, j = 0..K-2, j (the map's y) outer."""
    if kernel == 1:
        return np.zeros((1, 2))
    steps = np.arange(kernel - 1) - (kernel - 2) / 2.0
    ys, xs = np.meshgrid(steps, steps, indexing="ij")
    return np.stack([xs.ravel(), ys.ravel()], axis=1)


def guard_texels(kernel: int, bias: BiasRule) -> int:
    """Texels at each edge of a tile that the region it answers for leaves free: the filter's
    footprint plus the normal offset's move across the map (at most normal * sqrt(2) texels),
    rounded up, plus one for rounding. No tap of a lookup inside the region leaves the tile."""
    return math.ceil(footprint_radius(kernel) + bias.normal * math.sqrt(2.0)) + 1
