"""The rasteriser's shadow maps held against ray-cast truth (`renderer compare SCENE
--shadows-vs-truth`; docs/conventions.md, "Shadows", "Held against truth").

Per drawn pixel of an object that receives shadows (any shading mode), and per light with a
shadow map whose terms are not 0 there (N.L > 0, N the lit normal):

- v, the map's visibility: the reference's lookup (reference/shadow/lookup.py) at the
  surviving fragment's point P and normal N (reference/pipeline.py `surface_pixels`; the
  reference equals the GPU within the pipeline tolerance, which tests hold). The map says
  lit where v >= LIT_FROM.
- T, the truth: the ray tracer's shadow ray (reference/raytrace/trace.py `shadow_visibility`,
  float64: from P offset along its triangle's plane normal on the light's side, with the ray
  tracer's s_min; to the light's distance for a point light) through a BVH of the triangles
  the shadow passes draw: every casting object's mesh (an analytic shape's tessellation too).
- the band: where T is not constant within one texel of P across the light. Truth rays are
  cast also from P + delta_k, k = 0..7, delta_k one texel (t, the map's world texel size at P)
  along direction 45 k degrees in the map's axes X, Y, lifted along the light onto the plane
  of P's triangle (delta - L (delta.Ng) / (L.Ng), at most MAX_LIFT_TEXELS long).

Classes per pixel and light (CLASSES): lit and shadowed (the map agrees with T), wrongly lit
(T = 0, v >= 1/2) and wrongly shadowed (T = 1, v < 1/2), each inside the band or outside it.
A pixel counts once, for the worst of its lights (CLASSES' order). Acne (a flag over the
classes): T = 1, v < 1 (any darkening), outside the band, and the darkening is the receiver's
own: the same lookup in a map holding only its object's texels (ShadowLayers.caster; the
others as if nothing were drawn there) also gives v < 1. Peter-panning, for a pixel wrongly lit
outside the band: the distance to the true shadow's edge in texels, the smallest r = 2, 3,
... MAX_REACH_TEXELS at which one of the 8 directions finds a lit truth point (none: counted
as beyond).
"""

from __future__ import annotations

import math
import time
from dataclasses import dataclass, field, replace

import numpy as np

from reference.lighting import normalize
from reference.pipeline import SurfacePixels, surface_pixels
from reference.raytrace.trace import shadow_visibility
from reference.shadow.lookup import LOOKUPS, ShadowMaps
from renderer.core.raytrace_scene import RayScene, ray_scene
from renderer.core.scene import Mesh
from renderer.core.shadows import CUBE_FACE_AXES, CUBE_FACE_ROTATIONS, cube_face, shadow_layout

LIT_FROM = 0.5                 # the map's decision: lit where its visibility v >= LIT_FROM
DIRECTIONS = 8                 # around P, 45 degrees apart in the map's plane
MAX_LIFT_TEXELS = 64.0         # a step lifted onto a receiver nearly along the light, capped
MAX_REACH_TEXELS = 16          # peter-panning is looked for this far (texels)


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
NOT_CONSIDERED = -1
_INDEX = {c.name: k for k, c in enumerate(CLASSES)}
_OUTSIDE = (_INDEX["wrongly_lit"], _INDEX["wrongly_shadowed"])
_BACKDROP = (0, 0, 0)          # pixels not considered (background, non-receivers, unlit)


def casters_only(scene):
    """A copy of `scene` whose triangles are those the shadow passes draw: every object's
    analytic shape dropped (its tessellation stays), and the meshes of objects that do not
    cast emptied (kept, so that object indices and parents stay)."""
    empty = Mesh(np.zeros((0, 3)), np.zeros((0, 3)), np.zeros((0, 3), np.int64))
    return replace(scene, objects=[replace(o, shape=None, mesh=o.mesh if o.casts_shadows else empty)
                                   for o in scene.objects])


@dataclass
class LightRays:
    """One light as the measurement sees it: its truth rays through `rays` (casters_only) and
    its map's texels at a point (their world size and axes)."""
    kind: str
    index: int
    maps: ShadowMaps
    rays: RayScene

    def direction_to(self, P):
        """(K, 3) unit L from P towards the light."""
        lights = self.maps.lights
        if self.kind == "directional":
            return np.broadcast_to(normalize(-lights.u_directional_direction[self.index]), P.shape)
        return normalize(lights.u_point_position[self.index] - P)

    def lit(self, P, Ng) -> np.ndarray:
        """(K,) bool: the ray tracer's shadow ray from P (on the plane of normal Ng) is free."""
        see = shadow_visibility(self.rays, self.maps.lights, Ng, np.full(len(P), -1))
        return see(self.kind, self.index, P, None, np.ones(len(P), bool))[:, 0] > 0

    def texel_axes(self, P):
        """(t (K,), X (K, 3), Y (K, 3)): the map's world texel size at P and its axes."""
        u = self.maps.uniforms
        if self.kind == "directional":
            M = u["u_directional_shadow_matrix"][self.index]
            t = np.full(len(P), u["u_directional_shadow"][self.index][1])
            return t, *(np.broadcast_to(normalize(M[k, :3]), P.shape) for k in (0, 1))
        _, tan_half, _, resolution = u["u_point_shadow"][self.index]
        from_light = P - self.maps.lights.u_point_position[self.index]
        face = cube_face(from_light)
        m = np.einsum("ij,ij->i", CUBE_FACE_AXES[face], from_light)
        t = 2.0 * m * tan_half / resolution if resolution else np.zeros(len(P))
        return t, CUBE_FACE_ROTATIONS[face, 0], CUBE_FACE_ROTATIONS[face, 1]

    def steps(self, P, Ng, texels: float) -> list[np.ndarray]:
        """The DIRECTIONS points `texels` texels from P across the light, each (K, 3), lifted
        along L onto the plane through P of normal Ng (at most MAX_LIFT_TEXELS texels away)."""
        t, X, Y = self.texel_axes(P)
        L = self.direction_to(P)
        l_n = np.einsum("ij,ij->i", L, Ng)
        out = []
        for k in range(DIRECTIONS):
            angle = 2.0 * math.pi * k / DIRECTIONS
            delta = (texels * t)[:, None] * (math.cos(angle) * X + math.sin(angle) * Y)
            with np.errstate(divide="ignore", invalid="ignore"):
                lifted = delta - L * (np.einsum("ij,ij->i", delta, Ng) / l_n)[:, None]
            length = np.linalg.norm(lifted, axis=1)
            cap = MAX_LIFT_TEXELS * t
            lifted = np.where(np.isfinite(length)[:, None], lifted, 0.0)
            with np.errstate(divide="ignore", invalid="ignore"):
                lifted *= np.where(length > cap, cap / length, 1.0)[:, None]
            out.append(P + lifted)
        return out

    def changes_within(self, P, Ng, truth, texels: float) -> np.ndarray:
        """(K,) bool: a truth ray from one of the steps `texels` texels away disagrees with
        `truth` (K,)."""
        points = np.concatenate(self.steps(P, Ng, texels))
        seen = self.lit(points, np.tile(Ng, (DIRECTIONS, 1))).reshape(DIRECTIONS, len(P))
        return (seen != truth).any(axis=0)


@dataclass
class LightTruth:
    """One light's figures over the pixels it lights (`considered`): each pixel's class
    (indices into CLASSES, NOT_CONSIDERED elsewhere), acne, and peter-panning in texels
    (0 where not measured, MAX_REACH_TEXELS + 1 where no lit point was found)."""
    kind: str
    index: int
    resolution: int
    filter: str
    classes: np.ndarray            # (H, W) int8
    acne: np.ndarray               # (H, W) bool
    peter_panning: np.ndarray      # (H, W) int16


def _figures(classes: np.ndarray, acne: np.ndarray, peter_panning: np.ndarray) -> dict:
    total = classes.size
    count = {c.name: int((classes == k).sum()) for k, c in enumerate(CLASSES)}
    wrong_outside = int(np.isin(classes, _OUTSIDE).sum())
    measured = peter_panning[(peter_panning > 0) & (peter_panning <= MAX_REACH_TEXELS)]
    return {
        "pixels": total, "considered_pixels": int((classes != NOT_CONSIDERED).sum()),
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
    def acne(self) -> np.ndarray:
        return np.logical_or.reduce([light.acne for light in self.lights])

    @property
    def peter_panning(self) -> np.ndarray:
        return np.maximum.reduce([light.peter_panning for light in self.lights])

    def as_dict(self) -> dict:
        return {"scene": self.scene, "size": list(self.size), "lit_from": LIT_FROM,
                **_figures(self.classes, self.acne, self.peter_panning),
                "lights": [{"kind": light.kind, "index": light.index, "resolution": light.resolution,
                            "filter": light.filter,
                            **_figures(light.classes, light.acne, light.peter_panning)}
                           for light in self.lights],
                "milliseconds": self.milliseconds}

    def line(self) -> str:
        """The figures in one readable line."""
        f = self.as_dict()
        c, pp = f["classes"], f["peter_panning"]
        share = lambda n: f"{n:,} ({n / f['pixels']:.3%})"          # noqa: E731
        return (f"{self.scene} {self.size[0]}x{self.size[1]}: {f['considered_pixels']:,} lit pixels "
                f"held against ray-cast truth: wrong outside the 1-texel band "
                f"{share(f['wrong_outside_band_pixels'])} (wrongly lit {c['wrongly_lit']['pixels']:,}, "
                f"wrongly shadowed {c['wrongly_shadowed']['pixels']:,}), inside it "
                f"{share(f['wrong_in_band_pixels'])}, acne {share(f['acne_pixels'])}, peter-panning "
                f"up to {pp['max_texels']} texels (mean {pp['mean_texels']:.1f})")

    def image(self) -> np.ndarray:
        """(H, W, 3) uint8: each class's colour (CLASSES), acne over it, black elsewhere."""
        image = np.full((*self.classes.shape, 3), _BACKDROP, np.uint8)
        for k, c in enumerate(CLASSES):
            image[self.classes == k] = c.colour
        image[self.acne] = ACNE.colour
        return image


def _classify(light: LightRays, surface: SurfacePixels, rows: np.ndarray, shape, given=None):
    """(classes, acne, peter-panning) images of one light over the surface pixels `rows`
    (receivers where its terms are not 0). `given` (H, W): the map's visibility measured
    elsewhere (a GPU's images: renderer/study/shadow_sweep.py), NaN where it was not (those
    pixels are not considered); None: the reference's lookup."""
    height, width = shape
    if given is not None:
        rows = rows[np.isfinite(given.reshape(-1)[surface.pixel[rows]])]
    P, N, Ng = surface.P[rows], surface.N[rows], surface.Ng[rows]
    if given is None:
        v = LOOKUPS[light.kind](light.maps, light.index, P, N, surface.position_scale[rows]).visibility
    else:
        v = given.reshape(-1)[surface.pixel[rows]]
    truth = light.lit(P, Ng)
    said_lit = v >= LIT_FROM
    wrong = said_lit != truth
    darkened = truth & (v < 1.0)
    band = np.zeros(len(rows), bool)
    ask = np.flatnonzero(wrong | darkened)
    band[ask] = light.changes_within(P[ask], Ng[ask], truth[ask], 1.0)
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
        found = light.changes_within(P[left], Ng[left], truth[left], float(r))
        reach[left[found]] = r
        left = left[~found]
    out = lambda values, fill: _image(surface.pixel[rows], values, fill, width, height)   # noqa: E731
    return out(k, NOT_CONSIDERED).astype(np.int8), out(acne, False), out(reach, 0)


def _self_shadowed(light: LightRays, surface: SurfacePixels, rows: np.ndarray) -> np.ndarray:
    """(K,) bool: the lookup darkens surface pixels `rows` (v < 1) in a map that holds only
    their own object's texels (every other texel cleared, as where nothing was drawn)."""
    out = np.zeros(len(rows), bool)
    layers = light.maps.layers[light.kind]
    for index in np.unique(surface.object[rows]):
        at = np.flatnonzero(surface.object[rows] == index)
        own = replace(layers, depth=np.where(layers.caster == index, layers.depth, np.float32(1.0)))
        k = rows[at]
        v = LOOKUPS[light.kind](replace(light.maps, layers={**light.maps.layers, light.kind: own}),
                                light.index, surface.P[k],
                                surface.N[k], surface.position_scale[k]).visibility
        out[at] = v < 1.0
    return out


def _image(pixel, values, fill, width, height) -> np.ndarray:
    image = np.full(width * height, fill, dtype=np.asarray(values).dtype)
    image[pixel] = values
    return image.reshape(height, width)


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
    rays = ray_scene(casters_only(scene))
    receives = np.array([o.receives_shadows for o in scene.objects], bool)
    lights = []
    for light_map in layout.maps:
        light = LightRays(light_map.kind, light_map.index, maps, rays)
        lit_side = np.einsum("ij,ij->i", surface.N, light.direction_to(surface.P)) > 0.0
        rows = np.flatnonzero(receives[surface.object] & lit_side)
        given = (visibility or {}).get((light_map.kind, light_map.index))
        classes, acne, reach = _classify(light, surface, rows, (height, width), given)
        lights.append(LightTruth(light_map.kind, light_map.index, light_map.resolution,
                                 light_map.shadow.filter, classes, acne, reach))
    total_ms = (time.perf_counter() - start) * 1000.0
    return ShadowTruth(scene.name, (width, height), lights,
                       {"reference": reference_ms, "truth": total_ms - reference_ms, "total": total_ms})
