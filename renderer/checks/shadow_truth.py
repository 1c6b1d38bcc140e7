"""The rasteriser's shadow maps held against ray-cast truth (`renderer compare SCENE
--shadows-vs-truth`; docs/conventions.md, "Shadows", "Held against truth").

Per drawn pixel of an object that receives shadows (any shading mode), and per light with a
shadow map whose terms are not 0 there (N.L > 0, N the lit normal): the pixel is *considered*
for that light, and

- v, the map's visibility: the reference's lookup (reference/shadow/lookup.py) at the
  surviving fragment's point P and normal N (reference/pipeline.py `surface_pixels`; the
  reference equals the GPU within the pipeline tolerance, which tests hold), or a GPU's
  image (`visibility=`). The map says lit where v >= LIT_FROM.
- T, the truth, which shares nothing with the shadow planning (renderer/core/shadows.py) or
  the maps: the ray tracer's shadow ray (reference/raytrace/trace.py `shadow_visibility`,
  float64) from P with the ray tracer's own origin rule (P itself on an analytic shape, which
  the ray then never meets again but at a sphere's far side; Waechter and Binder's offset
  along the triangle's plane normal Ng on the light's side otherwise), to the light's
  distance for a point light, through the scene's casting objects as the ray tracer sees
  them (`casting_scene`: spheres and infinite planes exact, meshes as their triangles), the
  light taken from the scene (reference/lighting.py Lights.from_scene).

The headline: a pixel is *wrong* where the map's decision (v >= 1/2) differs from T, and
counts when it lies farther than EDGE_PX pixels (Euclidean, between pixel centres) from every
pixel of the true shadow boundary (`shadow_boundary`: considered pixels whose T differs from
that of a 4-neighbour that is considered and on the same object). Per light, and overall (a
pixel counts once, when it does for any of its lights), the count and its share of the
considered pixels: the shadow edge may be off by a couple of pixels, not more.

The band (the classes' finer measure, in the map's texels): the truth changes within one
texel of P along P's own surface. Step points S = P + delta_k, k = 0..7, delta_k one texel (t,
the map's world texel size at P: the only thing read from the plan, since it is what "a
texel" means) along 45 k degrees in the map's axes X, Y, lifted along L onto the plane of P's
triangle (at most MAX_LIFT_TEXELS long). A step counts only where S is reachable from P along
the surface (`LightRays.reachable`: nothing, casting or not, lies between P and S just above
the surface); one past a concave corner, behind the other wall, is not P's surface.

Classes per pixel and light (CLASSES): lit and shadowed (the map agrees with T), wrongly lit
(T = 0, v >= 1/2) and wrongly shadowed (T = 1, v < 1/2), each inside the band or outside it.
A pixel counts once, for the worst of its lights (CLASSES' order). Acne (a flag over the
classes): T = 1, v < 1 (any darkening), outside the band, and the darkening is the receiver's
own: the same lookup in a map holding only its object's texels (ShadowLayers.caster; the
others as if nothing were drawn there) also gives v < 1. Peter-panning, for a pixel wrongly lit
outside the band: the distance to the true shadow's edge in texels, the smallest r = 2, 3,
... MAX_REACH_TEXELS at which one of the 8 reachable directions finds a lit truth point (none:
counted as beyond).
"""

from __future__ import annotations

import math
import time
from dataclasses import dataclass, field, replace

import numpy as np

from reference.lighting import Lights, normalize
from reference.pipeline import SurfacePixels, surface_pixels
from reference.raytrace.trace import (HIT_TIE, MISS, occluded, ray_origin, scene_hit, shadow_visibility,
                                     surface)
from reference.shadow.lookup import LOOKUPS, ShadowMaps
from renderer.core.raytrace_scene import RayScene, ray_scene
from renderer.core.scene import Mesh
from renderer.core.facets import CREASE_CAP
from renderer.core.shadow_settings import footprint_radius
from renderer.core.shadows import CUBE_FACE_AXES, CUBE_FACE_ROTATIONS, cube_face, shadow_layout

LIT_FROM = 0.5                 # the map's decision: lit where its visibility v >= LIT_FROM
EDGE_PX = 2                    # the headline forgives a wrong pixel this near the true boundary
DIRECTIONS = 8                 # around P, 45 degrees apart in the map's plane
MAX_LIFT_TEXELS = 64.0         # a step lifted onto a receiver nearly along the light, capped
MAX_REACH_TEXELS = 16          # peter-panning is looked for this far (texels)
EDGE_KEY = f"wrong_beyond_{EDGE_PX}px"


@dataclass(frozen=True)
class PixelClass:
    name: str
    colour: tuple[int, int, int]       # in shadow_truth.png
    colour_name: str
    meaning: str


# In order of severity: a pixel shows the worst of its lights'.
CLASSES = (
    PixelClass("lit", (110, 110, 110), "grey", "the map and the truth agree: lit"),
    PixelClass("shadowed", (40, 40, 40), "dark grey", "the map and the truth agree: in shadow"),
    PixelClass("wrongly_lit_band", (255, 220, 0), "yellow",
               "lit by the map, in shadow in truth, within a texel of the true shadow's edge"),
    PixelClass("wrongly_shadowed_band", (0, 220, 220), "cyan",
               "in shadow by the map, lit in truth, within a texel of the true shadow's edge"),
    PixelClass("wrongly_lit", (230, 30, 30), "red",
               "lit by the map, in shadow in truth, farther than a texel from its edge "
               "(peter-panning, light leaks)"),
    PixelClass("wrongly_shadowed", (40, 80, 255), "blue",
               "in shadow by the map, lit in truth, farther than a texel from its edge"),
)
ACNE = PixelClass("acne", (255, 0, 255), "magenta",
                  "lit in truth, darkened by the map where its texel holds the receiver itself "
                  "(self-shadowing), farther than a texel from a true shadow edge")
WRONG_BEYOND = PixelClass(EDGE_KEY, (255, 255, 255), "white",
                          f"the map's decision differs from the truth farther than {EDGE_PX} px from "
                          f"every pixel of the true shadow boundary (the headline)")
NOT_CONSIDERED = -1
_INDEX = {c.name: k for k, c in enumerate(CLASSES)}
_OUTSIDE = (_INDEX["wrongly_lit"], _INDEX["wrongly_shadowed"])
_BACKDROP = (0, 0, 0)          # pixels not considered (background, non-receivers, unlit)


# --- the truth's scenes -------------------------------------------------------------------------

def casting_scene(scene):
    """A copy of `scene` holding only what casts shadows, as the ray tracer sees it: each
    casting object as it is (an analytic shape exact, else its mesh), every other object
    emptied (no mesh, no shape; kept, so that object indices and parents stay)."""
    empty = Mesh(np.zeros((0, 3)), np.zeros((0, 3)), np.zeros((0, 3), np.int64))
    return replace(scene, objects=[o if o.casts_shadows else replace(o, shape=None, mesh=empty)
                                   for o in scene.objects])


def shape_of_object(rays: RayScene, objects: int) -> np.ndarray:
    """(M,) int: each object's analytic shape in `rays` as trace.py numbers them (shape_id:
    sphere k is k, plane k is S + k), -1 for an object of triangles or absent."""
    out = np.full(objects, -1, np.int64)
    spheres = len(rays.sphere_radius)
    out[rays.sphere_object] = np.arange(spheres)
    out[rays.plane_object] = spheres + np.arange(len(rays.plane_offset))
    return out


def without_shape(rays: RayScene, shape: int) -> RayScene:
    """`rays` less one analytic shape (shape_id numbering)."""
    spheres = len(rays.sphere_radius)
    if shape < spheres:
        return replace(rays, sphere_centre=np.delete(rays.sphere_centre, shape, 0),
                       sphere_radius=np.delete(rays.sphere_radius, shape),
                       sphere_object=np.delete(rays.sphere_object, shape))
    k = shape - spheres
    return replace(rays, plane_normal=np.delete(rays.plane_normal, k, 0),
                   plane_offset=np.delete(rays.plane_offset, k), plane_object=np.delete(rays.plane_object, k))


@dataclass
class TruthScenes:
    """The scene as the truth traces it (float64, camera-relative): `casting` for the shadow
    rays (casting_scene), `every` surface for whether a step point is reachable along the
    receiver's surface (every object with triangles or a shape, casting or not), each object's
    shape in each (shape_of_object), and the lights from the scene. Motion is left out: the
    rasteriser draws the still scene."""
    casting: RayScene
    every: RayScene
    casting_shape: np.ndarray         # (M,) int
    every_shape: np.ndarray           # (M,) int
    lights: Lights

    @classmethod
    def of(cls, scene) -> "TruthScenes":
        casting, every = ray_scene(casting_scene(scene), motion=False), ray_scene(scene, motion=False)
        lights = Lights.from_scene(scene, np.float64, origin=scene.camera.eye)
        m = len(scene.objects)
        return cls(casting, every, shape_of_object(casting, m), shape_of_object(every, m), lights)


# --- one light ----------------------------------------------------------------------------------

def _dot(a, b):
    return np.einsum("ij,ij->i", a, b)


@dataclass
class LightRays:
    """One light as the measurement sees it: its truth rays through `scenes` (TruthScenes) and,
    for the band's width only, its map's texels at a point (their world size and axes)."""
    kind: str
    index: int
    maps: ShadowMaps
    scenes: TruthScenes

    def direction_to(self, P):
        """(K, 3) unit L from P towards the light (the scene's light, not the map's)."""
        lights = self.scenes.lights
        if self.kind == "directional":
            return np.broadcast_to(normalize(-lights.u_directional_direction[self.index]), P.shape)
        return normalize(lights.u_point_position[self.index] - P)

    def lit(self, P, Ng, obj, N=None) -> np.ndarray:
        """(K,) bool: the ray tracer's shadow ray from P (on object `obj` (K,), its triangle's
        plane normal Ng, the lit normal N: Ng where None) through the casting objects is free,
        and the facet, on N's side, is not turned from the light (the ray tracer's rule)."""
        s = self.scenes
        see = shadow_visibility(s.casting, s.lights, Ng, s.casting_shape[obj])
        return see(self.kind, self.index, P, Ng if N is None else N, np.ones(len(P), bool))[:, 0] > 0

    def reachable(self, P, Ng, N, obj, S, S_Ng=None) -> np.ndarray:
        """(K,) bool: step point S (K, 3), on P's own surface (onto_surface; its plane normal
        S_Ng, Ng where None), is reached from P along that surface: the segment between the two
        points, each lifted off the surface along its plane normal on the side of the lit
        normal N (the side the camera sees and lights) by half their distance, meets no surface
        of `scenes.every`, the receiver's own analytic shape left out (a plane or a sphere has
        no concave corner with itself). Half the distance clears a convex or gently concave
        surface between them (its sagitta is a small part of the chord), not a wall standing
        between them at a concave corner."""
        n = np.where((_dot(Ng, N) >= 0)[:, None], Ng, -Ng)
        m = n if S_Ng is None else np.where((_dot(S_Ng, N) >= 0)[:, None], S_Ng, -S_Ng)
        own = self.scenes.every_shape[obj]
        lift = 0.5 * np.sqrt(_dot(S - P, S - P))[:, None]
        O = ray_origin(P, n, own) + lift * n
        D = (S + lift * m) - O
        d = np.sqrt(_dot(D, D))
        with np.errstate(divide="ignore", invalid="ignore"):
            D = D / d[:, None]
        blocked = np.zeros(len(P), bool)
        for shape in np.unique(own):
            rows = np.flatnonzero((own == shape) & (d > 0))
            rays = self.scenes.every if shape < 0 else without_shape(self.scenes.every, shape)
            blocked[rows] = occluded(rays, O[rows], D[rows], d[rows] * (1.0 - HIT_TIE))
        return ~blocked

    def texel_axes(self, P):
        """(t (K,), X (K, 3), Y (K, 3)): the map's world texel size at P and its axes."""
        u = self.maps.uniforms
        if self.kind == "directional":
            M = u["u_directional_shadow_matrix"][self.index]
            t = np.full(len(P), u["u_directional_shadow"][self.index][1])
            return t, *(np.broadcast_to(normalize(M[k, :3]), P.shape) for k in (0, 1))
        resolution = u["u_point_shadow"][self.index][3]
        from_light = P - self.maps.lights.u_point_position[self.index]
        face = cube_face(from_light)
        m = _dot(CUBE_FACE_AXES[face], from_light)
        half = u["u_point_shadow_tiles"][6 * self.index + face][:, 2]     # each face's fitted half
        t = 2.0 * m * half / resolution if resolution else np.zeros(len(P))
        return t, CUBE_FACE_ROTATIONS[face, 0], CUBE_FACE_ROTATIONS[face, 1]

    def steps(self, P, Ng, texels: float) -> np.ndarray:
        """(DIRECTIONS, K, 3): the points `texels` texels from P across the light, lifted
        along L onto the plane through P of normal Ng (at most MAX_LIFT_TEXELS texels away)."""
        t, X, Y = self.texel_axes(P)
        L = self.direction_to(P)
        l_n = _dot(L, Ng)
        out = []
        for k in range(DIRECTIONS):
            angle = 2.0 * math.pi * k / DIRECTIONS
            delta = (texels * t)[:, None] * (math.cos(angle) * X + math.sin(angle) * Y)
            with np.errstate(divide="ignore", invalid="ignore"):
                lifted = delta - L * (_dot(delta, Ng) / l_n)[:, None]
            length = np.linalg.norm(lifted, axis=1)
            cap = MAX_LIFT_TEXELS * t
            lifted = np.where(np.isfinite(length)[:, None], lifted, 0.0)
            with np.errstate(divide="ignore", invalid="ignore"):
                lifted *= np.where(length > cap, cap / length, 1.0)[:, None]
            out.append(P + lifted)
        return np.stack(out)

    def onto_surface(self, P, Ng, N, obj, S):
        """(S', Ng', N', on) for step points S (K, 3) on the plane of P's triangle: the point of
        P's own object under S along the plane's normal (n: Ng on the side of the lit normal N),
        found by a ray from S + h n along -n (h the step's length) through every surface, and
        that surface's plane normal and lit normal (its shading normal on the side N faces);
        `on` (K,) bool: the first surface it meets within 2 h is
        P's object (a step off the object's edge, or onto another object, is not on P's
        surface). On a curved receiver the plane leaves the surface within a few texels, and
        the truth above it (in the air beside a convex part, inside a concave one) is not the
        surface's."""
        n = np.where((_dot(Ng, N) >= 0)[:, None], Ng, -Ng)
        h = np.sqrt(_dot(S - P, S - P))
        O, D = S + h[:, None] * n, -n
        kind, index, s, uv = scene_hit(self.scenes.every, O, D, 0.0, 2.0 * h)
        hit = np.flatnonzero(kind != MISS)
        surface_P, surface_Ng, surface_N = S.copy(), Ng.copy(), N.copy()
        on = np.zeros(len(S), bool)
        if len(hit):
            Q, Nq, Ns, owner = surface(self.scenes.every, O[hit], D[hit], kind[hit], index[hit], s[hit], uv[hit])
            mine = hit[owner == obj[hit]]
            k = owner == obj[hit]
            surface_P[mine], surface_Ng[mine] = Q[k], Nq[k]
            # its lit normal: the shading normal on the side P's lit normal faces
            surface_N[mine] = np.where((_dot(Ns[k], N[mine]) >= 0)[:, None], Ns[k], -Ns[k])
            on[mine] = True
        return surface_P, surface_Ng, surface_N, on

    def changes_within(self, P, Ng, N, obj, truth, texels: float) -> np.ndarray:
        """(K,) bool: the truth at one of the steps `texels` texels away, carried onto P's own
        surface (onto_surface) and reachable from P along it, differs from `truth` (K,)."""
        points = self.steps(P, Ng, texels).reshape(-1, 3)
        P8, Ng8, N8, obj8 = (np.tile(a, (DIRECTIONS,) + (1,) * (a.ndim - 1)) for a in (P, Ng, N, obj))
        points, normals, lit_normals, on = self.onto_surface(P8, Ng8, N8, obj8, points)
        differs = on & (self.lit(points, normals, obj8, lit_normals) != np.tile(truth, DIRECTIONS))
        ask = np.flatnonzero(differs)
        differs[ask] = self.reachable(P8[ask], Ng8[ask], N8[ask], obj8[ask], points[ask], normals[ask])
        return differs.reshape(DIRECTIONS, len(P)).any(axis=0)


# --- the true shadow boundary and the 2-pixel rule ----------------------------------------------

def shadow_boundary(truth: np.ndarray, objects: np.ndarray) -> np.ndarray:
    """(H, W) bool: the true shadow boundary of one light. `truth` (H, W) int8: 1 lit, 0
    shadowed, NOT_CONSIDERED elsewhere; `objects` (H, W) int: each pixel's object (-1 none).
    A pixel is on it where its truth differs from that of a 4-neighbour that is considered and
    on the same object: both pixels of such a pair. Across objects a change of truth is a
    silhouette (a lit ball before a shadowed floor), not a shadow's edge on a surface; next to
    a pixel not considered (unlit side, background) nothing is known to change."""
    edge = np.zeros(truth.shape, bool)
    for axis in (0, 1):
        a = [slice(None), slice(None)]
        b = [slice(None), slice(None)]
        a[axis], b[axis] = slice(None, -1), slice(1, None)
        a, b = tuple(a), tuple(b)
        pair = ((truth[a] != NOT_CONSIDERED) & (truth[b] != NOT_CONSIDERED)
                & (truth[a] != truth[b]) & (objects[a] == objects[b]))
        edge[a] |= pair
        edge[b] |= pair
    return edge


def near(mask: np.ndarray, radius: float) -> np.ndarray:
    """(H, W) bool: pixels whose centre lies within `radius` pixels (Euclidean) of a pixel of
    `mask` (H, W) bool: a dilation by the disc of that radius."""
    height, width = mask.shape
    out = np.zeros_like(mask)
    r = int(math.floor(radius))
    for dy in range(-r, r + 1):
        for dx in range(-r, r + 1):
            if dx * dx + dy * dy > radius * radius:
                continue
            out[max(dy, 0):height + min(dy, 0), max(dx, 0):width + min(dx, 0)] |= \
                mask[max(-dy, 0):height + min(-dy, 0), max(-dx, 0):width + min(-dx, 0)]
    return out


# --- figures --------------------------------------------------------------------------------------

@dataclass
class LightTruth:
    """One light's figures over the pixels it lights (`considered`): each pixel's class
    (indices into CLASSES, NOT_CONSIDERED elsewhere), the truth (1 lit, 0 shadowed,
    NOT_CONSIDERED), the true shadow boundary (shadow_boundary), the pixels wrong farther than
    EDGE_PX from it, acne, peter-panning in texels (0 where not measured, MAX_REACH_TEXELS + 1
    where no lit point was found), and the map's world texel size at the median considered
    pixel (None where none is, or where the light's map draws nothing: its lookup reads lit)."""
    kind: str
    index: int
    resolution: int
    filter: str
    classes: np.ndarray            # (H, W) int8
    truth: np.ndarray              # (H, W) int8
    boundary: np.ndarray           # (H, W) bool
    wrong_beyond: np.ndarray       # (H, W) bool
    acne: np.ndarray               # (H, W) bool
    peter_panning: np.ndarray      # (H, W) int16
    world_texel: float | None


def _figures(classes, wrong_beyond, acne, peter_panning) -> dict:
    total = classes.size
    considered = int((classes != NOT_CONSIDERED).sum())
    beyond = int(wrong_beyond.sum())
    count = {c.name: int((classes == k).sum()) for k, c in enumerate(CLASSES)}
    wrong_outside = int(np.isin(classes, _OUTSIDE).sum())
    measured = peter_panning[(peter_panning > 0) & (peter_panning <= MAX_REACH_TEXELS)]
    return {
        f"{EDGE_KEY}_pixels": beyond, f"{EDGE_KEY}_fraction": beyond / considered if considered else 0.0,
        "pixels": total, "considered_pixels": considered,
        "classes": {name: {"pixels": n, "fraction": n / total} for name, n in count.items()},
        "wrong_outside_band_pixels": wrong_outside, "wrong_outside_band_fraction": wrong_outside / total,
        "wrong_in_band_pixels": count["wrongly_lit_band"] + count["wrongly_shadowed_band"],
        "acne_pixels": int(acne.sum()), "acne_fraction": int(acne.sum()) / total,
        "peter_panning": {"pixels": int((peter_panning > 0).sum()),
                          "max_texels": int(measured.max()) if measured.size else 0,
                          "mean_texels": float(measured.mean()) if measured.size else 0.0,
                          f"beyond_{MAX_REACH_TEXELS}_texels": int((peter_panning > MAX_REACH_TEXELS).sum())},
    }


@dataclass
class ShadowTruth:
    """The scene's figures (shadows_vs_truth): per light, and per pixel the worst of them."""
    scene: str
    size: tuple[int, int]
    lights: list[LightTruth]
    milliseconds: dict = field(default_factory=dict)

    @property
    def classes(self) -> np.ndarray:
        """(H, W) int8: each pixel's class over all its lights (the worst)."""
        return np.maximum.reduce([light.classes for light in self.lights])

    @property
    def wrong_beyond(self) -> np.ndarray:
        """(H, W) bool: wrong farther than EDGE_PX from the true boundary for some light."""
        return np.logical_or.reduce([light.wrong_beyond for light in self.lights])

    @property
    def acne(self) -> np.ndarray:
        return np.logical_or.reduce([light.acne for light in self.lights])

    @property
    def peter_panning(self) -> np.ndarray:
        return np.maximum.reduce([light.peter_panning for light in self.lights])

    def as_dict(self) -> dict:
        return {"scene": self.scene, "size": list(self.size),
                **_figures(self.classes, self.wrong_beyond, self.acne, self.peter_panning),
                "lit_from": LIT_FROM, "edge_px": EDGE_PX,
                "lights": [{"kind": light.kind, "index": light.index, "resolution": light.resolution,
                            "filter": light.filter, "world_texel": light.world_texel,
                            "boundary_pixels": int(light.boundary.sum()),
                            **_figures(light.classes, light.wrong_beyond, light.acne, light.peter_panning)}
                           for light in self.lights],
                "milliseconds": self.milliseconds}

    def line(self) -> str:
        """The figures in one readable line."""
        f = self.as_dict()
        c, pp = f["classes"], f["peter_panning"]
        share = lambda n: f"{n:,} ({n / f['pixels']:.3%})"          # noqa: E731
        texels = ", ".join(f"{light['kind']} {light['index']} {light['world_texel']:.3g}"
                           if light["world_texel"] is not None else f"{light['kind']} {light['index']} -"
                           for light in f["lights"])
        return (f"{self.scene} {self.size[0]}x{self.size[1]}: wrong beyond {EDGE_PX} px of the true "
                f"shadow boundary {f[f'{EDGE_KEY}_pixels']:,} ({f[f'{EDGE_KEY}_fraction']:.3%} of "
                f"{f['considered_pixels']:,} lit pixels held against ray-cast truth); "
                f"world texel {texels}; wrong outside the 1-texel band "
                f"{share(f['wrong_outside_band_pixels'])} (wrongly lit {c['wrongly_lit']['pixels']:,}, "
                f"wrongly shadowed {c['wrongly_shadowed']['pixels']:,}), inside it "
                f"{share(f['wrong_in_band_pixels'])}, acne {share(f['acne_pixels'])}, peter-panning "
                f"up to {pp['max_texels']} texels (mean {pp['mean_texels']:.1f})")

    def image(self) -> np.ndarray:
        """(H, W, 3) uint8: each class's colour (CLASSES), acne over it, the pixels wrong
        beyond EDGE_PX over both (WRONG_BEYOND), black elsewhere."""
        image = np.full((*self.classes.shape, 3), _BACKDROP, np.uint8)
        for k, c in enumerate(CLASSES):
            image[self.classes == k] = c.colour
        image[self.acne] = ACNE.colour
        image[self.wrong_beyond] = WRONG_BEYOND.colour
        return image


# --- measuring one light ----------------------------------------------------------------------------

def _visibility(light: LightRays, surface: SurfacePixels, rows, given) -> np.ndarray:
    """(K,) v at surface pixels `rows`: the reference's lookup, or `given` (H, W)."""
    if given is not None:
        return given.reshape(-1)[surface.pixel[rows]]
    return _lookup(light, surface, rows, light.maps)


def _lookup(light: LightRays, surface: SurfacePixels, rows, maps) -> np.ndarray:
    """(K,) the reference's lookup in `maps` at surface pixels `rows`, each object's with its
    own facet normals and whether the map holds its own texels (as its fragments look up)."""
    v = np.ones(len(rows), surface.P.dtype)
    for index in np.unique(surface.object[rows]):
        at = np.flatnonzero(surface.object[rows] == index)
        k = rows[at]
        v[at] = LOOKUPS[light.kind](maps, light.index, surface.P[k], surface.facet[k],
                                    surface.position_scale[k],
                                    maps.own_texels(light.kind, light.index, int(index)),
                                    surface.crease[k]).visibility
    return v


def band_texels(shadow) -> float:
    """The band's width for a light's map (its Shadow), in texels: how far from P its lookup
    reads, so that a true shadow edge that far away may darken P by the filter's doing, not
    the receiver's: the filter's footprint radius (shadow_settings.footprint_radius: 1/2 hard,
    K/2 for K x K) plus the bias's moves of the point across the map, its normal offset
    (normal (|F.X| + |F.Y|) <= normal sqrt 2) and its crease lift (up to CREASE_CAP times the
    first two: reference/shadow/lookup.py crease_lift); at least one texel."""
    rule = shadow.bias_rule()
    reads = footprint_radius(shadow.kernel) + rule.normal * math.sqrt(2.0)
    return max(1.0, reads * (1.0 + CREASE_CAP))


def _classify(light: LightRays, surface: SurfacePixels, rows: np.ndarray, v, truth, width: float = 1.0):
    """(class, acne, peter-panning) of surface pixels `rows` (K,) against the truth (K,);
    `width`: the band's, in texels (band_texels)."""
    P, Ng, N, obj = surface.P[rows], surface.Ng[rows], surface.N[rows], surface.object[rows]
    said_lit = v >= LIT_FROM
    wrong = said_lit != truth
    darkened = truth & (v < 1.0)
    band = np.zeros(len(rows), bool)
    ask = np.flatnonzero(wrong | darkened)
    for radius in _band_radii(width):       # a ring at each whole texel out to the width
        left = ask[~band[ask]]
        band[left] = light.changes_within(P[left], Ng[left], N[left], obj[left], truth[left], radius)
    k = np.where(truth, np.where(said_lit, _INDEX["lit"], _INDEX["wrongly_shadowed"]),
                 np.where(said_lit, _INDEX["wrongly_lit"], _INDEX["shadowed"]))
    k = np.where(wrong & band, np.where(truth, _INDEX["wrongly_shadowed_band"], _INDEX["wrongly_lit_band"]), k)
    # acne: the darkening comes from the receiver's own texels
    acne = np.zeros(len(rows), bool)
    suspects = np.flatnonzero(darkened & ~band)
    acne[suspects] = _self_shadowed(light, surface, rows[suspects])
    # peter-panning: how far the true shadow's edge is, for pixels wrongly lit outside the band
    reach = np.zeros(len(rows), np.int16)
    left = np.flatnonzero(wrong & ~band & ~truth)
    reach[left] = MAX_REACH_TEXELS + 1
    for r in range(2, MAX_REACH_TEXELS + 1):
        if not len(left):
            break
        found = light.changes_within(P[left], Ng[left], N[left], obj[left], truth[left], float(r))
        reach[left[found]] = r
        left = left[~found]
    return k, acne, reach


def _band_radii(width: float) -> list[float]:
    """The rings the band is looked for on: 1, 2, ... texels, and `width` itself."""
    return sorted({*(float(r) for r in range(1, int(math.floor(width)) + 1)), float(width)})


def _self_shadowed(light: LightRays, surface: SurfacePixels, rows: np.ndarray) -> np.ndarray:
    """(K,) bool: the lookup darkens surface pixels `rows` (v < 1) in a map that holds only
    their own object's texels (every other texel cleared, as where nothing was drawn)."""
    out = np.zeros(len(rows), bool)
    layers = light.maps.layers[light.kind]
    for index in np.unique(surface.object[rows]):
        at = np.flatnonzero(surface.object[rows] == index)
        own = replace(layers, depth=np.where(layers.caster == index, layers.depth, np.float32(1.0)))
        maps = replace(light.maps, layers={**light.maps.layers, light.kind: own})
        out[at] = _lookup(light, surface, rows[at], maps) < 1.0
    return out


def _image(pixel, values, fill, width, height) -> np.ndarray:
    image = np.full(width * height, fill, dtype=np.asarray(values).dtype)
    image[pixel] = values
    return image.reshape(height, width)


def measure_light(light: LightRays, light_map, surface: SurfacePixels, rows: np.ndarray, shape,
                  given=None) -> LightTruth:
    """One light's LightTruth over the surface pixels `rows` (receivers where its terms are
    not 0). `given` (H, W): the map's visibility measured elsewhere (a GPU's images:
    renderer/study/shadow_sweep.py), NaN where it was not (those pixels are not considered);
    None: the reference's lookup."""
    height, width = shape
    if given is not None:
        rows = rows[np.isfinite(given.reshape(-1)[surface.pixel[rows]])]
    v = _visibility(light, surface, rows, given)
    truth = light.lit(surface.P[rows], surface.Ng[rows], surface.object[rows], surface.N[rows])
    k, acne, reach = _classify(light, surface, rows, v, truth, band_texels(light_map.shadow))
    out = lambda values, fill: _image(surface.pixel[rows], values, fill, width, height)   # noqa: E731
    truth_image = out(truth.astype(np.int8), np.int8(NOT_CONSIDERED))
    boundary = shadow_boundary(truth_image, _image(surface.pixel, surface.object, -1, width, height))
    wrong = out((v >= LIT_FROM) != truth, False)
    texels = light.texel_axes(surface.P[rows])[0]
    texel = float(np.median(texels)) if len(texels) else 0.0
    return LightTruth(light_map.kind, light_map.index, light_map.resolution, light_map.shadow.filter,
                      out(k, NOT_CONSIDERED).astype(np.int8), truth_image, boundary,
                      wrong & ~near(boundary, EDGE_PX), out(acne, False), out(reach, 0),
                      texel if texel > 0.0 else None)


def shadows_vs_truth(scene, width: int, height: int, visibility: dict | None = None) -> ShadowTruth:
    """The scene's shadow maps at width x height held against ray-cast truth (the module
    docstring). `visibility`: {(kind, light index): (H, W) v, NaN where not measured} in place
    of the reference's lookup for those lights (v from a GPU's images). A ValueError when the
    scene has no shadow maps."""
    layout = shadow_layout(scene, width, height)
    if not layout.any:
        raise ValueError("the scene has no shadow maps: no light with shadows on, or nothing "
                         "that casts, or nothing that receives")
    start = time.perf_counter()
    surface, maps = surface_pixels(scene, width, height)
    reference_ms = (time.perf_counter() - start) * 1000.0
    scenes = TruthScenes.of(scene)
    receives = np.array([o.receives_shadows for o in scene.objects], bool)
    lights = []
    for light_map in layout.maps:
        light = LightRays(light_map.kind, light_map.index, maps, scenes)
        lit_side = _dot(surface.N, light.direction_to(surface.P)) > 0.0
        rows = np.flatnonzero(receives[surface.object] & lit_side)
        given = (visibility or {}).get((light_map.kind, light_map.index))
        lights.append(measure_light(light, light_map, surface, rows, (height, width), given))
    total_ms = (time.perf_counter() - start) * 1000.0
    return ShadowTruth(scene.name, (width, height), lights,
                       {"reference": reference_ms, "truth": total_ms - reference_ms, "total": total_ms})
