"""# Twin: glsl/geometry.glsl

Flat shading: one colour per triangle, lit at the triangle's centroid with the face normal
normalize((p1 - p0) x (p2 - p0)) in world space (vertex order as in the mesh).

A textured material (TEXTURED) passes its vertices' UVs through and is lit in two parts as
Gouraud's (reference/vertex.py): the colours and terms below are OTHER_PART's, the
f_modulated_* MODULATED_PART's, and each light's term has a row of each part.

Inputs:  v_world_position (T, 3, 3) world positions of each triangle's vertices (`dtype`),
         v_uv (T, 3, 2) their UVs (a textured material's only, else None),
         the material, the packed lights and the eye (3,).
Outputs: `TriangleOutputs` in the same dtype:
         f_face_normal (T, 3)   unit face normal
         f_centroid (T, 3)      (p0 + p1 + p2) / 3
         f_color_front (T, 3)   colour lit with the face normal (flat varying)
         f_color_back (T, 3)    colour lit with -normal for a two-sided material, else
                                the front colour; the fragment picks by gl_FrontFacing
         f_world_position (T, 3, 3)  the vertices' world positions, passed on (the
                                fragment interpolates P from them)
         f_ambient (T, 3), f_directional_terms_front (T, Ld, 3), f_point_terms_front
         (T, Lp, 3), f_*_terms_back (lit with -normal; the front's when one-sided): the same
                                lighting kept apart (`LightTerms`), whose sums the colours
                                are: what a flat receiver of shadows hands on (SHADOW_MAPS)
                                (textured: 2 Ld and 2 Lp rows, `stacked_parts`)
         f_uv (T, 3, 2)         v_uv passed on (None unless textured)
         f_modulated_ambient, f_modulated_front, f_modulated_back (T, 3): MODULATED_PART's
                                ambient term and colours (None unless textured)
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from reference.lighting import HandsOnLighting, Lights, hand_on_lighting, normalize_or_zero


@dataclass
class TriangleOutputs(HandsOnLighting):
    PREFIX = "f_"
    f_face_normal: np.ndarray
    f_centroid: np.ndarray
    f_world_position: np.ndarray
    f_color_front: np.ndarray | None = None         # the lighting: shade_triangles hands it on
    f_color_back: np.ndarray | None = None
    f_ambient: np.ndarray | None = None
    f_directional_terms_front: np.ndarray | None = None
    f_directional_terms_back: np.ndarray | None = None
    f_point_terms_front: np.ndarray | None = None
    f_point_terms_back: np.ndarray | None = None
    f_uv: np.ndarray | None = None
    f_modulated_ambient: np.ndarray | None = None
    f_modulated_front: np.ndarray | None = None
    f_modulated_back: np.ndarray | None = None


def face_normal(p0: np.ndarray, p1: np.ndarray, p2: np.ndarray) -> np.ndarray:
    """normalize((p1 - p0) x (p2 - p0)): counter-clockwise vertices face the normal; zero for
    a triangle without area (it draws nothing anyway)."""
    return normalize_or_zero(np.cross(p1 - p0, p2 - p0))


def shade_triangles(v_world_position: np.ndarray, material, lights: Lights,
                    u_eye: np.ndarray, v_uv: np.ndarray | None = None) -> TriangleOutputs:
    """The geometry stage for a flat-shaded object."""
    p0, p1, p2 = v_world_position[:, 0], v_world_position[:, 1], v_world_position[:, 2]
    f_face_normal = face_normal(p0, p1, p2)
    f_centroid = (p0 + p1 + p2) / 3.0
    out = TriangleOutputs(f_face_normal, f_centroid, v_world_position, f_uv=v_uv)
    with np.errstate(invalid="ignore"):
        out.hand_on(hand_on_lighting(f_centroid, f_face_normal, u_eye, material, lights))
    return out
