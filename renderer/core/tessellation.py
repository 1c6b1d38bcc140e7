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

What a scene asks for (`Tessellation`, an object's `tessellation` table in a scene file): an
analytic sphere drawn from PATCH_SUBDIVISIONS' icosphere as triangle patches, in the camera
pass (the shadow passes draw the sphere's own icosphere, renderer/core/shapes.py).
"""

from __future__ import annotations

from dataclasses import dataclass

from renderer.core.scene import Sphere
from renderer.core.shapes import sphere_mesh

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


def patch_mesh(sphere):
    """The coarse patches a tessellated sphere is drawn from: icosphere(PATCH_SUBDIVISIONS) of
    the sphere, its corners on the surface (renderer/core/shapes.py sphere_mesh)."""
    return sphere_mesh(sphere, PATCH_SUBDIVISIONS)


def check_tessellated(obj) -> None:
    """A ValueError naming `obj` where its tessellation asks for what the stages do not draw
    yet: a shape other than an analytic sphere, a texture (the sphere's UV seam), shadow maps
    looked up (their facets are the patches'). The scene file refuses the same in one line."""
    if obj.tessellation is None:
        return
    if not isinstance(obj.shape, Sphere):
        raise ValueError(f"object {obj.name!r}: only an analytic sphere is tessellated yet")
    if obj.material.texture is not None:
        raise ValueError(f"object {obj.name!r}: a tessellated sphere cannot be textured yet")
    if obj.receives_shadows:
        raise ValueError(f"object {obj.name!r}: a tessellated sphere does not look shadow maps up "
                         f"yet (receives_shadows = false)")
