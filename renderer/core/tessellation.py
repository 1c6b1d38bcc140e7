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
"""

from __future__ import annotations

TARGET_PIXEL_ERROR = 0.25        # pixels: the target of the geometric error on screen
MAX_LEVEL = 64.0                 # GL_MAX_TESS_GEN_LEVEL's least value, llvmpipe's
SPACINGS = ("equal_spacing", "fractional_even_spacing", "fractional_odd_spacing")
DEFAULT_SPACING = "fractional_odd_spacing"   # levels change smoothly as the camera moves
