"""The rasteriser's tessellation stages (issue 34; notes 4.1): the rules the control stage's
GLSL (glsl/tess_control.glsl) and its twin (reference/tessellation/control.py) both read, so
that a level is defined once.

A curved surface is drawn from coarse triangle patches, the evaluation stage placing every
vertex the tessellator makes on the exact surface (glsl/tess_evaluation.glsl). Each patch edge
gets the level that keeps its worst segment's deviation from the surface under TARGET_PIXEL_ERROR
pixels on the screen (`edge_level` in the GLSL and its twin), from the edge's two end points
and the surface's radius alone, so that the two patches sharing an edge compute the same level
from the same bits (both end points enter symmetrically) and no crack opens between them. A
flat surface (radius 0) gets level 1: it needs no tessellation.

The level of an edge of chord c on a sphere of radius R (world units), seen at clip w = w_mid at
the edge's midpoint (pixels per world unit there: k = H P11 / (2 w_mid), H the viewport's height,
P11 the projection's [1][1]): the tessellator cuts the chord into L equal parts (equal spacing;
the fractional spacings' parts are no longer), the evaluation stage projects each part's points
onto the sphere, and the middle part, at distance d = sqrt(R^2 - c^2 / 4) from the centre, is the
longest arc: half its angle is atan(c / (2 L d)). Its sagitta R (1 - cos(half angle)) stays under
e = TARGET / k when half its angle is at most acos(1 - s), s = e / R, i.e. when

    L >= c (1 - s) / (2 d sqrt(s (2 - s)))          (tan(acos x) = sqrt(1 - x^2) / x)

written with +, -, *, / and sqrt alone, which llvmpipe rounds as IEEE float32 does, so that the
twin's levels are the GPU's bit for bit. Clamped to [1, MAX_LEVEL]; s >= 1 (an error as large as
the sphere) gives 1; an edge whose midpoint is at or behind the eye (w_mid <= 0) gets MAX_LEVEL.
The inner level is the largest of the three outer ones.

PN triangles (Vlachos, Peters, Boyd and Mitchell 2001, "Curved PN Triangles"): a mesh object
is drawn from its own triangles as patches, each a cubic Bezier triangle made from its corners'
positions P and normals N alone. Written as the flat triangle plus offsets (the flat triangle's
cubic net is its linear interpolation): the edge point of the net near corner a on the edge to
corner b moves by o_ab = N_a (-(P_b - P_a).N_a / 3) (the paper's b_210 = (2 P_1 + P_2 - w_12 N_1) / 3),
the centre by c = (sum of the six o) / 4 (b_111 = E + (E - V) / 2), so that

    p(t) = flat(t) + sum over edges (a, b) of 3 (t_a t_b) (t_a o_ab + t_b o_ba) + 6 (t_0 t_1 t_2) c

and the normal is the paper's quadratic: N_0 t_0^2 + N_1 t_1^2 + N_2 t_2^2 + the edges' mid
normals n_ab t_a t_b, n_ab = normalize(N_a + N_b - v_ab (P_b - P_a)),
v_ab = 2 (P_b - P_a).(N_a + N_b) / |P_b - P_a|^2, normalised. On an edge only that edge's
term is not zero, and each term is written so that both patches of the edge compute it from the
same bits (products and sums of two commute), so the shared edge is the same curve, point for
point, and no crack opens. Where the mesh's vertices split at a crease (the two faces of an edge
see other normals at its ends), the edge is kept straight in both (`pn_patches`: o_ab = o_ba =
0): each side's normals would bend it its own way.

An edge's level bounds the distance of its curve from the chords between the tessellator's
points: its cubic's control points' second differences d_a = o_ba - 2 o_ab, d_b = o_ab - 2 o_ba
(in world units: the model matrix times them, an affine map's) bound the curve's second
derivative by 6 max(|d_a|, |d_b|), and a chord over a parameter interval h strays at most h^2/8
of that from the curve: within e world units (e = target / k, as above) when

    L >= sqrt(PN_CURVE_BOUND max(|d_a|, |d_b|) / e),        PN_CURVE_BOUND = 6 / 8

from the edge's two ends alone, symmetrically (d_a and d_b swap with the ends). The inner level
is at least the outer ones and the interior's own need: the net's second differences across the
patch, (o_ik + o_jk) - 2 c for each corner k, at the patch centre's k.

Displacement (a mesh with `displacement`: `Displacement`): each point the tessellator makes on
a mesh's triangle is moved along the triangle's interpolated normal by S h, h the red channel
of a height image at the point's interpolated lookup coordinates (st = uv * uv_scale +
uv_offset at the corners; textureLod at level 0, bilinear, clamped to the edge), S the scale in
object units. Its normal is the displaced surface's: the cross product
of the displaced surface's UV tangents, T_s + N S dh/ds and T_t + N S dh/dt (T_s, T_t the
triangle's dP/ds and dP/dt, made once a patch; dh/ds, dh/dt central differences a texel apart).
An edge's level: the height changes by at most g (DISPLACEMENT_SLOPE: the largest difference
between neighbouring texels) a texel, so across a part of k texels the surface strays from the
chord by at most k g S_w / 2 (S_w: S in world units, the model matrix times the ends' normals,
the larger): within e when the edge's T texels (the larger of |ds| W and |dt| H) are cut into

    L >= T g S_w / (2 e),            L <= T (a part per texel)

parts, clamped to [1, MAX_LEVEL]: the chords then stay within e, or where a part per texel
caps L, within g S_w / 2 (the image holds nothing finer than its texels; a finer cut would
follow the bilinear creases between them at many times the cost); both ends enter symmetrically (no crack: the point, its UV,
its height and its normal are the same from both patches of an edge). The inner level is the
largest outer one.

What a scene asks for (`Tessellation`, an object's `tessellation` table in a scene file): an
analytic sphere drawn from PATCH_SUBDIVISIONS' icosphere as triangle patches, or a mesh's
triangles as PN triangles, or displaced by a height image, in the camera pass (the shadow passes
draw the sphere's own icosphere, the mesh as it is).
"""

from __future__ import annotations

import dataclasses
import functools
from dataclasses import dataclass

import numpy as np

from renderer.core.mesh_cache import per_mesh
from renderer.core.scene import Sphere
from renderer.core.shapes import sphere_mesh
from renderer.core.textures import Sampler, Texture

TARGET_PIXEL_ERROR = 0.25        # pixels: the target of the geometric error on screen
# The edges' sagitta is held to this share of the target: a triangle's interior dips deeper than
# its edges (an equilateral one's circumcentre by 4/3 of its edges' midpoints' sagitta, the
# tessellator's transition triangles more; benchmarks/bench_tessellation.py measures the
# triangles' deepest points against the target).
EDGE_ERROR_SHARE = 0.5
MAX_LEVEL = 64.0                 # GL_MAX_TESS_GEN_LEVEL's least value, llvmpipe's
SPACINGS = ("equal_spacing", "fractional_even_spacing", "fractional_odd_spacing")
DEFAULT_SPACING = "fractional_odd_spacing"   # levels change smoothly as the camera moves
PATCH_SUBDIVISIONS = 1           # a tessellated sphere's patches: icosphere(1), 80 triangles
SPACING_WORDS = {"equal": "equal_spacing", "fractional_even": "fractional_even_spacing",
                 "fractional_odd": "fractional_odd_spacing"}
# What the evaluation stage places the points on: an analytic sphere's exact surface, or a
# mesh's PN triangles (the object's kind decides: `surface_of`).
SURFACES = ("sphere", "pn_triangles", "displaced")
PN_CURVE_BOUND = 0.75            # 6 / 8: |B''| <= 6 max second difference; a chord strays h^2 / 8 of it
ONE_THIRD = 1.0 / 3.0            # o_ab's factor, multiplied (float32 0.33333334), not divided

# llvmpipe 22.3.6 (reference/tessellation/tessellator.py): a draw's patches are cut into runs
# of 4096 input vertices whose points share uint16 element indices, so a run must make at most
# 65,536 points. A triangle patch's levels round up to at most an even n = 2k, whose
# tessellation has 3 k (k + 1) + 1 points (k rings of 6 j points about the centre; an odd
# 2k - 1 has 3 k^2), at most 3,169 at level 64 (tests/test_tessellation_raster.py holds the
# bound to the tessellator's twin).
MAX_RUN_POINTS = 1 << 16


def max_triangle_points(level: float = MAX_LEVEL) -> int:
    k = int(-(-level // 2))
    return 3 * k * (k + 1) + 1


def patches_per_draw(max_level: float = MAX_LEVEL) -> int:
    """Triangle patches one draw call may hold so that no run wraps its element indices."""
    return max(1, MAX_RUN_POINTS // max_triangle_points(max_level))


@dataclass(frozen=True)
class Tessellation:
    """An object's tessellation (the scene file's `tessellation` table): the spacing, and
    either the target error in pixels (the levels by need, the rule above) or a fixed `level`
    on every edge and inside (None: by need)."""
    spacing: str = DEFAULT_SPACING
    error: float = TARGET_PIXEL_ERROR
    level: float | None = None
    surface: str = "sphere"      # SURFACES: what the points are placed on
    displacement: "Displacement | None" = None


# The height image's sampler: bilinear at level 0 (textureLod(u_height, st, 0)), clamped
DISPLACEMENT_SAMPLER = Sampler(wrap="clamp", filter="bilinear")


@dataclass(frozen=True)
class Displacement:
    """A mesh displaced along its normals by `scale` (object units) times a height image's red
    channel (linear, 0 to 1) at its UVs."""
    texture: Texture
    scale: float
    uv_scale: tuple = (1.0, 1.0)     # the lookup at st = uv * uv_scale + uv_offset (as a texture's)
    uv_offset: tuple = (0.0, 0.0)

    @functools.cached_property
    def slope(self) -> float:
        """g: the largest difference between the heights of two texels side by side (0 to 1),
        worked out once (every frame's uniforms read it)."""
        return displacement_slope(self.texture)


def displacement_slope(texture: Texture) -> float:
    """The largest |h(i + 1) - h(i)| between neighbouring texels of level 0's red channel, in
    float32 heights (texel / 255)."""
    red = texture.levels[0][..., 0].astype(np.float32) / np.float32(255)
    across = np.abs(np.diff(red, axis=1)).max(initial=0.0)
    down = np.abs(np.diff(red, axis=0)).max(initial=0.0)
    return float(max(across, down))


def surface_of(obj) -> str:
    """What a tessellated object's points are placed on: its analytic sphere, its mesh
    displaced by a height image, or its mesh's PN triangles."""
    if isinstance(obj.shape, Sphere):
        return "sphere"
    return "displaced" if obj.tessellation is not None and obj.tessellation.displacement else "pn_triangles"


@dataclass(frozen=True)
class PatchNet:
    """A mesh's PN-triangle patches as the camera pass draws them, a patch per face, its
    corners in the face's order: positions and normals (P, 3, 3) float32 object space, and
    `straight` (P, 3) float32, 1.0 where the edge opposite that corner is kept straight."""
    positions: np.ndarray
    normals: np.ndarray
    straight: np.ndarray

    @property
    def count(self) -> int:
        return len(self.positions)


@per_mesh
def displaced_patches(mesh):
    """A displaced mesh's patches, a patch per face, its corners in the face's order:
    positions, normals (P, 3, 3) and UVs (P, 3, 2), float32 object space."""
    faces = np.asarray(mesh.faces, np.int64)
    return tuple(np.asarray(values, np.float32)[faces] for values in (mesh.positions, mesh.normals, mesh.uvs))


@per_mesh
def pn_patches(mesh) -> PatchNet:
    """A patch per face of `mesh` (module docstring), made once per Mesh. An edge is kept
    straight where another face meets it whose corners there have the same positions but other
    normals (a crease the mesh splits its vertices at) or where more than two faces meet (no
    surface to follow); an edge on the mesh's border, or shared with the same normals, is
    curved."""
    faces = np.asarray(mesh.faces, np.int64)
    positions = np.asarray(mesh.positions, np.float32)
    normals = np.asarray(mesh.normals, np.float32)
    # each face's edges: edge k joins corners k + 1 and k + 2 (GL's outer level k's edge)
    ends = np.stack([faces[:, [1, 2]], faces[:, [2, 0]], faces[:, [0, 1]]], axis=1).reshape(-1, 2)
    # an edge by its ends' positions (their exact bits: a position's number), in either order
    _, place = np.unique(positions.view(np.uint32), axis=0, return_inverse=True)
    place = place.reshape(-1)[ends]
    swap = place[:, 0] > place[:, 1]
    first = np.where(swap, ends[:, 1], ends[:, 0])
    second = np.where(swap, ends[:, 0], ends[:, 1])
    _, edge, uses = np.unique(np.sort(place, axis=1), axis=0, return_inverse=True, return_counts=True)
    edge = edge.reshape(-1)
    # a crease: the edge's faces see more than one pair of normals at its ends
    seen = np.concatenate([edge[:, None], normals[first].view(np.uint32), normals[second].view(np.uint32)], axis=1)
    pairs = np.unique(seen, axis=0)
    creased = np.bincount(pairs[:, 0].astype(np.int64), minlength=len(uses)) > 1
    straight = (creased | (uses > 2))[edge].reshape(-1, 3).astype(np.float32)
    return PatchNet(positions[faces], normals[faces], straight)


def patch_mesh(sphere):
    """The coarse patches a tessellated sphere is drawn from: icosphere(PATCH_SUBDIVISIONS) of
    the sphere, its corners on the surface (renderer/core/shapes.py sphere_mesh)."""
    return sphere_mesh(sphere, PATCH_SUBDIVISIONS)


def check_tessellated(obj) -> None:
    """A ValueError naming `obj` where its tessellation asks for what the stages do not draw
    yet: an analytic shape other than a sphere (a plane is flat: it needs none), a texture (the
    sphere's UV seam; a mesh's UVs across the patches), a mesh's shadow maps looked up (they
    hold its flat triangles, which a PN surface's folds or a displaced bump rise above and dip
    below). The scene file refuses the same in one line."""
    if obj.tessellation is None:
        return
    if obj.shape is not None and not isinstance(obj.shape, Sphere):
        raise ValueError(f"object {obj.name!r}: a plane is flat; only a sphere or a mesh is tessellated")
    if obj.tessellation.surface == "displaced" and obj.mesh.uvs is None:
        raise ValueError(f"object {obj.name!r}: a displaced mesh needs texture coordinates")
    if obj.tessellation.surface != surface_of(obj):
        raise ValueError(f"object {obj.name!r}: its tessellation's surface is "
                         f"{obj.tessellation.surface!r}, its kind's {surface_of(obj)!r}")
    if obj.material.texture is not None:
        raise ValueError(f"object {obj.name!r}: a tessellated object cannot be textured yet")
    if obj.receives_shadows and obj.tessellation.surface != "sphere":
        raise ValueError(f"object {obj.name!r}: a tessellated mesh does not look shadow maps up "
                         f"yet (receives_shadows = false)")


def with_tessellated_spheres(scene, error: float = TARGET_PIXEL_ERROR):
    """A copy of `scene` whose analytic spheres that ask for no tessellation and carry no
    texture are drawn through the tessellation stages with levels by need at `error` pixels
    (`renderer compare --methods --tessellate`), and how many they are."""
    chosen = [isinstance(o.shape, Sphere) and o.tessellation is None and o.material.texture is None
              for o in scene.objects]
    objects = [dataclasses.replace(o, tessellation=Tessellation(error=error)) if pick else o
               for o, pick in zip(scene.objects, chosen)]
    return dataclasses.replace(scene, objects=objects), sum(chosen)
