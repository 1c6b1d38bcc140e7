"""# Twin: glsl/vertex.glsl

Vertex processing for one object: world position, world normal (normal matrix, then
renormalised), clip position gl_Position = P V M p, the camera-space depth -z_eye, and for
Gouraud materials the per-vertex lit colours (front with N, back with -N when two-sided).
A textured material (TEXTURED) hands its UVs on, and Gouraud lights it in two parts
(reference/lighting.py, lit_parts): the colours and terms below are OTHER_PART's, the
v_modulated_* MODULATED_PART's, and each light's term has a row of each part.

Inputs:  in_position (V, 3) and in_normal (V, 3) from the Mesh (float64, cast to `dtype`),
         in_uv (V, 2) (its UVs: a textured material's only, else None);
         u_model (4, 4), u_normal_matrix (3, 3), u_view (4, 4), u_projection (4, 4),
         u_eye (3,), the material and the packed lights.
Outputs: `VertexOutputs`, every array in `dtype`:
         gl_Position (V, 4)       clip coordinates
         v_world_position (V, 3)  world-space position
         v_world_normal (V, 3)    unit world-space normal
         v_view_depth (V,)        -z_eye, the distance along the viewing axis
         v_uv (V, 2)              in_uv (None unless textured)
         v_color_front (V, 3)     Gouraud colour lit with N        (None unless gouraud)
         v_color_back (V, 3)      Gouraud colour lit with -N       (the front colour when
                                  the material is one-sided; None unless gouraud)
         v_ambient (V, 3), v_directional_terms_front (V, Ld, 3), v_point_terms_front
         (V, Lp, 3), v_*_terms_back (lit with -N; the front's when one-sided): the same
                                  lighting kept apart (`LightTerms`), whose sums the colours
                                  are: what a Gouraud receiver of shadows hands on
                                  (SHADOW_MAPS); None unless gouraud (textured: 2 Ld and 2 Lp
                                  rows, `stacked_parts`)
         v_modulated_ambient (V, 3), v_modulated_front (V, 3), v_modulated_back (V, 3):
                                  MODULATED_PART's ambient term and colours (None unless
                                  Gouraud and textured)
Every output is an affine function of the vertex in clip space or is interpolated as one,
so clipping and perspective-correct interpolation treat them all alike.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from reference.lighting import HandsOnLighting, Lights, hand_on_lighting, normalize_or_zero


@dataclass
class VertexOutputs(HandsOnLighting):
    PREFIX = "v_"
    gl_Position: np.ndarray
    v_world_position: np.ndarray
    v_world_normal: np.ndarray
    v_view_depth: np.ndarray
    v_color_front: np.ndarray | None = None
    v_color_back: np.ndarray | None = None
    v_ambient: np.ndarray | None = None
    v_directional_terms_front: np.ndarray | None = None
    v_directional_terms_back: np.ndarray | None = None
    v_point_terms_front: np.ndarray | None = None
    v_point_terms_back: np.ndarray | None = None
    v_uv: np.ndarray | None = None
    v_modulated_ambient: np.ndarray | None = None
    v_modulated_front: np.ndarray | None = None
    v_modulated_back: np.ndarray | None = None


def transform_points(matrix: np.ndarray, points: np.ndarray) -> np.ndarray:
    """M p for (V, 3) points taken as (x, y, z, 1); returns (V, 4) homogeneous coordinates."""
    return points @ matrix[:, :3].T + matrix[:, 3]


def shade_vertices(in_position: np.ndarray, in_normal: np.ndarray, in_uv: np.ndarray | None = None,
                   *, u_model: np.ndarray, u_normal_matrix: np.ndarray, u_view: np.ndarray,
                   u_projection: np.ndarray, u_eye: np.ndarray, material, lights: Lights,
                   dtype=np.float64) -> VertexOutputs:
    """Run the vertex stage over all of an object's vertices at once."""
    in_position = np.asarray(in_position, dtype=dtype)
    in_normal = np.asarray(in_normal, dtype=dtype)
    u_model, u_view, u_projection = (np.asarray(m, dtype=dtype) for m in (u_model, u_view, u_projection))
    u_normal_matrix = np.asarray(u_normal_matrix, dtype=dtype)

    world = transform_points(u_model, in_position)                 # (V, 4), w = 1 for affine M
    v_world_position = world[:, :3]
    v_world_normal = normalize_or_zero(in_normal @ u_normal_matrix.T)   # N = normalize(Nm n)
    eye_space = world @ u_view.T                                   # V M p
    gl_Position = eye_space @ u_projection.T                       # P V M p
    v_view_depth = -eye_space[:, 2]

    out = VertexOutputs(gl_Position, v_world_position, v_world_normal, v_view_depth)
    if in_uv is not None:
        out.v_uv = np.asarray(in_uv, dtype=dtype)
    if material.shading == "gouraud":
        out.hand_on(hand_on_lighting(v_world_position, v_world_normal, u_eye, material, lights))
    return out
