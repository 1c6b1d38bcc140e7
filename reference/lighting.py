"""# Twin: glsl/lighting.glsl

The lighting equation of docs/conventions.md ("Lighting", section 2.1 of the notes), in
world space, vectorised over any number of surface points:

    I = I_a k_a + sum_l att_l I_l k_d max(N.L, 0) + sum_l att_l I_l k_s spec_l

Inputs:  P (..., 3) surface points and N (..., 3) unit normals in world space, E (3,) the
         eye, a `renderer.core.scene.Material` and the scene's lights packed as `Lights`
         (the GLSL light uniforms, from renderer/core/uniforms.py). Everything in one float dtype.
Output:  I (..., 3) linear RGB in that dtype, unclamped.

`light_terms` keeps the equation's terms apart (`LightTerms`: the ambient term and each
light's term, the GLSL's ambient_term, directional_term and point_term), as flat and Gouraud
receivers of shadows hand them on; lighting() is their sum, one light at a time.

A textured material (the GLSL's TEXTURED) lights its coefficients times factors
(`MaterialUniforms.with_factors`, the GLSL's material_factors): the texel on the coefficients
it modulates (Phong), or each part alone (`MaterialUniforms.part`, material_part: OTHER_PART
the other coefficients, MODULATED_PART the modulated ones), which flat and Gouraud light and
hand on apart (`lit_parts`, `stacked_parts`; LightTerms.modulated adds them up again).
`hand_on_lighting` is what those two stages hand on, and `HandsOnLighting` their outputs that
carry it (v_* and f_*: glsl/lighting.glsl's hand_on_light_terms).

The sides rule (one-sided / two-sided) is not applied here: callers pass the normal that
is to be lit (the vertex, geometry and fragment stages flip it for back faces).
"""

from __future__ import annotations

from dataclasses import dataclass, replace
from typing import ClassVar

import numpy as np

from reference import glsl_builtins
from renderer.core.uniforms import light_uniforms, material_uniforms

# The parts a textured material's flat and Gouraud lighting is handed on in (glsl/lighting.glsl).
OTHER_PART, MODULATED_PART = 0, 1


@dataclass
class Lights:
    """The scene's lights as uniform arrays, named as the GLSL uniforms are, in the pipeline's
    dtype: the layout of renderer/core/uniforms.py (LIGHT_UNIFORMS), which the GPU path
    uploads too.

    u_ambient (3,); directional: u_directional_direction (Ld, 3) (the way the light
    travels) and u_directional_intensity (Ld, 3); point: u_point_position (Lp, 3),
    u_point_intensity (Lp, 3), u_point_attenuation (Lp, 3) as (c, l, q).
    """
    u_ambient: np.ndarray
    u_directional_direction: np.ndarray
    u_directional_intensity: np.ndarray
    u_point_position: np.ndarray
    u_point_intensity: np.ndarray
    u_point_attenuation: np.ndarray

    @classmethod
    def from_scene(cls, scene, dtype=np.float64, origin=(0.0, 0.0, 0.0)) -> "Lights":
        """Point-light positions relative to `origin` (the frame's camera-relative origin),
        subtracted in float64 before the cast to `dtype`."""
        return cls(**{name: value.astype(dtype) for name, value in light_uniforms(scene, origin).items()})


@dataclass
class MaterialUniforms:
    """A material's coefficients as arrays of the pipeline's dtype: k_a, k_d, k_s (3,), n
    (renderer/core/uniforms.py, MATERIAL_UNIFORMS)."""
    u_ka: np.ndarray
    u_kd: np.ndarray
    u_ks: np.ndarray
    u_n: np.ndarray
    specular: bool = True        # False when every k_s is 0: the term is not computed (SPECULAR)

    @classmethod
    def from_material(cls, material, dtype=np.float64) -> "MaterialUniforms":
        return cls(**{name: value.astype(dtype) for name, value in material_uniforms(material).items()},
                   specular=material.has_specular)

    def with_factors(self, modulate, modulated, other) -> "MaterialUniforms":
        """material_factors(modulated, other): each coefficient named in `modulate` ("ka",
        "kd", "ks") times `modulated`, the others times `other` (scalars, (3,) or (N, 3) per
        point)."""
        factor = {k: modulated if k in modulate else other for k in ("ka", "kd", "ks")}
        return replace(self, u_ka=self.u_ka * factor["ka"], u_kd=self.u_kd * factor["kd"],
                       u_ks=self.u_ks * factor["ks"])

    def part(self, modulate, part: int) -> "MaterialUniforms":
        """material_part(part): the coefficients of MODULATED_PART (those in `modulate`) or
        of OTHER_PART (the rest) alone, the others 0."""
        modulated = 1.0 if part == MODULATED_PART else 0.0
        return self.with_factors(modulate, modulated, 1.0 - modulated)



def dot(a: np.ndarray, b: np.ndarray) -> np.ndarray:
    """GLSL dot() of 3-vectors over the last axis (as llvmpipe sums it, glsl_builtins.py), kept
    as length 1 to broadcast against RGB."""
    return glsl_builtins.dot(a, b)[..., None]


def normalize(v: np.ndarray) -> np.ndarray:
    """GLSL normalize() over the last axis (as llvmpipe computes it, glsl_builtins.py)."""
    return glsl_builtins.normalize(v)


def normalize_or_zero(v: np.ndarray) -> np.ndarray:
    """normalize(), except that a zero vector stays zero instead of NaN: a normal that
    vanishes (singular normal matrix, opposite normals interpolated) lights as ambient."""
    length = np.sqrt(dot(v, v))
    return v / np.where(length > 0, length, np.ones_like(length))


def reflect_light(N: np.ndarray, L: np.ndarray, n_dot_l: np.ndarray) -> np.ndarray:
    """R = 2 (N.L) N - L, the perfect reflection of the light vector L about N."""
    return 2.0 * n_dot_l * N - L


def specular_term(n_dot_l: np.ndarray, r_dot_v: np.ndarray, n: np.ndarray) -> np.ndarray:
    """spec = max(R.V, 0)^n where N.L > 0 and R.V > 0, else 0 (pow never sees a base <= 0)."""
    lit = (n_dot_l > 0) & (r_dot_v > 0)
    base = np.where(lit, r_dot_v, np.ones_like(r_dot_v))
    return np.where(lit, np.power(base, n), np.zeros_like(r_dot_v))


def directional_light_vector(direction: np.ndarray) -> np.ndarray:
    """L = normalize(-D) for a light travelling along D; its attenuation is 1."""
    return normalize(-direction)


def point_light_vector(P: np.ndarray, N: np.ndarray, position: np.ndarray, attenuation: np.ndarray):
    """L = (Q - P) / d with d = |Q - P|, and att = 1 / (c + l d + q d^2). Returns (L, att).
    A light on the surface (d = 0) is fully incident: L = N, att = 1 / c."""
    to_light = position - P
    d = np.sqrt(dot(to_light, to_light))
    c, l, q = attenuation
    L = np.where(d > 0, to_light / np.where(d > 0, d, np.ones_like(d)), N)
    return L, 1.0 / (c + l * d + q * d * d)


def light_contribution(N, L, V, att, intensity, material: MaterialUniforms) -> np.ndarray:
    """att I_l (k_d max(N.L, 0) + k_s spec) for one light; the k_s term only when the
    material has one (as the shader's SPECULAR)."""
    n_dot_l = dot(N, L)
    diffuse = material.u_kd * np.maximum(n_dot_l, 0.0)
    if not material.specular:
        return att * intensity * diffuse
    R = reflect_light(N, L, n_dot_l)
    specular = material.u_ks * specular_term(n_dot_l, dot(R, V), material.u_n)
    return att * intensity * (diffuse + specular)


@dataclass
class LightTerms:
    """The lighting equation kept apart, as the shader's terms (glsl/lighting.glsl): the ambient
    term I_a k_a (..., 3) and each light's term att I_l (k_d max(N.L, 0) + k_s spec), the
    directional lights' (..., Ld, 3) and the point lights' (..., Lp, 3), in lighting()'s order.
    Flat and Gouraud receivers of shadows hand these on per triangle or per vertex (the GLSL's
    *_ambient, *_directional_terms_*, *_point_terms_* varyings); the fragment stage weighs each
    light's term by its visibility there."""
    ambient: np.ndarray
    directional: np.ndarray
    point: np.ndarray

    @property
    def terms(self):
        """(kind, i, term (..., 3)) for each light, in lighting()'s order."""
        for kind, stacked in (("directional", self.directional), ("point", self.point)):
            for i in range(stacked.shape[-2]):
                yield kind, i, stacked[..., i, :]

    def map(self, f) -> "LightTerms":
        """The same terms with `f` applied to each array (interpolation, selection by index)."""
        return LightTerms(f(self.ambient), f(self.directional), f(self.point))

    def where(self, condition: np.ndarray, other: "LightTerms") -> "LightTerms":
        """condition (N,) ? self : other, per point."""
        def pick(a, b):
            return np.where(condition.reshape(condition.shape + (1,) * (a.ndim - 1)), a, b)
        return LightTerms(pick(self.ambient, other.ambient), pick(self.directional, other.directional),
                          pick(self.point, other.point))

    def shade(self, P: np.ndarray, N: np.ndarray, visibility=None) -> np.ndarray:
        """I = ambient + sum_l term_l (shade_terms)."""
        return shade_terms(self.ambient, self.terms, P, N, visibility)

    def modulated(self, modulated_ambient: np.ndarray, texel: np.ndarray) -> "LightTerms":
        """Terms stacked by `stacked_parts` added up at a texel (N, 3) (the GLSL's LIGHT_TERM):
        each light's OTHER_PART row plus its MODULATED_PART row times the texel, and the
        ambient term plus `modulated_ambient` times the texel."""
        def add(stacked):
            rows = stacked.shape[-2] // 2
            return stacked[..., :rows, :] + stacked[..., rows:, :] * texel[..., None, :]
        return LightTerms(self.ambient + modulated_ambient * texel, add(self.directional),
                          add(self.point))


def shade_terms(ambient: np.ndarray, terms, P: np.ndarray, N: np.ndarray, visibility=None) -> np.ndarray:
    """I = ambient + sum_l term_l over (kind, i, term) `terms` in order, each term times
    visibility(kind, i, P, N, needed) when given (lighting()'s `visibility`; `needed`: where
    the term is not 0), but an "area" term, which comes shadowed (lighting()'s `area_light`)."""
    I = ambient.astype(ambient.dtype, copy=True)
    for kind, i, term in terms:
        shadowed = visibility is None or kind == "area"
        I += term if shadowed else visibility(kind, i, P, N, (term != 0).any(-1)) * term
    return I


def ambient_term(P: np.ndarray, N: np.ndarray, material: MaterialUniforms, lights: Lights) -> np.ndarray:
    """I_a k_a at each point (the shape P and N broadcast to), in P's dtype (a read-only view)."""
    ambient = np.asarray(lights.u_ambient * material.u_ka).astype(P.dtype)
    return np.broadcast_to(ambient, np.broadcast_shapes(ambient.shape, P.shape, N.shape))


def point_term_at(P, N, V, position, intensity, attenuation, material: MaterialUniforms) -> np.ndarray:
    """A point light's term at P as if it shone from `position` (its position, or a point of
    its area; (3,) or one per point): the GLSL's point_term_at."""
    L, att = point_light_vector(P, N, position, attenuation)
    return light_contribution(N, L, V, att, intensity, material)


def each_light_term(P: np.ndarray, N: np.ndarray, E: np.ndarray, material: MaterialUniforms,
                    lights: Lights, area_light=None):
    """(kind, i, term) for each light, one at a time, in lighting()'s order (glsl/lighting.glsl:
    directional_term, point_term; lit_point: ("area", i, area_light's term) for a point light
    with an area, when `area_light` is given)."""
    V = normalize_or_zero(E - P)
    for i, (direction, intensity) in enumerate(zip(lights.u_directional_direction,
                                                   lights.u_directional_intensity)):
        L = directional_light_vector(direction)
        yield "directional", i, light_contribution(N, L, V, 1.0, intensity, material)
    for i, (position, intensity, attenuation) in enumerate(zip(
            lights.u_point_position, lights.u_point_intensity, lights.u_point_attenuation)):
        area = None if area_light is None else area_light(i, P, N, V, material)
        if area is not None:
            yield "area", i, area
        else:
            yield "point", i, point_term_at(P, N, V, position, intensity, attenuation, material)


def light_terms(P: np.ndarray, N: np.ndarray, E: np.ndarray, material: MaterialUniforms,
                lights: Lights) -> LightTerms:
    """The ambient term and every light's term at points P (..., 3) with unit normals N
    (..., 3), kept. E and the material's arrays may vary per point (broadcast against P)."""
    ambient = ambient_term(P, N, material, lights)
    stacked = {"directional": [], "point": []}
    for kind, _, term in each_light_term(P, N, E, material, lights):
        stacked[kind].append(np.broadcast_to(term, ambient.shape))
    empty = np.zeros(ambient.shape[:-1] + (0, 3), P.dtype)
    return LightTerms(ambient, *(np.stack(terms, axis=-2) if terms else empty
                                 for terms in stacked.values()))


def lit_parts(P: np.ndarray, N: np.ndarray, E: np.ndarray, material: MaterialUniforms,
              lights: Lights, modulate=()) -> list[LightTerms]:
    """What flat and Gouraud light at P with N: light_terms of the material, or, when a
    texture modulates the coefficients in `modulate`, of each part alone, indexed by part
    (OTHER_PART, MODULATED_PART)."""
    if not modulate:
        return [light_terms(P, N, E, material, lights)]
    return [light_terms(P, N, E, material.part(modulate, part), lights)
            for part in (OTHER_PART, MODULATED_PART)]


def side_colors(front: list[LightTerms], back: list[LightTerms], P: np.ndarray, N: np.ndarray,
                two_sided: bool, part: int = OTHER_PART) -> tuple[np.ndarray, np.ndarray]:
    """One part's colours (lit_parts' sums) lit with N and with -N: (front, back); the back
    is the front's when the material is one-sided."""
    lit_front = front[part].shade(P, N)
    return lit_front, (back[part].shade(P, -N) if two_sided else lit_front)


def stacked_parts(parts: list[LightTerms]) -> LightTerms:
    """The terms a receiver of shadows hands on: OTHER_PART's ambient term, and each kind's
    lights' terms part after part (TERM_PARTS rows a light: (..., parts x L, 3))."""
    return LightTerms(parts[OTHER_PART].ambient,
                      np.concatenate([p.directional for p in parts], axis=-2),
                      np.concatenate([p.point for p in parts], axis=-2))


def modulated(material) -> tuple:
    """The coefficients `material`'s texel modulates; empty without a texture."""
    return () if material.texture is None else tuple(material.texture.modulate)


def hand_on_lighting(P: np.ndarray, N: np.ndarray, u_eye: np.ndarray, material,
                     lights: Lights) -> dict[str, np.ndarray]:
    """What flat and Gouraud hand on of the lighting at points P (..., 3) with unit normals N
    (..., 3) for `material` (a renderer.core.scene.Material), in P's dtype (the GLSL's
    keep_light_terms and hand_on_light_terms; without shadow maps the colours, the terms'
    sums), by the stage outputs' names without their prefix (v_ in reference/vertex.py, f_ in
    reference/geometry.py): the ambient term and the terms stacked by part (`stacked_parts`),
    and the colours, each lit with N and, two-sided, with -N (else the back's are the
    front's); with a texture, MODULATED_PART's ambient term and colours (modulated_*)."""
    uniforms = MaterialUniforms.from_material(material, P.dtype)
    eye = np.asarray(u_eye, dtype=P.dtype)
    modulate = modulated(material)
    front = lit_parts(P, N, eye, uniforms, lights, modulate)
    back = lit_parts(P, -N, eye, uniforms, lights, modulate) if material.two_sided else front
    colors = [side_colors(front, back, P, N, material.two_sided, part) for part in range(len(front))]
    stacked = {"front": stacked_parts(front), "back": stacked_parts(back)}
    lit = {"ambient": stacked["front"].ambient}
    for side, terms in stacked.items():
        lit[f"directional_terms_{side}"], lit[f"point_terms_{side}"] = terms.directional, terms.point
    lit["color_front"], lit["color_back"] = colors[OTHER_PART]
    if modulate:
        lit["modulated_ambient"] = front[MODULATED_PART].ambient
        lit["modulated_front"], lit["modulated_back"] = colors[MODULATED_PART]
    return lit


class HandsOnLighting:
    """A stage's outputs that carry hand_on_lighting's, each as PREFIX + its name
    (VertexOutputs' v_*, TriangleOutputs' f_*)."""
    PREFIX: ClassVar[str] = ""

    def hand_on(self, lit: dict[str, np.ndarray]) -> None:
        """Each of `lit` into the output of its name (the GLSL's hand_on_light_terms, and the
        colours' outs)."""
        for name, value in lit.items():
            setattr(self, self.PREFIX + name, value)

    def light_terms(self, back: bool) -> LightTerms:
        """The terms handed on for the front (or back) side."""
        side = "back" if back else "front"
        return LightTerms(*(getattr(self, self.PREFIX + name) for name in
                            ("ambient", f"directional_terms_{side}", f"point_terms_{side}")))


def lighting(P: np.ndarray, N: np.ndarray, E: np.ndarray, material: MaterialUniforms,
             lights: Lights, visibility=None, area_light=None) -> np.ndarray:
    """The notes' lighting equation at points P (..., 3) with unit normals N (..., 3): the sum
    of light_terms.

    `visibility` (the shader's SHADOWS; the ray tracer's shadow rays): None lights every point
    by every light (the rasteriser's path, unchanged), else a callable
    visibility(kind, i, P, N, needed) -> (..., 1) 0 or 1 per point for light i of kind
    "directional" or "point", which multiplies that light's diffuse and specular terms (the
    GLSL's light_visibility_directional / light_visibility_point): in shadow, ambient only.
    `needed` (...,) is where the light's terms are not 0: elsewhere visibility can change
    nothing, and the GLSL casts no shadow ray (the callable may answer anything there).
    `area_light` (the ray tracer's AREA_LIGHTS): None, or a callable
    area_light(i, P, N, V, material) -> (..., 3) giving point light i's whole term where it
    has an area (its samples, each shadowed, averaged: raytrace/area_lights.py's area_light_terms) and None
    for a light without one, which then lights as above.
    E and the material's arrays may vary per point (broadcast against P). One light's term
    at a time (the terms are not kept)."""
    return shade_terms(ambient_term(P, N, material, lights),
                       each_light_term(P, N, E, material, lights, area_light), P, N, visibility)
