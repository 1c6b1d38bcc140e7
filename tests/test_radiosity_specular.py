"""Radiosity's direct specular term (issue 33; glsl/radiosity/specular.glsl, twin
reference/radiosity/specular.py): the display adds to the interpolated radiosity each light's
k_s term where a material has one, shadowed by the light buffer the light was drawn from.

By hand: the frame with k_s minus the frame without is k_s I att(d) max(R.V, 0)^n at each
pixel's surface point (written here from the depth image and the camera, sharing nothing with
the display), 0 where a box hides the light (a slab test on the segment to the light), the
closed form where it clearly does not; a new k_s or n redraws the frame without solving again;
a scene without a specular term keeps no light buffer and compiles no specular term. GPU
against twin: every radiosity scene's frame (tests/test_radiosity_gpu_vs_twin.py, with
radiosity_specular among them)."""

import dataclasses

import numpy as np
import pytest

from renderer.core.builtin import builtin_scenes
from renderer.core.radiosity_options import RadiosityOptions
from renderer.core.scene_file import load_scene, scene_from_dict
from renderer.methods import open_renderer

LIGHT = (0.5, 1.5, -0.5)
INTENSITY = 2.0
ATTENUATION = (0.5, 0.2, 0.3)
KS, SHININESS = 0.5, 20.0
BOX_CENTRE, BOX_HALF = np.array([0.2, 0.8, -0.1]), 0.2
OPTIONS = RadiosityOptions(element_size=0.5, hemicube=16, light_buffer=512)


def glossy_floor(box: bool, ks: float = KS, n: float = SHININESS):
    objects = [{"name": "floor", "mesh": {"primitive": "plane", "size": 1.0}, "scale": [4.0, 1.0, 4.0],
                "material": "floor"}]
    if box:
        objects.append({"name": "box", "mesh": {"primitive": "cube", "size": 2 * BOX_HALF},
                        "translate": BOX_CENTRE.tolist(), "material": "box"})
    return scene_from_dict({
        "background": [0.0, 0.0, 0.0], "ambient": [0.0, 0.0, 0.0],
        "camera": {"eye": [0.0, 1.6, 2.2], "look": [0.0, 0.0, -0.2], "fov_y": 60.0, "near": 0.1, "far": 20.0},
        "materials": {"floor": {"kd": [0.3, 0.3, 0.3], "ks": [ks] * 3, "n": n},
                      "box": {"kd": [0.0, 0.0, 0.0]}},
        "lights": [{"type": "point", "position": list(LIGHT), "intensity": [INTENSITY] * 3,
                    "attenuation": list(ATTENUATION)}],
        "objects": objects})


def surface_points(scene, frame):
    """(H, W, 3) world points of the pixel centres from the view depth (-z_eye), the camera's
    own unprojection, and (H, W) where something was drawn."""
    height, width = frame.depth.shape
    camera = scene.camera
    tan = np.tan(np.radians(camera.fov_y) / 2)
    x = ((np.arange(width) + 0.5) / width * 2 - 1) * tan * width / height
    y = (1 - (np.arange(height) + 0.5) / height * 2) * tan
    drawn = np.isfinite(frame.depth)
    depth = np.where(drawn, frame.depth, 1.0).astype(np.float64)          # masked by `drawn`
    eye_space = np.stack([x[None, :] * depth, y[:, None] * depth, -depth], axis=-1)
    rotation = scene.matrices(width, height).view[:3, :3]
    return eye_space @ rotation + np.asarray(camera.eye, np.float64), drawn


def closed_form(points):
    """k_s I att(d) max(R.V, 0)^n on the floor (normal +y) under LIGHT, seen from the eye."""
    to_light = np.asarray(LIGHT) - points
    d = np.linalg.norm(to_light, axis=-1, keepdims=True)
    L = to_light / d
    N = np.array([0.0, 1.0, 0.0])
    R = 2 * (L @ N)[..., None] * N - L
    to_eye = np.array([0.0, 1.6, 2.2]) - points
    V = to_eye / np.linalg.norm(to_eye, axis=-1, keepdims=True)
    c, l, q = ATTENUATION
    return KS * INTENSITY / (c + l * d[..., 0] + q * d[..., 0] ** 2) * np.maximum((R * V).sum(-1), 0) ** SHININESS


def box_distance(points):
    """(H, W): how far the segment from each point to LIGHT passes inside the box (> 0: hidden,
    by that much; < 0: clear of it by that much), a slab test on the box grown and shrunk."""
    def hidden(half):
        direction = np.asarray(LIGHT) - points
        with np.errstate(divide="ignore", invalid="ignore"):
            t0 = (BOX_CENTRE - half - points) / direction
            t1 = (BOX_CENTRE + half - points) / direction
        near = np.nanmax(np.minimum(t0, t1), axis=-1)
        far = np.nanmin(np.maximum(t0, t1), axis=-1)
        return (near <= far) & (far > 0) & (near < 1)
    margin = np.zeros(points.shape[:2])
    for step in np.linspace(0.0, 0.06, 7)[1:]:               # growing: the last that holds stays
        margin = np.where(hidden(BOX_HALF - step), step, margin)
        margin = np.where(~hidden(BOX_HALF + step), -step, margin)
    return margin


def specular_alone(scene, backend, context, size):
    """The frame of `scene`, and its specular term: the linear frame minus the same scene's
    with k_s = 0."""
    dull = dataclasses.replace(scene, objects=[dataclasses.replace(
        o, material=dataclasses.replace(o.material, ks=(0.0, 0.0, 0.0))) for o in scene.objects])
    extra = {"context": context} if backend == "gpu" else {"precision": "float32"}
    with open_renderer(scene, size, method="radiosity", backend=backend, options=OPTIONS, **extra) as renderer:
        shiny = renderer.render(linear=True)
    with open_renderer(dull, size, method="radiosity", backend=backend, options=OPTIONS, **extra) as renderer:
        plain = renderer.render(linear=True)
    return shiny, shiny.linear[..., 0].astype(np.float64) - plain.linear[..., 0]


@pytest.mark.parametrize("backend, size", [("gpu", (160, 120)),
                                           pytest.param("reference", (64, 48), marks=pytest.mark.slow)])
def test_the_term_is_the_lighting_equations_ks_term(gl_contexts, backend, size):
    scene = glossy_floor(box=False)
    frame, term = specular_alone(scene, backend, gl_contexts["egl"], size)
    points, drawn = surface_points(scene, frame)
    expected = closed_form(points)
    assert drawn.mean() > 0.5 and expected[drawn].max() > 0.2          # a highlight in view
    assert np.abs(term - expected)[drawn].max() < 1e-5                # float32: 1.8e-6 measured


@pytest.mark.parametrize("backend, size", [("gpu", (160, 120)),
                                           pytest.param("reference", (64, 48), marks=pytest.mark.slow)])
def test_a_highlight_is_shadowed_where_the_light_is_hidden(gl_contexts, backend, size):
    """Where the segment to the light passes well inside the box the term is 0; well clear of
    it, the closed form; the light buffer's pixels (512 a side, about 0.006 across at the box)
    decide a band along the shadow's edge."""
    scene = glossy_floor(box=True)
    frame, term = specular_alone(scene, backend, gl_contexts["egl"], size)
    points, drawn = surface_points(scene, frame)
    floor = drawn & (np.abs(points[..., 1]) < 1e-3)
    margin = box_distance(points)
    expected = closed_form(points)
    hidden, clear = floor & (margin >= 0.02), floor & (margin <= -0.02)
    assert (expected[hidden] > 0.05).sum() > 20                      # the shadow crosses the highlight
    assert np.all(term[hidden] == 0)
    assert np.abs(term[clear] - expected[clear]).max() < 1e-5


def test_new_ks_or_n_redraws_without_solving_again(gl_contexts):
    scene = glossy_floor(box=False)
    with open_renderer(scene, (64, 48), method="radiosity", options=OPTIONS, context=gl_contexts["egl"]) as renderer:
        before = renderer.render().linear[..., 0].copy()
        draws = (renderer.solves, renderer.light_draws, renderer.form_factor_draws)
        renderer.update(glossy_floor(box=False, ks=2 * KS))
        after = renderer.render().linear[..., 0].copy()
        assert (renderer.solves, renderer.light_draws, renderer.form_factor_draws) == draws
    with open_renderer(glossy_floor(box=False), (64, 48), method="radiosity", options=OPTIONS,
                       context=gl_contexts["egl"]) as renderer:
        renderer.update(glossy_floor(box=False, ks=0.0))
        diffuse = renderer.render().linear[..., 0]
    assert np.allclose(after - diffuse, 2 * (before - diffuse), atol=1e-5)
    assert (before - diffuse).max() > 0.2


def test_a_scene_without_a_specular_term_keeps_no_light_buffer(gl_contexts):
    scene = load_scene(builtin_scenes()["radiosity_window"])              # diffuse walls, the sun
    with open_renderer(scene, (32, 24), method="radiosity", options=dataclasses.replace(OPTIONS, element_size=1.0),
                       context=gl_contexts["egl"]) as renderer:
        assert not renderer.solution.lighting.specular and renderer.solution.light_surfaces is None
        assert renderer.light_draws == 1
    with open_renderer(glossy_floor(box=True), (32, 24), method="radiosity", options=OPTIONS,
                       context=gl_contexts["egl"]) as renderer:
        surfaces = renderer.solution.light_surfaces
        assert renderer.solution.lighting.specular and renderer.light_draws == 1   # kept from the same draw
        assert surfaces.surfaces.shape == (6, 512, 512) and set(np.unique(surfaces.surfaces)) == {0, 1, 2}


@pytest.mark.slow
def test_refined_elements_keep_the_shadows_at_the_options_light_buffer(gl_contexts):
    scene = glossy_floor(box=True)
    options = dataclasses.replace(OPTIONS, refine=1)
    with open_renderer(scene, (32, 24), method="radiosity", options=options, context=gl_contexts["egl"]) as renderer:
        solution = renderer.solution
        assert solution.levels == 1 and solution.light_surfaces.surfaces.shape[-1] == OPTIONS.light_buffer
