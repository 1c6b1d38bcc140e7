"""The lighting equation of docs/conventions.md, on values worked out by hand.

    I = I_a k_a + sum_l att_l I_l k_d max(N.L, 0) + sum_l att_l I_l k_s spec_l

reference/lighting.py (twin of glsl/lighting.glsl) evaluates it; the vertex, geometry and
fragment stages decide which normal it sees (one-sided, two-sided, flat, Gouraud, Phong).
"""

from __future__ import annotations

import math
from pathlib import Path

import numpy as np
import pytest

from reference import render
from reference.geometry import shade_triangles
from reference.lighting import Lights, MaterialUniforms, lighting
from reference.vertex import shade_vertices
from renderer.core.scene import (Camera, DirectionalLight, Material, PointLight, Scene, SceneObject,
                            Transform)
from renderer.core import primitives

ORIGIN = np.zeros(3)
UP_Z = np.array([0.0, 0.0, 1.0])


def lights(ambient=(0.0, 0.0, 0.0), directional=(), point=()) -> Lights:
    scene = Scene(ambient=ambient,
                  directional_lights=[DirectionalLight(d, i) for d, i in directional],
                  point_lights=[PointLight(p, i, a) for p, i, a in point])
    return Lights.from_scene(scene)


def light_at(P, N, E, material: Material, light_set: Lights) -> np.ndarray:
    return lighting(np.asarray(P, float), np.asarray(N, float), np.asarray(E, float),
                    MaterialUniforms.from_material(material), light_set)


def test_ambient_term():
    """No lights: I = I_a k_a per channel."""
    I = light_at(ORIGIN, UP_Z, (0, 0, 5), Material(ka=(0.5, 0.5, 1.0)), lights(ambient=(0.1, 0.2, 0.3)))
    assert I == pytest.approx([0.05, 0.1, 0.3])


def test_diffuse_head_on_and_at_60_degrees():
    """Light straight down the normal: k_d; at 60 degrees from it: k_d cos 60 = k_d / 2."""
    material = Material(ka=(0, 0, 0), kd=(0.8, 0.6, 0.4), ks=(0, 0, 0))
    head_on = lights(directional=[((0, 0, -1), (1, 1, 1))])
    assert light_at(ORIGIN, UP_Z, (0, 0, 5), material, head_on) == pytest.approx([0.8, 0.6, 0.4])
    slanted = lights(directional=[((0, -math.sin(math.pi / 3), -0.5), (1, 1, 1))])
    assert light_at(ORIGIN, UP_Z, (0, 0, 5), material, slanted) == pytest.approx([0.4, 0.3, 0.2])


def test_specular_mirror_direction_and_off_mirror():
    """L at 45 degrees: viewed along the mirror direction R = V, spec = 1; viewed along N,
    R.V = cos 45 and spec = (1/sqrt 2)^2 = 1/2 for n = 2."""
    material = Material(ka=(0, 0, 0), kd=(0.2, 0.2, 0.2), ks=(0.5, 0.5, 0.5), n=2)
    light_set = lights(directional=[((-1, 0, -1), (1, 1, 1))])       # L = (1, 0, 1)/sqrt 2
    mirror = light_at(ORIGIN, UP_Z, (-3, 0, 3), material, light_set)
    assert mirror == pytest.approx([0.2 / math.sqrt(2) + 0.5] * 3)
    overhead = light_at(ORIGIN, UP_Z, (0, 0, 3), material, light_set)
    assert overhead == pytest.approx([0.2 / math.sqrt(2) + 0.5 * 0.5] * 3)


def test_no_highlight_when_reflection_points_away():
    """R.V < 0 gives no specular term (and pow never sees a negative base)."""
    material = Material(ka=(0, 0, 0), kd=(0, 0, 0), ks=(1, 1, 1), n=3)
    light_set = lights(directional=[((-1, 0, -1), (1, 1, 1))])       # R = (-1, 0, 1)/sqrt 2
    with np.errstate(all="raise"):
        I = light_at(ORIGIN, UP_Z, (10, 0, 1), material, light_set)   # V nearly +x: R.V < 0
    assert I == pytest.approx([0, 0, 0])


def test_point_light_attenuation():
    """Point light 3 units above: d = 3, att = 1 / (1 + 0.5*3 + 0.25*9) = 1 / 4.75;
    seen from above, R = V so spec = 1: I = att I_l (k_d + k_s)."""
    material = Material(ka=(0, 0, 0), kd=(0.6, 0.4, 0.2), ks=(0.3, 0.3, 0.3), n=8)
    light_set = lights(point=[((0, 0, 3), (1.0, 0.5, 2.0), (1.0, 0.5, 0.25))])
    I = light_at(ORIGIN, UP_Z, (0, 0, 5), material, light_set)
    assert I == pytest.approx(np.array([1.0, 0.5, 2.0]) * np.array([0.9, 0.7, 0.5]) / 4.75)


def test_lights_add_up():
    """Ambient + a directional + a point light: the sum of each alone."""
    material = Material(ka=(0.5, 0.5, 0.5), kd=(0.6, 0.6, 0.6), ks=(0.4, 0.4, 0.4), n=16)
    parts = [lights(ambient=(0.2, 0.2, 0.2)),
             lights(directional=[((0.3, -0.2, -1), (0.7, 0.7, 0.7))]),
             lights(point=[((1, 2, 3), (0.5, 0.5, 0.5), (1, 0.1, 0.01))])]
    together = lights((0.2, 0.2, 0.2), [((0.3, -0.2, -1), (0.7, 0.7, 0.7))],
                      [((1, 2, 3), (0.5, 0.5, 0.5), (1, 0.1, 0.01))])
    P, E = (0.1, 0.2, 0.0), (0.5, 0.5, 4.0)
    assert light_at(P, UP_Z, E, material, together) == pytest.approx(
        sum(light_at(P, UP_Z, E, material, part) for part in parts))


def test_one_sided_from_behind_is_ambient_only():
    """A light behind the surface (N.L < 0) adds nothing, not even a highlight, although
    here R.V = 1 > 0: only the ambient term is left."""
    material = Material(ka=(0.5, 0.5, 0.5), kd=(1, 1, 1), ks=(1, 1, 1), n=4)
    light_set = lights(ambient=(0.2, 0.2, 0.2), directional=[((0, 0, 1), (1, 1, 1))])
    I = light_at(ORIGIN, UP_Z, (0, 0, -5), material, light_set)
    assert I == pytest.approx([0.1, 0.1, 0.1])


# --- the sides rule in the stages -----------------------------------------------------

def test_gouraud_vertex_colours_front_and_back():
    """Two-sided Gouraud: the vertex stage lights each vertex with N (front colour) and with
    -N (back colour); one-sided has one colour."""
    scene_lights = lights(ambient=(0.1, 0.1, 0.1), directional=[((0, 0, 1), (1, 1, 1))])
    common = dict(u_model=np.eye(4), u_normal_matrix=np.eye(3), u_view=np.eye(4),
                  u_projection=np.eye(4), u_eye=np.array([0.0, 0.0, -5.0]), lights=scene_lights)
    material = Material(ka=(1, 1, 1), kd=(0.5, 0.5, 0.5), ks=(0, 0, 0), shading="gouraud",
                        two_sided=True)
    out = shade_vertices(np.zeros((1, 3)), UP_Z[None], material=material, **common)
    assert out.v_color_front[0] == pytest.approx([0.1] * 3)            # light behind N
    assert out.v_color_back[0] == pytest.approx([0.6] * 3)             # -N faces the light
    material.two_sided = False
    out = shade_vertices(np.zeros((1, 3)), UP_Z[None], material=material, **common)
    assert out.v_color_back[0] == pytest.approx([0.1] * 3)


def test_flat_face_normal_and_centroid():
    """Flat: normal normalize((p1 - p0) x (p2 - p0)), lit at the centroid: a point light
    2 units above the centroid of a CCW triangle in z = 0, attenuation (0, 0, 1): 1/4."""
    p = np.array([[[0.0, 0, 0], [3, 0, 0], [0, 3, 0]]])
    light_set = lights(point=[((1, 1, 2), (1, 1, 1), (0, 0, 1))])
    out = shade_triangles(p, Material(ka=(0, 0, 0), kd=(1, 1, 1), ks=(0, 0, 0), shading="flat"),
                          light_set, np.array([0.0, 0.0, 5.0]))
    assert out.f_face_normal[0] == pytest.approx([0, 0, 1])
    assert out.f_centroid[0] == pytest.approx([1, 1, 0])
    assert out.f_color_front[0] == pytest.approx([0.25] * 3)


@pytest.mark.parametrize("shading", ["flat", "gouraud", "phong"])
def test_two_sided_flips_the_normal_seen_from_behind(shading):
    """A plane facing +y seen from below (its back, clockwise on screen), lit from below.
    One-sided: ambient only, 0.2 * 0.5. Two-sided: N := -N faces the light straight on,
    0.1 + k_d = 0.1 + 0.6."""
    def centre_colour(two_sided):
        scene = Scene(camera=Camera(eye=(0, -3, 0), look=(0, 0, 0), up=(0, 0, 1)),
                      objects=[SceneObject("plane", primitives.plane(2.0),
                                           Material(ka=(0.5, 0.5, 0.5), kd=(0.6, 0.6, 0.6),
                                                    ks=(0, 0, 0), shading=shading,
                                                    two_sided=two_sided))],
                      directional_lights=[DirectionalLight((0, 1, 0))], ambient=(0.2, 0.2, 0.2))
        return render(scene, 16, 16, linear=True).linear[8, 8]
    assert centre_colour(False) == pytest.approx([0.1, 0.1, 0.1, 1.0], abs=1e-6)
    assert centre_colour(True) == pytest.approx([0.7, 0.7, 0.7, 1.0], abs=1e-6)


ONE_SIDED_RULE = ("seen from behind, a surface shows the light falling on its front, and a light "
                  "on the viewer's side adds nothing but the ambient term")


@pytest.mark.parametrize("shading", ["flat", "gouraud", "phong"])
def test_one_sided_seen_from_behind_shows_the_light_on_its_front(shading, gl_contexts):
    """The sentence of docs/scene-format.md (two_sided) and docs/conventions.md, held against
    both pipelines: a one-sided plane facing +y seen from below (its back), with k_a 0.5 under
    I_a 0.2 and k_d 0.6. Lit from above (on its front): 0.1 + 0.6. Lit from below (the
    viewer's side): 0.1, the ambient term. Two-sided is the other way round."""
    from renderer.gpu import GpuRenderer

    def centre(light_travels_y, two_sided):
        scene = Scene(camera=Camera(eye=(0, -3, 0), look=(0, 0, 0), up=(0, 0, 1)),
                      objects=[SceneObject("plane", primitives.plane(2.0),
                                           Material(ka=(0.5, 0.5, 0.5), kd=(0.6, 0.6, 0.6),
                                                    ks=(0, 0, 0), shading=shading,
                                                    two_sided=two_sided))],
                      directional_lights=[DirectionalLight((0, light_travels_y, 0))],
                      ambient=(0.2, 0.2, 0.2))
        with GpuRenderer(scene, 16, 16, context=gl_contexts["egl"]) as gpu:
            on_gpu = gpu.render(linear=True).linear[8, 8, :3]
        on_reference = render(scene, 16, 16, linear=True).linear[8, 8, :3]
        np.testing.assert_allclose(on_gpu, on_reference, atol=1e-6)
        return on_reference

    for document in ("docs/scene-format.md", "docs/conventions.md"):
        text = " ".join((Path(__file__).parents[1] / document).read_text().split())
        assert ONE_SIDED_RULE in text, document
    from_above, from_below = -1.0, 1.0            # the way the light travels along y
    assert centre(from_above, two_sided=False) == pytest.approx([0.7] * 3, abs=1e-6)
    assert centre(from_below, two_sided=False) == pytest.approx([0.1] * 3, abs=1e-6)
    assert centre(from_above, two_sided=True) == pytest.approx([0.1] * 3, abs=1e-6)
    assert centre(from_below, two_sided=True) == pytest.approx([0.7] * 3, abs=1e-6)


def test_phong_specular_follows_the_fragment():
    """Phong lights each fragment: under a point light at the eye, a pixel's colour is the
    equation at the point its centre sees (V from that point to the eye), brighter
    next to the spot under the light than in a corner."""
    light = PointLight((0.0, 0.0, 1.0), (1, 1, 1), (1, 0, 0))
    material = Material(ka=(0, 0, 0), kd=(0, 0, 0), ks=(1, 1, 1), n=10, shading="phong")
    scene = Scene(camera=Camera(eye=(0, 0, 1), look=(0, 0, 0), projection="parallel", height=2.0),
                  objects=[SceneObject("plane", primitives.plane(2.0, segments=1), material,
                                       Transform(rotate=(90, 0, 0)))],
                  point_lights=[light], ambient=(0, 0, 0))
    image = render(scene, 8, 8, linear=True).linear
    # pixel (row 3, column 4) from the top: centre at x = -1 + 4.5/4 = 0.125, y = 1 - 3.5/4 = 0.125
    P = np.array([0.125, 0.125, 0.0])
    expected = light_at(P, UP_Z, (0.0, 0.0, 1.0), material, lights(point=[((0, 0, 1), (1, 1, 1), (1, 0, 0))]))
    assert image[3, 4, :3] == pytest.approx(expected, rel=1e-6)
    assert image[3, 4, 0] > image[0, 0, 0]                 # the highlight fades away from it
