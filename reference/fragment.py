"""# Twin: glsl/fragment.glsl

Per-fragment shading, run only for the fragment that survived the depth test at each pixel
(there is no blending, so deferring it changes nothing).

- flat:    out_color = gl_FrontFacing ? f_color_front : f_color_back (flat varyings from
           the geometry stage);
- gouraud: out_color = gl_FrontFacing ? v_color_front : v_color_back, interpolated;
- phong:   N = normalize_or_zero(v_world_normal); N = -N for a two-sided material seen from the
           back; out_color = lighting(v_world_position, N).
When the object receives shadows and the frame has maps (SHADOW_MAPS), each light's term is
multiplied by its shadow-map visibility (reference/shadow/lookup.py) at the fragment's
interpolated world position P with the lit normal N (flipped for a two-sided back face):
Phong as above; flat with P from f_world_position, its face normal and the triangle's terms
(f_ambient, f_*_terms_*), Gouraud with normalize_or_zero(v_world_normal) and the vertices'
terms interpolated (v_ambient, v_*_terms_*), of the
side seen: out_color = ambient + sum_l visibility_l term_l, no lookup where a term is 0.
A textured material (TEXTURED) looks its texel up at the fragment's UV (reference/texture.py;
a mipmapped sampler's level of detail from the UVs at the fragment's quad reference pixels,
its triangle's planes evaluated there whether it covers them or not): Phong lights with the
modulated coefficients times the texel (MaterialUniforms.with_factors); flat and Gouraud add
their two parts (reference/vertex.py) as other + modulated * texel, the colours or, with
SHADOW_MAPS, the ambient term and each light's term (LightTerms.modulated).
Alpha is 1. Also out_view_depth, the interpolated -z_eye, for the depth image.

Inputs:  `ObjectVaryings` (the vertex and geometry stage outputs of one object, its faces
         and material), and per fragment: triangle (N,) int64 index into the object's
         faces, weights (N, 3) perspective-correct weights of that triangle's vertices,
         gl_FrontFacing (N,) bool; for a textured material also gl_FragCoord (N, 2), the
         pixel's centre in window coordinates, and the viewport's (width, height).
Outputs: out_color (N, 4) and out_view_depth (N,), in the pipeline's dtype, and the shadow
         ties: None, or (tied (N,) bool, out_color (N, 4) with tied shadow-map taps decided
         the other way) (reference/shadow/lookup.py, "Ties").
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from reference.geometry import TriangleOutputs
from reference.lighting import (LightTerms, Lights, MaterialUniforms, dot, light_terms, lighting, modulated,
                                normalize_or_zero)
from reference.rasterizer import perspective_weights_at
from reference.sampler import quad_reference
from reference.shadow.lookup import FragmentShadows, ShadowMaps
from reference.texture import material_texel
from reference.vertex import VertexOutputs
from renderer.core.facets import CREASE_CAP, face_normals


@dataclass
class ObjectVaryings:
    material: object
    faces: np.ndarray                  # (T, 3) int64
    vertices: VertexOutputs
    triangles: TriangleOutputs | None  # flat shading only
    receives_shadows: bool = False
    displace_lookup: object = None     # a check's displacement of the texture lookup (reference/texture.py)
    index: int = -1                    # the object's index in the scene (the shadow masks')
    facet_normals: np.ndarray | None = None  # (T, 3) world facet normals as wound (a receiver)
    creases: np.ndarray | None = None  # (T, 2) its faces' creases (facets.py; None: an analytic shape)


def interpolate(varying: np.ndarray, faces: np.ndarray, triangle: np.ndarray,
                weights: np.ndarray) -> np.ndarray:
    """sum_j weights[:, j] * varying[faces[triangle, j]] for per-vertex varyings (V, ...)."""
    corners = faces[triangle]                                    # (N, 3) vertex indices
    w = weights.reshape(weights.shape + (1,) * (varying.ndim - 1))
    return (w[:, 0] * varying[corners[:, 0]] + w[:, 1] * varying[corners[:, 1]]
            + w[:, 2] * varying[corners[:, 2]])


def select_by_facing(gl_FrontFacing: np.ndarray, front: np.ndarray, back: np.ndarray) -> np.ndarray:
    """gl_FrontFacing ? front : back, per fragment."""
    return np.where(gl_FrontFacing[:, None], front, back)


def lit_point(obj: ObjectVaryings, triangle: np.ndarray, weights: np.ndarray,
              gl_FrontFacing: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """(P, N) a fragment is lit at (Phong) or looks its shadows up at (every mode): P
    interpolated (flat: from its triangle's corners, the geometry stage's), N the renormalised
    interpolated normal (flat: the face normal), flipped for a two-sided back face."""
    vertices, faces = obj.vertices, obj.faces
    if obj.material.shading == "flat":
        corners = obj.triangles.f_world_position[triangle]                   # (N, 3, 3)
        P = (weights[:, 0:1] * corners[:, 0] + weights[:, 1:2] * corners[:, 1]
             + weights[:, 2:3] * corners[:, 2])
        N = obj.triangles.f_face_normal[triangle]
    else:
        P = interpolate(vertices.v_world_position, faces, triangle, weights)
        N = normalize_or_zero(interpolate(vertices.v_world_normal, faces, triangle, weights))
    if obj.material.two_sided:
        N = np.where(gl_FrontFacing[:, None], N, -N)
    return P, N


def facet_normal(obj: ObjectVaryings, triangle: np.ndarray, N: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """((N, 3), (N,)): the fragments' facet normals on the side N lights and their facets'
    creases on that side, as glsl/fragment.glsl sets shadow_facet_normal and shadow_crease:
    the face's world normal as wound (obj.facet_normals: world_facet_normals), turned to N's
    side (flat: its geometry stage's face normal, N itself), and the crease of that side; an
    analytic shape's (no creases: its triangles only stand in for it) N, and for crease how
    steeply its facet tilts off N (tan of the angle, up to CREASE_CAP)."""
    if obj.facet_normals is None:
        return N, np.zeros(len(N), N.dtype)
    wound = obj.facet_normals[triangle]
    lit_side = dot(wound, N)[:, 0] >= 0.0
    if obj.creases is None:                   # an analytic shape: N, its facet's tilt off N
        c = np.abs(dot(wound, N)[:, 0])
        cap = N.dtype.type(CREASE_CAP)
        with np.errstate(divide="ignore", invalid="ignore"):
            tilt = np.where(c > 0.0, np.minimum(np.sqrt(np.maximum(1 - c * c, 0)) / c, cap), cap)
        return N, tilt.astype(N.dtype)
    crease = np.where(lit_side, obj.creases[triangle, 0], obj.creases[triangle, 1]).astype(N.dtype)
    facet = N if obj.material.shading == "flat" else np.where(lit_side[:, None], wound, -wound)
    return facet, crease


def world_facet_normals(mesh, u_normal_matrix: np.ndarray, dtype) -> np.ndarray:
    """(T, 3) the faces' world unit normals as the GLSL computes them: the float32 object-space
    face normals (renderer/core/facets.py) through the normal matrix, renormalised, in dtype."""
    n = face_normals(mesh).astype(dtype)
    return normalize_or_zero(n @ np.asarray(u_normal_matrix, dtype).T)


def fragment_texel(obj: ObjectVaryings, triangle: np.ndarray, weights: np.ndarray,
                   gl_FragCoord: np.ndarray, viewport: tuple[int, int]) -> np.ndarray:
    """material_texel(UV) (N, 3) of a textured object's fragments: the UV interpolated at
    each fragment (flat: f_uv, from its triangle's corners) and, for a mipmapped sampler, at
    its quad's reference pixels from the same triangle's planes."""
    texture = obj.material.texture
    if obj.material.shading == "flat":
        corners = obj.triangles.f_uv[triangle]                               # (N, 3, 2)
        at = lambda w: np.einsum("nk,nkc->nc", w, corners)                  # noqa: E731
    else:
        at = lambda w: interpolate(obj.vertices.v_uv, obj.faces, triangle, w)   # noqa: E731
    uv_quad = None
    if texture.sampler.mipmapped:
        clip = obj.vertices.gl_Position[obj.faces[triangle]]                 # (N, 3, 4)
        uv_quad = np.stack([at(perspective_weights_at(clip, x, y, *viewport))
                            for x, y in quad_reference(gl_FragCoord[:, 0], gl_FragCoord[:, 1])])
    return material_texel(texture, at(weights), uv_quad, obj.displace_lookup)


def shade_fragments(obj: ObjectVaryings, triangle: np.ndarray, weights: np.ndarray,
                    gl_FrontFacing: np.ndarray, lights: Lights, u_eye: np.ndarray,
                    shadows: ShadowMaps | None = None, *, gl_FragCoord: np.ndarray | None = None,
                    viewport: tuple[int, int] | None = None):
    """The fragment stage for one object's surviving fragments -> (out_color, out_view_depth,
    shadow ties or None). `shadows`: the frame's maps, or None (no SHADOW_MAPS).
    `gl_FragCoord` and `viewport`: a textured material's only."""
    material, faces, vertices = obj.material, obj.faces, obj.vertices
    dtype = vertices.gl_Position.dtype
    if material.shading not in ("flat", "gouraud", "phong"):
        raise ValueError(f"unknown shading mode {material.shading!r}")
    shadowed = shadows is not None and obj.receives_shadows
    texel = (None if material.texture is None
             else fragment_texel(obj, triangle, weights, gl_FragCoord, viewport))
    tie = None
    if material.shading == "flat" and not shadowed:
        side = lambda front, back: select_by_facing(                       # noqa: E731
            gl_FrontFacing, front[triangle], back[triangle])
        color = _with_texel(side(obj.triangles.f_color_front, obj.triangles.f_color_back),
                            lambda: side(obj.triangles.f_modulated_front, obj.triangles.f_modulated_back),
                            texel)
    elif material.shading == "gouraud" and not shadowed:
        side = lambda front, back: select_by_facing(                       # noqa: E731
            gl_FrontFacing, interpolate(front, faces, triangle, weights),
            interpolate(back, faces, triangle, weights))
        color = _with_texel(side(vertices.v_color_front, vertices.v_color_back),
                            lambda: side(vertices.v_modulated_front, vertices.v_modulated_back),
                            texel)
    else:
        P, N = lit_point(obj, triangle, weights, gl_FrontFacing)
        E, uniforms = np.asarray(u_eye, dtype=dtype), MaterialUniforms.from_material(material, dtype)
        if texel is not None and material.shading == "phong":
            uniforms = uniforms.with_factors(modulated(material), texel, 1.0)
        if not shadowed:
            color = lighting(P, N, E, uniforms, lights)
        else:
            terms = _terms_of_side(obj, triangle, weights, gl_FrontFacing, P, N, E, uniforms, lights,
                                   texel)
            # the tie bands' scale: GL interpolates P from these vertices (lookup.py, SHADOW_TIE)
            scale = np.abs(vertices.v_world_position[faces[triangle]]).max(axis=(1, 2))
            facet, crease = facet_normal(obj, triangle, N)
            look = FragmentShadows(shadows, scale, facet, obj.index, crease)
            color = terms.shade(P, N, look.visibility)
            tied = look.tied
            if tied is not None and tied.any():
                other = terms.shade(P, N, look.alternative)
                tie = (tied, np.concatenate([other, np.ones((len(other), 1), dtype=dtype)], axis=1))
    out_color = np.concatenate([color, np.ones((len(color), 1), dtype=dtype)], axis=1)
    out_view_depth = interpolate(vertices.v_view_depth, faces, triangle, weights)
    return out_color, out_view_depth, tie


def _with_texel(color: np.ndarray, modulated_color, texel: np.ndarray | None) -> np.ndarray:
    """Flat and Gouraud's colour: other + modulated * texel for a textured material (the
    modulated part's colour from the callable), else the colour as it is."""
    return color if texel is None else color + modulated_color() * texel


def _terms_of_side(obj: ObjectVaryings, triangle, weights, gl_FrontFacing, P, N, E, uniforms,
                   lights, texel=None) -> LightTerms:
    """The lighting's terms at the fragments, of the side seen: Phong lights P with N here;
    flat takes its triangle's (flat varyings), Gouraud interpolates its vertices', and adds
    their parts up at the texel when textured."""
    if obj.material.shading == "phong":
        return light_terms(P, N, E, uniforms, lights)
    if obj.material.shading == "flat":
        at = lambda a: a[triangle]                                            # noqa: E731
        varyings, modulated_ambient = obj.triangles, obj.triangles.f_modulated_ambient
    else:
        at = lambda a: interpolate(a, obj.faces, triangle, weights)           # noqa: E731
        varyings, modulated_ambient = obj.vertices, obj.vertices.v_modulated_ambient
    front, back = (varyings.light_terms(side).map(at) for side in (False, True))
    if texel is not None:
        front, back = (terms.modulated(at(modulated_ambient), texel) for terms in (front, back))
    return front.where(gl_FrontFacing, back) if obj.material.two_sided else front
