"""Shadow maps: the rules both twins read, written once (docs/conventions.md, "Shadows").

The rasteriser decides per fragment and per light whether the light reaches the fragment by
looking the fragment up in a shadow map: the depth of the nearest caster seen from the
light, drawn by a depth-only pass (glsl/shadow/depth.vert, reference/shadow/depth.py) and
compared by GL's depth-compare sampler (glsl/shadow/lookup.glsl, reference/shadow/lookup.py).
This module holds what the GPU path and the reference share and neither computes on its own:

- (the settings of a light's map, `Shadow`: on/off, resolution, filter, bias, are in
  renderer/core/shadow_settings.py; objects carry `casts_shadows` / `receives_shadows`);
- the layers: every map of a scene is a layer of a DEPTH_COMPONENT32F 2D array texture, one
  texture per kind of light (`ShadowLayout`, `LayerStack`, `Tile`), each map drawn from texel
  (0, 0) of its layer; a directional light has one layer in the directional stack, a point
  light six in the point stack (the faces of a cube around it, each a perspective view of
  the face, or of the part of it where a shadow can fall, widened by a guard band, so that no
  filter tap ever leaves its map: no seams). A stack's layers are its largest map's size, so
  a cube face of 512 texels is not a layer of a directional map's 2048;
- each frame's light views (`plan_shadows`), by the pair rule of
  renderer/core/shadow_casting.py (which caster can shadow which receiver): an orthographic
  view for a directional light fitted to where a pair's caster and receiver meet across the
  light within the camera's view volume, a fitted perspective view per cube face of a point
  light, the passes worth drawing (none for a light or a face without a pair), each caster in
  the passes where it has a pair (an analytic plane as its polygon in the pass's volume:
  renderer/core/plane_clip.py), and the uniform values (ShadowPlan.uniforms, and per object
  ShadowPlan.self_masks).

Coordinates are camera-relative, as everything else the pipelines get (FrameMatrices). A map
of R texels in layers of side S (its stack's) covers texture coordinates [0, R/S)^2 of its
layer; its rows count up from the bottom as GL's window rows do (the depth pass draws with
the viewport at (0, 0), R x R, on that layer).
"""

from __future__ import annotations

import math
from dataclasses import dataclass, field, replace

import numpy as np

from renderer.core import transforms
from renderer.core.shadow_settings import (MAX_SHADOW_TEXELS, RESOLUTIONS, Shadow, auto_resolution,
                                           guard_texels, scene_has_shadows)
from renderer.core.drawn import drawn_meshes, is_plane
from renderer.core.gl_rules import STANDARD_DEPTH
from renderer.core.plane_clip import plane_polygon
from renderer.core.scene import world_shape
from renderer.core.shadow_casting import (Occluders, bounds, light_can_shadow, light_frame, light_rotation,
                                          world_geometry)
from renderer.core.visibility import all_outside, corners
from renderer.errors import SceneError

# --- cube faces ------------------------------------------------------------------------------

# Face f of a point light's cube looks along CUBE_FACE_AXES[f] (+x, -x, +y, -y, +z, -z); its view
# rotation's rows are (right, up, back) = CUBE_FACE_ROTATIONS[f] (each a reflection, determinant -1, as
# GL's cube-map faces are: a face counter-clockwise seen from outside is clockwise in its
# window), so that a
# direction d from the light has eye coordinates R d with -z_eye = d . axis. The face for d is
# its major axis: the largest |d_i|, ties going to the earlier axis (x before y before z); the
# sign picks + or - (+ for a zero component). glsl/shadow/lookup.glsl writes the same table.
CUBE_FACE_AXES = np.array([[1, 0, 0], [-1, 0, 0], [0, 1, 0], [0, -1, 0], [0, 0, 1], [0, 0, -1]],
                          dtype=np.float64)
CUBE_FACE_ROTATIONS = np.array([
    [[0, 0, -1], [0, 1, 0], [-1, 0, 0]],     # +x: right -z, up +y
    [[0, 0, 1], [0, 1, 0], [1, 0, 0]],       # -x: right +z, up +y
    [[1, 0, 0], [0, 0, -1], [0, -1, 0]],     # +y: right +x, up -z
    [[1, 0, 0], [0, 0, 1], [0, 1, 0]],       # -y: right +x, up +z
    [[1, 0, 0], [0, 1, 0], [0, 0, -1]],      # +z: right +x, up +y
    [[-1, 0, 0], [0, 1, 0], [0, 0, 1]],      # -z: right -x, up +y
], dtype=np.float64)


def cube_face(direction: np.ndarray) -> np.ndarray:
    """(...,) int face index for directions (..., 3) from the light (the rule above)."""
    d = np.asarray(direction)
    a = np.abs(d)
    axis = np.where((a[..., 0] >= a[..., 1]) & (a[..., 0] >= a[..., 2]), 0,
                    np.where(a[..., 1] >= a[..., 2], 1, 2))
    negative = np.take_along_axis(d, axis[..., None], axis=-1)[..., 0] < 0
    return 2 * axis + negative.astype(axis.dtype)


# --- the layers ------------------------------------------------------------------------------

SHADOW_KINDS = ("directional", "point")     # the stacks' order


@dataclass(frozen=True)
class Tile:
    """One map: the texels [0, size)^2 of layer `layer` of its light kind's stack (GL rows: y
    counts up from the bottom).
    Every map starts at texel (0, 0) of its own layer, because llvmpipe evaluates a triangle's
    depth plane from the window origin in float32: a map drawn at an offset in a larger texture
    would store depths hundreds of float32 units from the plane's (the probe in
    docs/llvmpipe/shadow-sampler.md, section 6)."""
    layer: int
    size: int


@dataclass(frozen=True)
class LightMap:
    """One light's shadow map: its layers of the array texture."""
    kind: str                  # "directional" or "point"
    index: int                 # the light's index among lights of its kind
    shadow: Shadow
    resolution: int
    tiles: tuple[Tile, ...]    # 1 for a directional light, 6 (CUBE_FACE_AXES order) for a point one

    @property
    def guard(self) -> int:
        return guard_texels(self.shadow.kernel, self.shadow.bias_rule())


@dataclass(frozen=True)
class LayerStack:
    """One kind of light's array texture: `layers` layers of `side` texels on a side (its
    largest map's; 0 and 0 where the kind has no map)."""
    side: int = 0
    layers: int = 0

    @property
    def texels(self) -> int:
        return self.layers * self.side * self.side


@dataclass(frozen=True)
class ShadowLayout:
    """Which lights have a map and where: fixed for a scene at an image size (the array
    textures are made from it once). `stacks`: the directional and the point lights' array
    textures (SHADOW_KINDS order); `maps`: each light's map, its tiles in its kind's stack."""
    stacks: tuple[LayerStack, LayerStack] = (LayerStack(), LayerStack())
    maps: tuple[LightMap, ...] = ()                  # ShadowLayout(): no maps at all

    def stack(self, kind: str) -> LayerStack:
        return self.stacks[SHADOW_KINDS.index(kind)]

    def get(self, kind: str, index: int) -> LightMap | None:
        for m in self.maps:
            if m.kind == kind and m.index == index:
                return m
        return None

    @property
    def any(self) -> bool:
        return bool(self.maps)


def has_shadow_maps(scene) -> bool:
    """Whether shadow_layout(scene, ...) has maps, at any image size: some light with shadows
    on can darken some receiver (`shadow_lights`)."""
    return bool(shadow_lights(scene))


def shadow_lights(scene, prune: bool = True) -> list[tuple[str, int]]:
    """(kind, index) of each light that gets a map: its shadows are on, and some caster can
    shadow some receiver under it from some camera (renderer/core/shadow_casting.py; the
    receivers are every one the scene has, seen or not). Kinds in the order directional,
    point. A light that nothing can shadow gets no map, and when no light has one the programs
    compile no shadow code: the image and the cost are those with its shadows off. `prune`
    False: every light with shadows on, when something casts and something receives (as
    plan_shadows(prune=False) draws every caster)."""
    if not scene_has_shadows(scene):
        return []
    enabled = [(kind, i) for kind, lights in (("directional", scene.directional_lights),
                                                ("point", scene.point_lights))
               for i, light in enumerate(lights) if light.shadow.enabled]
    if not enabled or not prune:
        return enabled
    occluders = Occluders(scene, *world_geometry(scene))
    return [(kind, i) for kind, i in enabled if light_can_shadow(scene, occluders, kind, i)]


def shadow_layout(scene, width: int, height: int, prune: bool = True) -> ShadowLayout:
    """The shadow maps of `scene` rendered at width x height: a layer for each light of
    `shadow_lights(scene, prune)` (six for a point light), none at all when it has none. Together
    they hold at most MAX_SHADOW_TEXELS: automatic resolutions are halved, the largest first,
    until they fit (a large image with several lights); a SceneError when the resolutions the
    file sets do not fit even so."""
    wanted = []
    for kind, i in shadow_lights(scene, prune):
        light = (scene.directional_lights if kind == "directional" else scene.point_lights)[i]
        resolution = light.shadow.resolution or auto_resolution(width, height, kind == "point",
                                                                light.shadow.kernel)
        wanted.append([kind, i, light.shadow, resolution])
    if not wanted:
        return ShadowLayout()
    while sum(stack.texels for stack in _stacks(wanted)) > MAX_SHADOW_TEXELS:
        shrinkable = [w for w in wanted if w[2].resolution is None and w[3] > RESOLUTIONS[0]]
        if not shrinkable:
            sizes = " and ".join(f"{s.layers} layers of {s.side}x{s.side}" for s in _stacks(wanted) if s.layers)
            raise SceneError(f"the shadow maps need {sizes} texels, more than {MAX_SHADOW_TEXELS} "
                             f"texels: lower shadow_resolution or turn shadows off for some lights",
                             file=getattr(scene, "source", "") or None, key="lights")
        largest = max(w[3] for w in shrinkable)
        for w in shrinkable:
            if w[3] == largest:
                w[3] //= 2
    maps, next_layer = [], {kind: 0 for kind in SHADOW_KINDS}
    for kind, i, shadow, resolution in wanted:
        count = 6 if kind == "point" else 1
        first = next_layer[kind]
        maps.append(LightMap(kind, i, shadow, resolution,
                             tuple(Tile(first + k, resolution) for k in range(count))))
        next_layer[kind] += count
    return ShadowLayout(_stacks(wanted), tuple(maps))


def _stacks(wanted) -> tuple[LayerStack, LayerStack]:
    """The stacks the wanted maps ([kind, index, shadow, resolution]) need: per kind, its
    layers (six for a point light) of its largest resolution."""
    out = []
    for kind in SHADOW_KINDS:
        sizes = [w[3] for w in wanted if w[0] == kind]
        out.append(LayerStack(max(sizes), len(sizes) * (6 if kind == "point" else 1)) if sizes
                   else LayerStack())
    return tuple(out)


# --- each frame's light views ----------------------------------------------------------------

# A point light's near plane: half the distance to the nearest caster's triangles, and at
# least NEAR_FRACTION of the far distance (geometry nearer than that to the light casts no
# shadow; depth precision near the far plane stays ~1e-7 * far^2 / near = ~1e-4 far).
NEAR_FRACTION = 2.0 ** -10
FACE_PLANE_SLACK = 1e-9                # a point this near a cube face's plane (of its distance) is on it
FACE_STEPS_PER_OCTAVE = 4              # a fitted cube face's size: the whole face's / 2^(k / 4)
DEPTH_MARGIN = 2.0 ** -8               # of the depth span, added at both ends of a light view


@dataclass(frozen=True)
class ShadowPass:
    """One tile drawn by the depth pass: `casters` (object indices) seen through
    `clip_from_world` (light clip coordinates from camera-relative world, float64) into
    `tile` (a layer, from texel (0, 0)), standard depth mapping (z_w = (z_ndc + 1) / 2, cleared to 1, GL_LESS)."""
    kind: str
    light: int
    face: int
    tile: Tile
    clip_from_world: np.ndarray
    casters: tuple[int, ...]
    # An analytic plane among the casters is drawn as the polygon where it meets this pass's
    # view volume (renderer/core/plane_clip.py; camera-relative world, the identity model):
    # caster index -> that Mesh. The other casters draw their meshes.
    polygons: dict = field(default_factory=dict)


@dataclass
class ShadowPlan:
    """A frame's shadow work: the passes to draw and the uniforms of the lookup (float64,
    named as in glsl/shadow/lookup.glsl; a light without a map reads as lit)."""
    layout: ShadowLayout
    passes: list[ShadowPass]
    uniforms: dict[str, np.ndarray]
    texel_size: dict = field(default_factory=dict)   # (kind, light) -> world size of a texel (directional)

    def self_masks(self, index: int) -> dict[str, int]:
        """The lookup's per-object bit masks (u_shadow_self_directional, u_shadow_self_point):
        bit i set where object `index` is drawn into a pass of light i of that kind, i.e.
        where the map holds its own texels and its lookups need the bias's normal offset
        (docs/conventions.md, "The bias rule"); elsewhere no texel of its own can shadow it."""
        masks = {"u_shadow_self_directional": 0, "u_shadow_self_point": 0}
        for shadow_pass in self.passes:
            if index in shadow_pass.casters:
                masks[f"u_shadow_self_{shadow_pass.kind}"] |= 1 << shadow_pass.light
        return masks


def world_points(scene, matrices) -> list[np.ndarray]:
    """Each object's vertices in camera-relative world coordinates (float64, (V, 3)); for an
    analytic plane, those of the polygon the camera pass draws (renderer/core/drawn.py: what of
    it can receive a visible shadow), or of its square where it misses the view."""
    out = []
    for obj, m, what in zip(scene.objects, matrices.objects, drawn_meshes(scene, matrices)):
        if is_plane(obj) and what.mesh.triangle_count:
            out.append(np.asarray(what.mesh.positions, dtype=np.float64))
            continue
        model = np.asarray(m.model, dtype=np.float64)
        out.append(np.asarray(obj.mesh.positions, dtype=np.float64) @ model[:3, :3].T + model[:3, 3])
    return out


def plane_polygons(scene, matrices, casters, clip_from_world: np.ndarray) -> dict:
    """{caster: the polygon where its analytic plane meets the view volume of
    `clip_from_world`} for the analytic planes among `casters` (renderer/core/plane_clip.py),
    None where it misses the volume."""
    return {i: plane_polygon(world_shape(scene.objects[i].shape, matrices.objects[i].model),
                             clip_from_world, STANDARD_DEPTH)
            for i in casters if is_plane(scene.objects[i])}


def _with_polygons(shadow_pass: ShadowPass, scene, matrices) -> ShadowPass | None:
    """`shadow_pass` with its analytic planes' polygons (plane_polygons); a plane that misses
    the pass's volume is left out of its casters (None: no caster is left)."""
    polygons = plane_polygons(scene, matrices, shadow_pass.casters, shadow_pass.clip_from_world)
    if not polygons:
        return shadow_pass
    casters = tuple(c for c in shadow_pass.casters if polygons.get(c, True) is not None)
    if not casters:
        return None
    return replace(shadow_pass, casters=casters,
                   polygons={c: mesh for c, mesh in polygons.items() if mesh is not None})


def _camera_frustum_corners(camera, matrices) -> np.ndarray:
    """(8, 3) corners of the camera's view volume, camera-relative world, from the camera's
    near and far distances and the projection's scales (P[0][0], P[1][1]: the half-width and
    half-height are their inverses, times the distance in perspective). Not by inverting P V:
    a near plane of 1e-300 makes that singular (the fuzz test's extreme cameras)."""
    P = matrices.projection
    half = np.array([1.0 / P[0, 0], 1.0 / P[1, 1]])
    perspective = camera.projection == "perspective"
    corners = []
    for distance in (float(camera.near), float(camera.far)):
        x, y = half * distance if perspective else half
        corners += [(sx * x, sy * y, -distance) for sx in (-1.0, 1.0) for sy in (-1.0, 1.0)]
    return np.asarray(corners) @ np.asarray(matrices.view)[:3, :3]          # R^T p, rows


def _ortho_rows(centre_x, centre_y, half, near, far) -> np.ndarray:
    return np.array([[1.0 / half, 0.0, 0.0, -centre_x / half],
                     [0.0, 1.0 / half, 0.0, -centre_y / half],
                     transforms.depth_row(near, far, perspective=False, reversed_z=False),
                     [0.0, 0.0, 0.0, 1.0]])


def _map_from_clip(tile: Tile, side: int) -> np.ndarray:
    """(4, 4) taking light clip coordinates (w = 1) to (u, v) in the tile's layer and z_w."""
    scale = 0.5 * tile.size / side
    m = np.diag([scale, scale, 0.5, 1.0])
    m[:3, 3] = (scale, scale, 0.5)
    return m


def _plane_depths(plane, rotation: np.ndarray, region) -> tuple[float, float]:
    """The least and greatest depth along a directional light (its frame: `rotation`) of an
    infinite plane over the square `region` (lo, hi) across the light: at the square's corners,
    the plane's depth being linear across it."""
    n = rotation[:3, :3] @ np.asarray(plane.normal, np.float64)     # light frame: x, y, -depth
    corners = np.array([(x, y) for x in (region[0][0], region[1][0]) for y in (region[0][1], region[1][1])])
    depth = (corners @ n[:2] + float(plane.offset)) / n[2]           # -z: the plane's depth
    return float(depth.min()), float(depth.max())


def _plan_directional(index, light, light_map, layout, points, receivers, pairs,
                      frustum, planes=None) -> tuple[ShadowPass | None, np.ndarray, np.ndarray, float]:
    """The light's orthographic view, fitted to where a visible shadow can fall: across the
    light, the union over the pairs (caster c, receiver r) that can interact (`pairs`: c -> its
    receivers) of c's box, r's box and the camera's view volume's box, intersected (a parallel
    light's shadow falls within its caster's box across the light, on the receiver, in view);
    a receiver point outside the map reads as lit. Square texels; the centre snapped to whole
    texels so that the map does not shimmer as the camera moves. In depth, from the nearest
    caster drawn to the deepest visible receiver whose box meets the region (a receiver point
    past the far plane would compare as shadowed). `planes`: caster -> its analytic plane
    (camera-relative world): unbounded across the light, its depth over the region its own."""
    rotation = light_rotation(light.direction)
    params = np.zeros(4)
    planes = planes or {}
    if not pairs:
        return None, np.eye(4), params, 0.0
    box = {i: bounds(light_frame(points[i], rotation)) for i in {*receivers, *pairs}}
    for i in planes:
        if i in box and i not in receivers:
            box[i] = box[i].copy()
            box[i][:, :2] = ((-np.inf, -np.inf), (np.inf, np.inf))
    view = bounds(light_frame(frustum, rotation))
    lo, hi = _pairs_region(box, pairs, within=(view[0, :2], view[1, :2]))
    if not np.all(lo <= hi):
        return None, np.eye(4), params, 0.0
    resolution, guard = light_map.resolution, light_map.guard
    extent = max(float(np.abs(b[np.isfinite(b)]).max(initial=0.0)) for b in box.values())
    half_inner = max(float((hi - lo).max()) / 2.0, 1e-9 * (1.0 + extent))
    texel = 2.0 * half_inner / (resolution - 2 * guard)
    centre = np.round((lo + hi) / 2.0 / texel) * texel       # snapped: steady as the camera moves
    half = resolution * texel / 2.0
    region = (centre - half, centre + half)
    drawn = [c for c in pairs if _meets(box[c], region)]
    seen = [r for r in receivers if _meets(box[r], region)]
    if not drawn or not seen:
        return None, np.eye(4), params, texel
    far_depth = max(float(box[r][1, 2]) for r in seen)
    for i in drawn:
        if i in planes:                       # the plane over the region, not beyond the deepest receiver
            box[i][:, 2] = np.clip(_plane_depths(planes[i], rotation, region), -np.inf, far_depth)
    near_depth = min(float(box[i][0, 2]) for i in (*drawn, *seen))
    margin = max(DEPTH_MARGIN * (far_depth - near_depth), 2.0 * texel)
    near_depth, far_depth = near_depth - margin, far_depth + margin
    clip = _ortho_rows(centre[0], centre[1], half, near_depth, far_depth) @ rotation
    tile, side = light_map.tiles[0], layout.stack("directional").side
    lookup = _map_from_clip(tile, side) @ clip
    params[:] = (tile.layer, texel, light_map.shadow.kernel, tile.size / side)
    return ShadowPass("directional", index, 0, tile, clip, tuple(drawn)), lookup, params, texel


def _pairs_region(boxes: dict, pairs: dict, within=None) -> tuple[np.ndarray, np.ndarray]:
    """(lo, hi) across the light: the union over the pairs (`pairs`: caster c -> its
    receivers) of c's box met with each receiver's (`boxes`: object -> (2, k), the first two
    columns across the light) and with `within` (lo, hi) if given, where they meet; lo > hi
    where no pair's do."""
    lo, hi = np.full(2, np.inf), np.full(2, -np.inf)
    for c, shadowed in pairs.items():           # each caster's receivers at once
        theirs = np.array([boxes[r][:, :2] for r in shadowed])          # (n, 2, 2)
        piece_lo = np.maximum(boxes[c][0, :2], theirs[:, 0])
        piece_hi = np.minimum(boxes[c][1, :2], theirs[:, 1])
        if within is not None:
            piece_lo, piece_hi = np.maximum(piece_lo, within[0]), np.minimum(piece_hi, within[1])
        meet = np.all(piece_lo <= piece_hi, axis=1)
        if meet.any():
            lo = np.minimum(lo, piece_lo[meet].min(axis=0))
            hi = np.maximum(hi, piece_hi[meet].max(axis=0))
    return lo, hi


def _meets(box: np.ndarray, region: tuple[np.ndarray, np.ndarray]) -> bool:
    """Whether a light-frame box (2, 3) meets the region (lo, hi) across the light."""
    return bool(np.all(box[1, :2] >= region[0]) and np.all(box[0, :2] <= region[1]))


def triangle_distance(corners: np.ndarray, position: np.ndarray) -> np.ndarray:
    """(T,) distance from `position` to each triangle `corners` (T, 3, 3): to its plane where
    the foot lies inside it, else to the nearest of its edges (segments)."""
    a, b, c = corners[:, 0], corners[:, 1], corners[:, 2]
    n = np.cross(b - a, c - a)
    area2 = np.einsum("ij,ij->i", n, n)
    best = np.full(len(corners), np.inf)
    flat = area2 > 0.0
    if flat.any():
        w = (position - a[flat])
        height = np.einsum("ij,ij->i", w, n[flat]) / area2[flat]
        foot = position - height[:, None] * n[flat]
        inside = np.ones(int(flat.sum()), bool)
        for p, q in ((a, b), (b, c), (c, a)):
            edge_normal = np.cross(q[flat] - p[flat], n[flat])    # points out of the triangle
            inside &= np.einsum("ij,ij->i", foot - p[flat], edge_normal) <= 0.0
        best[np.flatnonzero(flat)[inside]] = (np.abs(height) * np.sqrt(area2[flat]))[inside]
    for p, q in ((a, b), (b, c), (c, a)):                          # the edges, as segments
        e = q - p
        length2 = np.einsum("ij,ij->i", e, e)
        s = np.clip(np.einsum("ij,ij->i", position - p, e) / np.where(length2 > 0, length2, 1.0), 0, 1)
        nearest = p + s[:, None] * e
        best = np.minimum(best, np.linalg.norm(position - nearest, axis=1))
    return best


def _caster_distance(scene, points: np.ndarray, caster: int, position: np.ndarray) -> float:
    """The distance from `position` to the nearest point of object `caster`'s triangles."""
    faces = np.asarray(scene.objects[caster].mesh.faces, dtype=np.int64)
    return float(triangle_distance(points[caster][faces], position).min())


# A box nearer than this fraction more than the nearest triangle found so far is searched.
BOX_BOUND_SLACK = 1e-9


def _nearest_caster(scene, points, casters: list[int], lo: np.ndarray, hi: np.ndarray,
                    position: np.ndarray) -> float:
    """The distance from `position` to the nearest triangle of the casters (boxes lo, hi):
    the casters by their boxes' distance, a lower bound of their triangles', and none past the
    first box farther than the nearest triangle found (BOX_BOUND_SLACK covers rounding: the
    answer is the minimum over every caster's triangles)."""
    box = np.linalg.norm(np.maximum(np.maximum(lo - position, position - hi), 0.0), axis=1)
    nearest = np.inf
    for k in np.argsort(box, kind="stable"):
        if box[k] > nearest * (1.0 + BOX_BOUND_SLACK):
            break
        nearest = min(nearest, _caster_distance(scene, points, casters[k], position))
    return nearest


def _boxes(points: list[np.ndarray], indices: list[int]) -> tuple[np.ndarray, np.ndarray]:
    """(n, 3) low and high ends of the bounding boxes of points[i] for i in indices."""
    return (np.array([points[i].min(axis=0) for i in indices]).reshape(-1, 3),
            np.array([points[i].max(axis=0) for i in indices]).reshape(-1, 3))


def _outside_frusta(clips_from_world: np.ndarray, lo: np.ndarray, hi: np.ndarray) -> np.ndarray:
    """(F, n) whether box j (lo[j], hi[j]) lies wholly outside one clip plane of view f
    (clips_from_world (F, 4, 4)), as renderer/core/visibility.py tests objects against the
    camera's."""
    clip = corners(lo, hi)[None] @ np.swapaxes(clips_from_world, 1, 2)[:, None]   # (F, n, 8, 4)
    return all_outside(clip)


def point_face_projection(resolution: int, guard: int, near: float, far: float) -> tuple[np.ndarray, float]:
    """A cube face's perspective projection, widened so that the 90-degree face fills all but
    `guard` texels at each edge: tan(half angle) = R / (R - 2 guard). Returns (P, tan)."""
    tan_half = resolution / (resolution - 2.0 * guard)
    projection = transforms.perspective(2.0 * math.atan(tan_half), 1.0, near, far)
    return projection, tan_half


def fitted_face_projection(projection: np.ndarray, centre, half: float) -> np.ndarray:
    """`projection` (a face's, point_face_projection) made to cover the square of tangent
    coordinates (x, y) = (right.d, up.d) / (axis.d) within `half` of `centre`: clip x =
    (x_view + cx z_view) / half, so that x_ndc = (x - cx) / half (y likewise); depth as before."""
    fitted = projection.copy()
    fitted[0, :] = (1.0 / half, 0.0, centre[0] / half, 0.0)
    fitted[1, :] = (0.0, 1.0 / half, centre[1] / half, 0.0)
    return fitted


def _face_box(points: np.ndarray, face: int, position: np.ndarray) -> np.ndarray:
    """(2, 2): the rectangle of tangent coordinates (x, y) = (right.d, up.d) / (axis.d), d from
    the light, that `points` project to on cube face `face`, within the face's own square
    [-1, 1]^2; the whole square where a point lies on or behind the face's plane (its
    projection is unbounded there)."""
    d = points - position
    m = d @ CUBE_FACE_AXES[face]
    whole = np.array([[-1.0, -1.0], [1.0, 1.0]])
    if not len(d) or np.any(m <= FACE_PLANE_SLACK * np.linalg.norm(d, axis=1)):
        return whole
    xy = np.stack([d @ CUBE_FACE_ROTATIONS[face, 0], d @ CUBE_FACE_ROTATIONS[face, 1]], axis=1) / m[:, None]
    return np.clip(np.stack([xy.min(axis=0), xy.max(axis=0)]), -1.0, 1.0)


def _fit_face(boxes: dict, pairs_in_face: dict, resolution: int, guard: int):
    """(centre (2,), half) of the square a face's map covers in tangent coordinates: the union
    over the caster-receiver pairs in the face (`pairs_in_face`: caster -> its receivers there)
    of the caster's box and the receiver's, meeting
    (a point light's shadow falls within its caster's projection), squared, its inner R - 2g - 2
    texels spanning it (a guard band, and a texel each side for the snapped centre); the half
    size rounded up to the whole face's over a power of 2^(1/4), the centre to whole texels, so
    that the map does not crawl as the camera moves. None where no pair's boxes meet."""
    lo, hi = _pairs_region(boxes, pairs_in_face)
    if not np.all(lo <= hi):
        return None
    whole = resolution / (resolution - 2.0 * guard)
    needed = max(float((hi - lo).max()) / 2.0, 1e-9) * resolution / (resolution - 2.0 * guard - 2.0)
    steps = max(0, math.floor(FACE_STEPS_PER_OCTAVE * math.log2(whole / min(needed, whole))))
    half = whole / 2.0 ** (steps / FACE_STEPS_PER_OCTAVE)
    texel = 2.0 * half / resolution
    centre = np.round((lo + hi) / 2.0 / texel) * texel
    if half >= whole:
        centre = np.zeros(2)                  # the whole face
    return centre, half


def _plan_point(index, light, light_map, layout, matrices, points, receivers, pairs, scene,
                prune=True):
    """The light's six cube faces (docs/conventions.md, "A point light's cube"): a face is
    drawn when its frustum holds a caster and a receiver that caster can shadow (`pairs`: c ->
    its receivers), fitted to where those pairs' boxes meet on it (_fit_face); with `prune`
    False, every face whole, with every caster in its frustum."""
    position = matrices.relative(light.position)
    passes = []
    faces = np.tile([0.0, 0.0, 1.0, -1.0], (6, 1))      # (cx, cy, half, layer or -1)
    params = np.zeros(4)
    depth = np.zeros(4)
    seen = [points[i] for i in receivers]
    casters = list(pairs)
    if not seen or not casters:
        return passes, faces, params, depth
    far = float(np.sqrt(((np.vstack(seen) - position) ** 2).sum(axis=1)).max()) * (1.0 + DEPTH_MARGIN)
    far = max(far, 1e-30)
    objects = casters + [r for r in receivers if r not in pairs]
    lo, hi = _boxes(points, objects)
    n = len(casters)
    near = max(0.5 * _nearest_caster(scene, points, casters, lo[:n], hi[:n], position),
               NEAR_FRACTION * far)
    near = min(near, 0.5 * far)
    resolution, guard = light_map.resolution, light_map.guard
    projection, tan_half = point_face_projection(resolution, guard, near, far)
    views = np.empty((6, 4, 4))
    for face in range(6):
        views[face] = np.eye(4)
        views[face][:3, :3] = CUBE_FACE_ROTATIONS[face]
        views[face][:3, 3] = -CUBE_FACE_ROTATIONS[face] @ position
    outside = _outside_frusta(projection @ views, lo, hi)    # (6, objects)
    for face in range(6):
        tile = light_map.tiles[face]
        inside = {i for i, out in zip(objects, outside[face]) if not out}
        if prune:
            in_face = np.zeros(len(scene.objects), bool)
            in_face[list(inside)] = True
            pairs_in_face = {}
            for c in casters:
                if in_face[c]:
                    shadowed = np.asarray(pairs[c], np.int64)
                    shadowed = shadowed[in_face[shadowed]]
                    if len(shadowed):
                        pairs_in_face[c] = shadowed
            boxes = {i: _face_box(points[i], face, position)
                     for i in {*pairs_in_face, *(r for rs in pairs_in_face.values() for r in rs.tolist())}}
            fit = _fit_face(boxes, pairs_in_face, resolution, guard)
            if fit is None:
                continue                        # not drawn: its lookups read as lit
            drawn = tuple(pairs_in_face)
        else:
            fit, drawn = (np.zeros(2), tan_half), tuple(c for c in casters if c in inside)
        centre, half = fit
        faces[face] = (centre[0], centre[1], half, float(tile.layer))
        clip = fitted_face_projection(projection, centre, half) @ views[face]
        passes.append(ShadowPass("point", index, face, tile, clip, drawn))
    if passes:
        params[:] = (1.0, resolution / layout.stack("point").side, light_map.shadow.kernel, resolution)
        depth[:] = (0.5 - 0.5 * projection[2, 2], 0.5 * projection[2, 3], near, far)
    return passes, faces, params, depth


def plan_shadows(scene, matrices, layout: ShadowLayout, visible: list[bool] | None = None,
                 prune: bool = True) -> ShadowPlan:
    """The frame's shadow passes and lookup uniforms (module docstring). `visible`: which
    objects the camera can see (renderer/core/visibility.visible_objects; all if None); only
    those count as receivers to fit a map to. `prune` False draws every caster, also those
    that cannot shadow any receiver (renderer/core/shadow_casting.py), into every cube face,
    also those that see no caster or no receiver: a plane in its own map, to study the bias,
    and the work the pruning saves (benchmarks/bench_shadow_pruning.py)."""
    n_dir, n_point = len(scene.directional_lights), len(scene.point_lights)
    uniforms = {
        "u_directional_shadow_map_size": np.array(float(layout.stack("directional").side)),
        "u_point_shadow_map_size": np.array(float(layout.stack("point").side)),
        "u_directional_shadow_matrix": np.tile(np.eye(4), (n_dir, 1, 1)),
        "u_directional_shadow": np.zeros((n_dir, 4)),
        "u_directional_shadow_bias": np.zeros((n_dir, 4)),
        "u_point_shadow": np.zeros((n_point, 4)),
        "u_point_shadow_depth": np.zeros((n_point, 4)),
        "u_point_shadow_bias": np.zeros((n_point, 4)),
        "u_point_shadow_tiles": np.tile([0.0, 0.0, 1.0, -1.0], (6 * n_point, 1)),
    }
    plan = ShadowPlan(layout, [], uniforms)
    if not layout.any:
        return plan
    visible = [True] * len(scene.objects) if visible is None else visible
    points = world_points(scene, matrices)
    occluders = Occluders(scene, points, [np.asarray(m.model, dtype=np.float64) for m in matrices.objects])
    receivers = [i for i, o in enumerate(scene.objects)
                 if o.receives_shadows and visible[i] and o.mesh.triangle_count]
    casters = [i for i, o in enumerate(scene.objects) if o.casts_shadows and o.mesh.triangle_count]
    frustum = _camera_frustum_corners(scene.camera, matrices)
    planes = {i: world_shape(scene.objects[i].shape, matrices.objects[i].model)
              for i in casters if is_plane(scene.objects[i])}
    for light_map in layout.maps:
        i = light_map.index
        bias = light_map.shadow.bias_rule().as_vec4()
        if light_map.kind == "directional":
            light = scene.directional_lights[i]
            pairs = (occluders.pairs(casters, receivers, light_direction=light.direction) if prune
                     else {c: receivers for c in casters})
            shadow_pass, lookup, params, texel = _plan_directional(
                i, light, light_map, layout, points, receivers, pairs, frustum, planes)
            if shadow_pass is not None:
                shadow_pass = _with_polygons(shadow_pass, scene, matrices)
                if shadow_pass is None:
                    params = np.zeros(4)           # only a plane that misses it: no pass
            uniforms["u_directional_shadow_matrix"][i] = lookup
            uniforms["u_directional_shadow"][i] = params
            uniforms["u_directional_shadow_bias"][i] = bias
            plan.texel_size[("directional", i)] = texel
            if shadow_pass is not None:
                plan.passes.append(shadow_pass)
        else:
            light = scene.point_lights[i]
            position = matrices.relative(light.position)
            pairs = (occluders.pairs(casters, receivers, light_position=position) if prune
                     else {c: receivers for c in casters})
            passes, faces, params, depth = _plan_point(
                i, light, light_map, layout, matrices, points, receivers, pairs, scene, prune)
            kept = [_with_polygons(p, scene, matrices) for p in passes]
            for dropped in (p for p, k in zip(passes, kept) if k is None):
                faces[dropped.face, 3] = -1.0          # only a plane that misses it: not drawn
            passes = [p for p in kept if p is not None]
            uniforms["u_point_shadow"][i] = params
            uniforms["u_point_shadow_depth"][i] = depth
            uniforms["u_point_shadow_bias"][i] = bias
            uniforms["u_point_shadow_tiles"][6 * i:6 * i + 6] = faces
            plan.passes.extend(passes)
    return plan
