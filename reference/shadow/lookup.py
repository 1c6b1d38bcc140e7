"""# Twin: glsl/shadow/lookup.glsl

The shadow-map lookup (docs/conventions.md, "Shadows"; the rules: renderer/core/shadows.py,
renderer/core/shadow_settings.py): whether light i reaches surface points P (N, 3) with unit
normals N (the normals that are lit), as lighting.py's `visibility` hook asks: 1 lit, 0 in
shadow, a fraction where a filter straddles a shadow edge. In the pipeline's dtype, vectorised
over fragments, with the GLSL's formulas in the GLSL's order: the point moved by the bias
rule, then compared with the depth its map's layer stored (depth.py) as llvmpipe's
depth-compare sampler does it (docs/llvmpipe/shadow-sampler.md: the layer chosen, texel
choice and bilinear weights within it from one float32 product u * S, CLAMP_TO_EDGE to the
layer's S x S, compare ref <= stored unclamped, denormals flushed).

Ties (the reference's second acceptable answer): GL's float32 arithmetic puts P, the matrix
product and the stored depth within rounding of the reference's, so a tap whose reference
depth is that close to the stored one (or to any depth GL may store there: at a caster's
edge its float32 vertices may snap otherwise) may be decided either way, and a hard lookup whose
u * S is that close to a texel edge may read the neighbouring texel. Each lookup returns
its visibility, whether some tap was so tied, and the visibility with the tied taps decided
the other way (`ShadowLookup`); the pipeline shades such pixels again into Frame.rgba8_tie.
"""

from __future__ import annotations

from dataclasses import dataclass, field

import numpy as np

from reference.lighting import Lights, dot, normalize
from reference.shadow.depth import ShadowLayers
from renderer.core.shadow_settings import MAX_SLOPE, SQRT2, tap_offsets
from renderer.core.shadows import CUBE_FACE_AXES, CUBE_FACE_ROTATIONS, cube_face

UNIT_ROUNDOFF32 = 2.0 ** -24
SMALLEST_NORMAL32 = 2.0 ** -126
# The tie bands, in float32 roundings of the quantities a lookup is made of. GL's receiver
# point P is interpolated in float32 from vertices |V| large (camera-relative), with
# perspective weights set up and evaluated in float32 at absolute window coordinates: P is
# off by a few (~4) roundings of max |V| (`position_scale`). The bias adds ~2 roundings of
# |Q|, the 4-term product M (Q, 1) ~4 roundings of sum |M_k Q_k| + |M_3|, the cube lookup a
# division and a reciprocal; llvmpipe fuses some of these and the reference (in float64) none,
# so the count is doubled: SHADOW_TIE = 16 roundings of
#   |M_z| . (|Q| + position_scale) + |M_z3|          (z_w of a directional map),
#   S (|M_u| . (|Q| + position_scale) + |M_u3|)       (u * S, texels, for the hard texel),
# and for a point light the same through d = Q - light, z_w = A + B / m, u = 0.5 (r.d) / (m
# tan) + 0.5 (`_point_tie_bounds`). The stored depth's own rounding is depth.py's per-texel
# `tolerance` (STORE_TIE_ROUNDINGS); the compare band is their sum, around the range of depths
# GL may have stored where its snapping may change a caster's coverage (depth.py below, above).
SHADOW_TIE = 16 * UNIT_ROUNDOFF32
# The facet test (facet . L < 0: the facet is turned from the light) is decided either way
# where |facet . L| is within FACET_TIE: GL's facet normal (a float32 mat3 product of the
# float32 face normal, renormalised) and L differ from the reference's by a few roundings.
FACET_TIE = 64 * UNIT_ROUNDOFF32


@dataclass
class ShadowLookup:
    """Per fragment (N,): the visibility, the visibility with tied taps decided the other way,
    and whether any tap (of non-zero weight) was tied."""
    visibility: np.ndarray
    alternative: np.ndarray
    tied: np.ndarray

    @classmethod
    def lit(cls, n: int, dtype) -> "ShadowLookup":
        return cls(np.ones(n, dtype), np.ones(n, dtype), np.zeros(n, bool))   # not one array twice

    def put(self, where: np.ndarray, other: "ShadowLookup") -> None:
        """Overwrite the fragments `where` (indices or mask) with `other`'s."""
        self.visibility[where], self.alternative[where], self.tied[where] = (
            other.visibility, other.alternative, other.tied)


@dataclass
class ShadowMaps:
    """What the lookup reads: the frame's layers per kind of light ("directional", "point":
    the GLSL's u_directional_shadow_maps and u_point_shadow_maps), the plan's uniforms in the
    pipeline's dtype (ShadowPlan.uniforms, named as the GLSL's), the lights (their direction
    and position) and `self_masks(object)` (ShadowPlan.self_masks: the GLSL's u_shadow_self_*)."""
    layers: dict[str, ShadowLayers]
    uniforms: dict[str, np.ndarray]
    lights: Lights
    self_masks: object = None

    @classmethod
    def from_plan(cls, layers: dict[str, ShadowLayers], plan, lights: Lights, dtype) -> "ShadowMaps":
        return cls(layers, {k: np.asarray(v).astype(dtype) for k, v in plan.uniforms.items()}, lights,
                   plan.self_masks)

    def own_texels(self, kind: str, i: int, index: int) -> bool:
        """Whether light i's map (of `kind`) holds object `index`'s own texels (its bit in
        u_shadow_self_<kind>): only then does its lookup take the bias's normal term."""
        return self.self_masks is not None and bool(self.self_masks(index)[f"u_shadow_self_{kind}"] >> i & 1)


def facet_test(facet: np.ndarray, L: np.ndarray, lookup) -> ShadowLookup:
    """The light's visibility where the facet (unit normal on the lit side, (N, 3)) is turned
    from the light L ((N, 3) or (3,)): 0 where facet . L < 0, else `lookup(rows)`'s (a
    ShadowLookup of those rows; a facet along the light, facet . L = 0, is looked up as a ray
    grazing it is not blocked by it); within FACET_TIE of 0 the other decision is the
    alternative."""
    c = dot(facet, L)[:, 0]
    rows = np.flatnonzero(c > -FACET_TIE)
    out = ShadowLookup(np.zeros(len(c), facet.dtype), np.zeros(len(c), facet.dtype), np.zeros(len(c), bool))
    if len(rows):
        out.put(rows, lookup(rows))
    facing = c >= 0.0
    near = np.abs(c) <= FACET_TIE
    out.alternative = np.where(near, np.where(facing, 0.0, out.visibility), out.alternative).astype(facet.dtype)
    out.visibility = np.where(facing, out.visibility, 0.0).astype(facet.dtype)
    out.tied = out.tied & facing | near
    return out


# --- the bias ---------------------------------------------------------------------------------

def crease_lift(own: bool, kernel: int, normal, crease) -> np.ndarray:
    """How far (texels) the point is lifted along the facet normal for its crease (glsl's
    crease_lift): where the map holds the receiver's own texels, the crease's slope times the
    texels the lookup reads (the filter's reach plus the normal offset's move, normal sqrt 2)."""
    dtype = np.result_type(crease)
    reach = dtype.type(0.5) if kernel == 1 else dtype.type(0.5) * dtype.type(kernel)
    return dtype.type(float(own)) * crease * (reach + dtype.type(normal) * dtype.type(SQRT2))


def shadow_bias_point(P, N, L, X, Y, t, bias, lift=0.0) -> np.ndarray:
    """The receiver point moved before it is compared (shadow_settings.BiasRule): along the
    facet normal N by bias.x (|N.X| + |N.Y|) texels (X, Y the map's axes) and towards the light L by bias.y +
    bias.z min(tan(theta), MAX_SLOPE) texels; t (..., 1) or scalar is the world size of a texel."""
    dtype = np.result_type(P)
    c = np.clip(dot(N, L), 0.0, 1.0)
    s = np.sqrt(1.0 - c * c)
    with np.errstate(divide="ignore", invalid="ignore"):
        tan_theta = np.where(c > 0.0, np.minimum(s / c, dtype.type(MAX_SLOPE)), dtype.type(MAX_SLOPE))
    normal = bias[0] * (np.abs(dot(N, X)) + np.abs(dot(N, Y))) + np.reshape(lift, (-1, 1))
    toward = bias[1] + bias[2] * tan_theta
    return P + t * (normal * N + toward * L)


# --- the sampler ------------------------------------------------------------------------------

def _flush_denormals(x: np.ndarray) -> np.ndarray:
    return np.where(np.abs(x) < SMALLEST_NORMAL32, np.zeros_like(x), x)


def compare(ref: np.ndarray, stored: np.ndarray) -> np.ndarray:
    """GL's LEQUAL depth compare as llvmpipe does it for DEPTH_COMPONENT32F: lit where
    ref <= stored, ref not clamped to [0, 1], denormals compared as 0, NaN never lit."""
    return _flush_denormals(ref) <= _flush_denormals(stored.astype(np.result_type(ref)))


def linear_texels(u: np.ndarray, size: int):
    """LINEAR + CLAMP_TO_EDGE along one axis (llvmpipe lp_build_sample_wrap_linear):
    x = max(min(u S, S) - 1/2, 0) (NaN: S then 0), texels floor(x) and its successor (clamped
    to S - 1), and the successor's weight x - floor(x)."""
    x = u * u.dtype.type(size)
    x = np.where(np.isnan(x), size, np.minimum(x, size)) - u.dtype.type(0.5)
    x = np.maximum(x, 0)
    floor = np.floor(x)
    i0 = floor.astype(np.int64)
    return i0, np.minimum(i0 + 1, size - 1), x - floor


def _taps(layers: ShadowLayers, layer, ref, tie_ref, j, i):
    """(lit, tied) of one texel (i, j) of `layer` per fragment: tied where ref lies within the
    band (tie_ref plus the texel's tolerance) of the depths GL may have stored there, from
    depth - below to depth + above (depth.py: its coverage may differ at a caster's edge)."""
    stored = layers.depth[layer, j, i]
    lit = compare(ref, stored)
    band = tie_ref + layers.tolerance[layer, j, i]
    nearest, farthest = stored - layers.below[layer, j, i], stored + layers.above[layer, j, i]
    with np.errstate(invalid="ignore"):
        tied = (ref >= nearest - band) & (ref <= farthest + band)
    return lit, tied


def _bilinear(lit00, lit01, lit10, lit11, s, t):
    """llvmpipe's blend of four compare results (m_yx), x first, then y."""
    v0 = np.where(lit01, s, 0) + np.where(lit00, 1 - s, 0)
    v1 = np.where(lit11, s, 0) + np.where(lit10, 1 - s, 0)
    return v0 + t * (v1 - v0)


def shadow_filter(layers: ShadowLayers, uvz: np.ndarray, layer, kernel: int, tie_ref: np.ndarray,
                  tie_texel: np.ndarray) -> ShadowLookup:
    """The filter at points uvz (N, 3) = (u, v, reference z_w) of `layer` (int or (N,) ints:
    GLSL's layer coordinate, an exact integer, so no rounding to choose). Kernel 1 (hard): the
    nearest texel's comparison (GLSL: the LINEAR sampler at its centre, weight exactly 0 for
    the neighbour); K >= 2: the mean of the (K-1)^2 bilinear comparisons at tap_offsets(K) / S.
    tie_ref (N,): the receiver's z_w tie band; tie_texel (N, 2): the band of u S, v S (hard)."""
    S = layers.side
    u, v, ref = uvz[:, 0], uvz[:, 1], uvz[:, 2]
    dtype = uvz.dtype
    if kernel == 1:
        x, y = u * dtype.type(S), v * dtype.type(S)
        i = np.clip(np.floor(x), 0, S - 1).astype(np.int64)
        j = np.clip(np.floor(y), 0, S - 1).astype(np.int64)
        lit, tied = _taps(layers, layer, ref, tie_ref, j, i)
        # the neighbouring texel where u S (v S) is within its band of a texel edge
        near_x = np.abs(x - np.round(x)) <= tie_texel[:, 0]
        near_y = np.abs(y - np.round(y)) <= tie_texel[:, 1]
        i_alt = np.clip(np.where(near_x, np.where(x - np.floor(x) < 0.5, i - 1, i + 1), i), 0, S - 1)
        j_alt = np.clip(np.where(near_y, np.where(y - np.floor(y) < 0.5, j - 1, j + 1), j), 0, S - 1)
        lit_alt = compare(ref, layers.depth[layer, j_alt, i_alt])
        other_texel = lit_alt != lit
        visibility = lit.astype(dtype)
        alternative = np.where(other_texel, lit_alt, np.where(tied, ~lit, lit)).astype(dtype)
        return ShadowLookup(visibility, alternative, tied | other_texel)
    visibility = np.zeros(len(uvz), dtype)
    alternative = np.zeros(len(uvz), dtype)
    tied_any = np.zeros(len(uvz), bool)
    for ox, oy in tap_offsets(kernel):
        i0, i1, s = linear_texels(u + dtype.type(ox) / dtype.type(S), S)
        j0, j1, t = linear_texels(v + dtype.type(oy) / dtype.type(S), S)
        corners = [_taps(layers, layer, ref, tie_ref, j, i) for j, i in ((j0, i0), (j0, i1), (j1, i0), (j1, i1))]
        weights = [(1 - s) * (1 - t), s * (1 - t), (1 - s) * t, s * t]
        visibility += _bilinear(*(lit for lit, _ in corners), s, t)
        alternative += _bilinear(*(lit ^ tied for lit, tied in corners), s, t)
        for (_, tied), weight in zip(corners, weights):
            tied_any |= tied & (weight > 0)
    taps = dtype.type((kernel - 1) ** 2)
    return ShadowLookup(visibility / taps, alternative / taps, tied_any)


# --- the lights -------------------------------------------------------------------------------

def light_visibility_directional(maps: ShadowMaps, i: int, P: np.ndarray, facet: np.ndarray,
                                 position_scale: np.ndarray, own: bool = True,
                                 crease=None) -> ShadowLookup:
    """Directional light i at points P (N, 3) on facets of unit normal `facet` (the lit side);
    position_scale (N,): the largest |coordinate| of the vertices P was interpolated from (the
    tie bands); `own`: the map holds the object's own texels (ShadowMaps.own_texels); `crease`
    (N,): each facet's crease on its lit side (renderer/core/facets.py; None: 0)."""
    L = normalize(-maps.lights.u_directional_direction[i])
    crease = np.zeros(len(P), P.dtype) if crease is None else np.asarray(crease, P.dtype)
    return facet_test(facet, np.broadcast_to(L, facet.shape), lambda rows: _directional(
        maps, i, P[rows], facet[rows], np.asarray(position_scale)[rows], own, L, crease[rows]))


def _directional(maps: ShadowMaps, i: int, P, facet, position_scale, own: bool, L, crease) -> ShadowLookup:
    dtype = P.dtype
    p = maps.uniforms["u_directional_shadow"][i]                 # (layer, t, kernel, extent)
    if p[3] == 0.0:
        return ShadowLookup.lit(len(P), dtype)    # no pass this frame: nothing can shadow
    M = maps.uniforms["u_directional_shadow_matrix"][i]
    X, Y = normalize(M[0, :3]), normalize(M[1, :3])
    bias = maps.uniforms["u_directional_shadow_bias"][i] * np.array([float(own), 1, 1, 1], dtype)
    Q = shadow_bias_point(P, facet, L, X, Y, p[1], bias, crease_lift(own, int(p[2]), bias[0], crease))
    uvz = Q @ M[:3, :3].T + M[:3, 3]
    scale = np.abs(Q).astype(np.float64) + np.asarray(position_scale, np.float64)[:, None]
    A = np.abs(M.astype(np.float64))
    tie_ref = SHADOW_TIE * (scale @ A[2, :3] + A[2, 3])
    layers = maps.layers["directional"]
    tie_texel = SHADOW_TIE * layers.side * (scale @ A[:2, :3].T + A[:2, 3])
    # Outside the map, which holds every caster that can shadow, nothing is there: lit.
    inside = np.flatnonzero(((uvz[:, :2] >= 0.0) & (uvz[:, :2] <= p[3])).all(axis=1))
    result = ShadowLookup.lit(len(P), dtype)
    result.put(inside, shadow_filter(layers, uvz[inside], int(p[0]), int(p[2]),
                                     tie_ref[inside], tie_texel[inside]))
    return result


def _point_tie_bounds(Q, light, d, m, right_up, position_scale, depth, half, rect_size, S):
    """(tie_ref, tie_texel) of a cube lookup: d = Q - light is off by e (the roundings of
    |Q|, P's vertices and |light|); m = axis.d by e too; z_w = A + B / m by |B| e / m^2 and
    the roundings of A and B / m; u S by S size (0.5 / half) (e / |m| + |r.d| e / m^2)."""
    e = SHADOW_TIE * (np.abs(Q).max(axis=1) + position_scale + np.abs(light).max())
    m = np.abs(m)
    A, B = abs(float(depth[0])), abs(float(depth[1]))
    tie_ref = B * e / (m * m) + SHADOW_TIE * (A + B / m)
    per_texel = S * rect_size * 0.5 / half
    tie_texel = per_texel[:, None] * ((e / m)[:, None] + np.abs(right_up) * (e / (m * m))[:, None])
    tie_texel += SHADOW_TIE * S
    return tie_ref, tie_texel


def light_visibility_point(maps: ShadowMaps, i: int, P: np.ndarray, facet: np.ndarray,
                           position_scale: np.ndarray, own: bool = True, crease=None) -> ShadowLookup:
    """Point light i at points P (N, 3) on facets of unit normal `facet` (as
    light_visibility_directional)."""
    dtype = P.dtype
    out = ShadowLookup.lit(len(P), dtype)
    crease = np.zeros(len(P), dtype) if crease is None else np.asarray(crease, dtype)
    light = maps.lights.u_point_position[i]
    to_light = light - P
    rows = np.flatnonzero(dot(to_light, to_light)[:, 0] != 0.0)   # a light on the surface: lit
    L = normalize(to_light[rows])
    out.put(rows, facet_test(facet[rows], L, lambda k: _point(
        maps, i, P[rows[k]], facet[rows[k]], np.asarray(position_scale)[rows[k]], own, L[k],
        to_light[rows[k]], crease[rows[k]])))
    return out


def _point(maps: ShadowMaps, i: int, P, facet, scale, own: bool, L, to_light, crease) -> ShadowLookup:
    dtype = P.dtype
    out = ShadowLookup.lit(len(P), dtype)
    p = maps.uniforms["u_point_shadow"][i]                      # (drawn, R / S, kernel, R)
    if p[0] == 0.0:
        return out
    light = maps.lights.u_point_position[i]
    rotations, axes = CUBE_FACE_ROTATIONS.astype(dtype), CUBE_FACE_AXES.astype(dtype)
    f = cube_face(-to_light)          # P's own face, also for Q (the GLSL says why)
    face = maps.uniforms["u_point_shadow_tiles"][6 * i + f]   # (centre x, y, half, layer or -1)
    rows = np.flatnonzero(face[:, 3] >= 0.0)                 # else the face is not drawn: lit
    P, facet, scale, L, to_light, crease, f, face = (a[rows] for a in (P, facet, scale, L, to_light,
                                                                       crease, f, face))
    t = 2.0 * dot(axes[f], -to_light) * face[:, 2:3] / p[3]   # a texel's size at P's distance
    bias = maps.uniforms["u_point_shadow_bias"][i] * np.array([float(own), 1, 1, 1], dtype)
    Q = shadow_bias_point(P, facet, L, rotations[f, 0], rotations[f, 1], t, bias,
                          crease_lift(own, int(p[2]), bias[0], crease))
    d = Q - light
    m = dot(axes[f], d)[:, 0]
    right_up = np.stack([dot(rotations[f, 0], d)[:, 0], dot(rotations[f, 1], d)[:, 0]], axis=1)
    with np.errstate(divide="ignore", invalid="ignore"):
        tangent = right_up / m[:, None]
        uv = (dtype.type(0.5) * (tangent - face[:, :2]) / face[:, 2:3] + dtype.type(0.5)) * p[1]
        depth = maps.uniforms["u_point_shadow_depth"][i]
        uvz = np.concatenate([uv, (depth[0] + depth[1] / m)[:, None]], axis=1)
        tie_ref, tie_texel = _point_tie_bounds(
            Q.astype(np.float64), np.asarray(light, np.float64), d, m.astype(np.float64),
            right_up.astype(np.float64), scale.astype(np.float64), depth,
            face[:, 2].astype(np.float64), float(p[1]), maps.layers["point"].side)
    # outside the fitted square, which holds every caster-receiver pair's shadow: lit
    inside = np.flatnonzero(((uv >= 0.0) & (uv <= p[1])).all(axis=1))
    out.put(rows[inside], shadow_filter(maps.layers["point"], uvz[inside], face[inside, 3].astype(np.int64),
                                        int(p[2]), tie_ref[inside], tie_texel[inside]))
    return out


LOOKUPS = {"directional": light_visibility_directional, "point": light_visibility_point}


@dataclass
class FragmentShadows:
    """The `visibility` callable lighting() takes, for one object's fragments, keeping each
    light's lookup: `alternative` then answers the same lights with tied taps decided the
    other way, and `tied` (N,) says where some light's lookup (where its term is not 0) was."""
    maps: ShadowMaps
    position_scale: np.ndarray
    facet: np.ndarray                  # (N, 3) the fragments' facet normals on the lit side
    index: int                         # the object's index in the scene
    crease: np.ndarray | None = None   # (N,) their facets' creases on the lit side
    lookups: dict = field(default_factory=dict)

    def _lookup(self, kind, i, P, N, needed) -> ShadowLookup:
        key = (kind, i)
        if key not in self.lookups:
            out = ShadowLookup.lit(len(P), P.dtype)
            rows = np.flatnonzero(needed)          # elsewhere the light adds nothing
            if len(rows):
                out.put(rows, LOOKUPS[kind](self.maps, i, P[rows], self.facet[rows],
                                            self.position_scale[rows],
                                            self.maps.own_texels(kind, i, self.index),
                                            None if self.crease is None else self.crease[rows]))
            self.lookups[key] = out
        return self.lookups[key]

    def visibility(self, kind, i, P, N, needed) -> np.ndarray:
        return self._lookup(kind, i, P, N, needed).visibility[:, None]

    def alternative(self, kind, i, P, N, needed) -> np.ndarray:
        return self._lookup(kind, i, P, N, needed).alternative[:, None]

    @property
    def tied(self) -> np.ndarray | None:
        masks = [look.tied for look in self.lookups.values()]
        return np.logical_or.reduce(masks) if masks else None
