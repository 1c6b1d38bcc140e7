"""Radiosity lit by point and directional lights (issue 33; renderer/core/light_buffers.py): the
lights' direct irradiance H on each element, from item buffers drawn at the light, and
B = E + rho (H + F B).

By hand, against closed forms that share nothing with the light buffer: under an
inverse-square point light an element's H A is I times the solid angle it subtends (Van
Oosterom and Strackee's formula for a triangle), per element within the pixels along its edges
(falling as 1 / N with the buffer's resolution N) and over the whole floor closer still; with no
fall-off, H is the mean of I cos over the element (a quadrature); under a directional light
H = I cos(theta) on a lit element and 0 in a blocker's shadow; a Lambertian disc light gives an
element under its centre I / (h^2 + r^2). GPU against twin: the lights' item buffers identical
on EGL and OSMesa, so the irradiance is too; moved lights draw only the lights' buffers again."""

import dataclasses

import numpy as np
import pytest

from reference.radiosity.item_buffer import ItemBuffers as TwinItemBuffers
from renderer.core.builtin import builtin_scenes
from renderer.core.light_buffers import LightSource, area_points, irradiance, light_sources, views
from renderer.core.radiosity_options import RadiosityOptions
from renderer.core.scene import LightArea, PointLight
from renderer.core.scene_file import load_scene
from renderer.errors import OptionError
from renderer.gpu.item_buffers import ItemBuffers
from renderer.methods import open_renderer
from tests.radiosity_scenes import elements_of, furnished_room, quad

INVERSE_SQUARE = (0.0, 0.0, 1.0)


def unit_floor(size=0.125):
    """The unit square on z = 0 facing +z, cut into elements of `size`."""
    return elements_of(quad((0, 0, 0), (1, 0, 0), (0, 1, 0)), np.array([0, 0]), size)


def solid_angle(q, triangles) -> np.ndarray:
    """(T,): the solid angle each triangle (T, 3, 3) subtends at q (Van Oosterom and Strackee,
    IEEE Trans. Biomed. Eng. 1983: tan(omega / 2) = |a . (b x c)| / (abc + (a.b) c + (a.c) b +
    (b.c) a))."""
    a, b, c = np.moveaxis(np.asarray(triangles) - q, 1, 0)
    la, lb, lc = (np.linalg.norm(v, axis=1) for v in (a, b, c))
    dot = lambda x, y: (x * y).sum(axis=1)
    return 2 * np.arctan2(np.abs(dot(a, np.cross(b, c))),
                          la * lb * lc + dot(a, b) * lc + dot(a, c) * lb + dot(b, c) * la)


def twin_irradiance(elements, sources, resolution):
    return irradiance(elements, sources, TwinItemBuffers(elements, resolution).views)


def test_a_point_lights_irradiance_is_the_solid_angle_each_element_subtends():
    """Per element, H A = I omega within the pixels along its edges: a pixel's centre decides
    what the whole pixel sees, so the error is about the edge pixels' share, which halves as N
    doubles (measured: 0.21, 0.11, 0.054 most at N = 128, 256, 512; the floor's total within
    0.4 % at each)."""
    floor = unit_floor()
    q = np.array([0.3, 0.4, 0.5])
    light = LightSource("point", tuple(q), (1.0, 1.0, 1.0), INVERSE_SQUARE)
    exact = solid_angle(q, floor.corners)
    worst = []
    for n in (128, 256, 512):
        h = twin_irradiance(floor, [light], n)
        assert np.array_equal(h[:, 0], h[:, 2])                    # white light, grey answer
        got = h[:, 0] * floor.areas
        worst.append(np.abs(got / exact - 1).max())
        assert abs(got.sum() / exact.sum() - 1) < 5e-3
    assert worst[2] < 0.07 and worst[1] < 0.6 * worst[0] and worst[2] < 0.6 * worst[1], worst


def test_without_fall_off_an_element_gets_the_mean_of_i_cos_over_it():
    """The Phong model's default light (attenuation 1): H is the mean of I cos(theta) over the
    element, here a quadrature of 4,096 points a triangle."""
    floor = unit_floor(0.25)
    q = np.array([0.5, 0.2, 0.6])
    intensity = (0.5, 1.0, 2.0)
    h = twin_irradiance(floor, [LightSource("point", tuple(q), intensity)], 512)
    k = 64                                               # midpoints of a 64 x 64 split of each triangle
    i, j = np.meshgrid(np.arange(k), np.arange(k), indexing="ij")
    keep = i + j < k
    s, t = (i[keep] + 1 / 3) / k, (j[keep] + 1 / 3) / k              # up-pointing pieces' centroids
    s2, t2 = (i[i + j < k - 1] + 2 / 3) / k, (j[i + j < k - 1] + 2 / 3) / k   # down-pointing pieces'
    s, t = np.r_[s, s2], np.r_[t, t2]
    a, b, c = np.moveaxis(floor.corners, 1, 0)
    points = a[:, None] + s[None, :, None] * (b - a)[:, None] + t[None, :, None] * (c - a)[:, None]
    to_light = q - points
    cosine = to_light[..., 2] / np.linalg.norm(to_light, axis=-1)
    exact = cosine.mean(axis=1)[:, None] * np.array(intensity)
    assert np.abs(h / exact - 1).max() < 0.03


def test_a_directional_light_gives_i_cos_where_lit_and_nothing_in_shadow():
    """A 0.4 square blocker 0.5 over the floor's middle, facing down (its back to the light),
    under a light along (0.2, 0.1, -1): an element whose corners all lie outside the blocker's
    shadow gets I cos(theta) within its edge pixels (its area counted in pixels of (diagonal /
    N)^2); one whose corners all lie inside it, nothing."""
    floor = quad((0, 0, 0), (1, 0, 0), (0, 1, 0))
    blocker = quad((0.3, 0.3, 0.5), (0, 0.4, 0), (0.4, 0, 0))          # faces -z
    elements = elements_of(np.concatenate([floor, blocker]), np.array([0, 0, 1, 1]), 0.05)
    direction = np.array([0.2, 0.1, -1.0])
    direction /= np.linalg.norm(direction)
    h = twin_irradiance(elements, [LightSource("directional", tuple(direction), (1.0, 1.0, 1.0))], 1024)
    on_floor = elements.obj == 0
    assert np.all(h[~on_floor] == 0)                               # the blocker's back is lit
    corners = elements.corners[on_floor]
    shadow = corners[..., :2] + 0.5 * direction[:2] / direction[2]    # along the light up to z = 0.5
    inside = ((shadow > 0.3) & (shadow < 0.7)).all(axis=-1)
    lit, dark = ~inside.any(axis=1), inside.all(axis=1)
    assert lit.sum() > 400 and dark.sum() > 60
    cosine = -direction[2]
    assert np.all(h[on_floor][dark] == 0)
    assert np.abs(h[on_floor][lit, 0] / cosine - 1).max() < 0.12
    assert abs(h[on_floor][lit, 0].mean() / cosine - 1) < 5e-3


def disc_irradiance(r, z, rho):
    """The irradiance at distance rho off the axis of a Lambertian disc of radius r and normal
    intensity 1, on a plane parallel to it z away (the disc's closed form, e.g. Howell's
    catalogue B-13 times pi r^2; on the axis 1 / (z^2 + r^2))."""
    s = z * z + rho * rho + r * r
    return (1 - (z * z + rho * rho - r * r) / np.sqrt(s * s - 4 * r * r * rho * rho)) / (2 * r * r)


def test_a_lambertian_disc_light_gives_an_element_its_closed_form():
    """A disc light of radius r facing down, z over two elements (the halves of a 0.2 square
    under its centre), seen from 16 x 16 of its points: each element's mean irradiance against
    the disc's closed form averaged over it (a 64 x 64 grid of its points), within 0.5 %."""
    r, z = 0.5, 0.8
    elements = elements_of(quad((-0.1, -0.1, 0), (0.2, 0, 0), (0, 0.2, 0)), np.array([0, 0]), 1.0)
    offsets, normals, scale = area_points(LightArea("disc", radius=r, normal=(0, 0, -1)), 16)
    sources = [LightSource("point", (p[0], p[1], z + p[2]), (1 / len(offsets),) * 3, INVERSE_SQUARE,
                           tuple(normals[m]), scale) for m, p in enumerate(offsets)]
    h = twin_irradiance(elements, sources, 512)
    grid = -0.1 + 0.2 * (np.arange(64) + 0.5) / 64
    x, y = np.meshgrid(grid, grid)
    values = disc_irradiance(r, z, np.hypot(x, y))
    # the square's diagonal from (-0.1, -0.1) to (0.1, 0.1) splits it; by symmetry both halves
    # have the square's mean
    assert abs(disc_irradiance(r, z, 0.0) - 1 / (z * z + r * r)) < 1e-12
    assert np.allclose(h, values.mean(), rtol=5e-3), (h[:, 0], values.mean())


def test_an_area_lights_points_are_equal_shares_of_it():
    for area in (LightArea("rectangle", size=(2.0, 1.0), normal=(0, 0, 1)),
                 LightArea("disc", radius=0.5, normal=(0, 1, 0)), LightArea("sphere", radius=0.3)):
        offsets, normals, scale = area_points(area, 4)
        assert offsets.shape == normals.shape == (16, 3) and scale == (4.0 if area.shape == "sphere" else 1.0)
        assert np.allclose(offsets.mean(axis=0), 0, atol=1e-12)        # centred on the light
    offsets, normals, _ = area_points(LightArea("disc", radius=0.0), 4)
    assert offsets.shape == (1, 3) and normals is None                 # size 0: the point light


@pytest.mark.parametrize("kind", ["egl", "osmesa"])
def test_the_gpu_and_the_twin_draw_identical_light_buffers(gl_contexts, kind):
    triangles, obj = furnished_room()
    elements = elements_of(triangles, obj, 0.5)
    sources = [LightSource("point", (1.5, 2.5, 1.4), (1.0, 1.0, 1.0), INVERSE_SQUARE),
               LightSource("directional", tuple(np.array([0.3, -1.0, 0.2]) / np.linalg.norm([0.3, -1.0, 0.2])),
                           (1.0, 1.0, 1.0))]
    buffers = ItemBuffers(gl_contexts[kind], elements, 64)
    try:
        for source in sources:
            matrices = views(source, elements)
            gpu = buffers.views(matrices)
            twin = TwinItemBuffers(elements, 64).views(matrices)
            assert gpu.shape == (len(matrices), 64, 64) and (gpu != 0).mean() > 0.3
            assert np.array_equal(gpu, twin)
        assert np.array_equal(irradiance(elements, sources, buffers.views),
                              twin_irradiance(elements, sources, 64))
    finally:
        buffers.release()


def test_a_scenes_lights_become_sources():
    scene = load_scene(builtin_scenes()["classic"])
    point, directional = light_sources(scene, 4)
    assert (point.kind, directional.kind) == ("point", "directional")
    scene.point_lights[0] = dataclasses.replace(scene.point_lights[0],
                                                area=LightArea("rectangle", size=(1.0, 1.0), normal=(0, -1, 0)))
    sources = light_sources(scene, 3)
    assert len(sources) == 1 + 9
    assert np.allclose(np.sum([s.intensity for s in sources if s.kind == "point"], axis=0),
                       scene.point_lights[0].intensity)
    scene.point_lights[0] = PointLight(intensity=(0.0, 0.0, 0.0))
    assert [s.kind for s in light_sources(scene, 3)] == ["directional"]     # a dark light is left out


def test_the_window_room_is_lit_by_the_sun_alone(gl_contexts):
    """radiosity_window: no surface emits, and the sun reaches the floor alone, through the
    window: the floor's power sum H A is the sun's through the window, I A_window cos (within
    1 %, the buffer's edge pixels; measured 0.8 % at N = 512), and no element's H is much above
    I cos(theta) (its edge pixels again: 8 % at most at N = 512); a moved sun draws the lights'
    buffers again and keeps the form factors."""
    scene = load_scene(builtin_scenes()["radiosity_window"])
    options = RadiosityOptions(element_size=0.5, hemicube=16, light_buffer=512)
    with open_renderer(scene, (32, 24), method="radiosity", options=options,
                       context=gl_contexts["egl"]) as renderer:
        solution = renderer.solution
        h = solution.irradiance
        sun = scene.directional_lights[0]
        direction = np.array(sun.direction) / np.linalg.norm(sun.direction)
        most = np.array(sun.intensity) * -direction[1]                 # on the floor, facing up
        floor = solution.elements.obj == 0
        assert (solution.elements.emission == 0).all() and np.all(h[~floor] == 0)
        through_window = np.array(sun.intensity) * 1.6 * 1.1 * -direction[0]
        assert np.allclose((h[floor] * solution.elements.areas[floor, None]).sum(axis=0), through_window, rtol=0.01)
        assert np.all(h[floor] <= most * 1.1) and (np.abs(h[floor] / most - 1) < 0.1).all(axis=1).sum() > 5
        assert (renderer.light_draws, renderer.form_factor_draws, renderer.solves) == (1, 1, 1)
        scene.directional_lights[0] = dataclasses.replace(sun, direction=(-1.0, -0.9, 0.1))
        renderer.update(scene)
        assert (renderer.light_draws, renderer.form_factor_draws, renderer.solves) == (2, 1, 2)
        assert not np.array_equal(renderer.solution.irradiance, h)


def test_the_light_options_are_checked_by_name():
    for field, value, words in (("light_buffer", 100, "a power of two from 4 to 2048"),
                                ("area_samples", 0, "an integer from 1 to 16")):
        with pytest.raises(OptionError, match=words) as refused:
            RadiosityOptions(**{field: value})
        assert refused.value.fields == (field,)
