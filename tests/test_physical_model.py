"""The physical model (issue 33; renderer/core/physical.py, docs/conventions.md "The physical
model"): a scene's `model = "physical"` in radiometric units, pixels in radiance.

By hand and by closed forms: each method's scene by hand; a floor under a point light is
rho / pi I cos / d^2 on the rasteriser and the ray tracer, GPU and twin; radiance inside glass
is n^2 times that outside (a camera at the centre of a glass ball sees 2.25 times the sky); the
white furnace is E / (pi (1 - rho)) under radiosity (within 1e-6) and the path tracer (within
three standard errors); the scene file's rules (reflectances at most 1, no attenuation, exact
Fresnel by default) one line each.
"""

import dataclasses
import math

import numpy as np
import pytest

from renderer.core.builtin import builtin_scenes
from renderer.core.path_options import PathOptions
from renderer.core.physical import INVERSE_SQUARE, for_method
from renderer.core.radiosity_options import RadiosityOptions
from renderer.core.ray_options import RayOptions
from renderer.core.scene_file import load_scene, scene_from_dict
from renderer.errors import SceneError
from renderer.methods import open_renderer


def floor_under_a_lamp(model="physical", rho=0.6, intensity=10.0, height=2.0):
    """A floor (y = 0, reflectance rho) under a point light of `intensity` W/sr `height` up,
    seen straight down by a parallel camera 4 units tall; no ambient light, a black sky."""
    return scene_from_dict({
        "model": model, "ambient": 0, "background": [0, 0, 0],
        "camera": {"projection": "parallel", "eye": [0, 5, 0], "look": [0, 0, 0], "up": [0, 0, -1],
                   "height": 4.0, "near": 0.1, "far": 10.0},
        "materials": {"floor": {"kd": [rho] * 3, "ka": [0.9] * 3}},
        "lights": [{"type": "point", "position": [0, height, 0], "intensity": [intensity] * 3}],
        "objects": [{"name": "floor", "shape": {"type": "plane"}, "material": "floor"}]})


def test_the_scene_file_reads_the_model_and_its_rules():
    assert floor_under_a_lamp("phong").model == "phong" and scene_from_dict({}).model == "phong"
    physical = floor_under_a_lamp()
    assert physical.model == "physical" and physical.objects[0].material.fresnel == "exact"
    schlick = scene_from_dict({"model": "physical", "materials": {"m": {"fresnel": "schlick"}}})
    assert schlick is not None
    for data, key, reason in (
            ({"model": "physical", "materials": {"m": {"kd": [1.2, 0.5, 0.5]}}}, "materials.m.kd",
             "is a reflectance in the physical model"),
            ({"model": "physical", "lights": [{"type": "point", "attenuation": [1, 0, 0]}]},
             "lights[0].attenuation", "fall off as the inverse square"),
            ({"model": "radiometric"}, "model", "radiometric")):
        with pytest.raises(SceneError) as refused:
            scene_from_dict(data)
        assert refused.value.key == key and reason in str(refused.value), str(refused.value)


def test_each_method_draws_the_physical_scene_in_its_units():
    scene = floor_under_a_lamp()
    scene.objects[0].material.ks, scene.objects[0].material.n = (0.3, 0.3, 0.3), 8.0
    scene.objects[0].material.emission = (2.0, 2.0, 2.0)
    shaded = for_method(scene, "raytrace").objects[0].material
    assert shaded.kd == pytest.approx((0.6 / math.pi,) * 3) and shaded.ka == (0.6, 0.6, 0.6)
    assert shaded.ks == pytest.approx((0.3 * 10 / (2 * math.pi),) * 3)       # (n + 2) / (2 pi) k_s
    paths = for_method(scene, "pathtrace")
    assert paths.objects[0].material.kd == (0.6, 0.6, 0.6)                  # a reflectance
    assert paths.objects[0].material.emission == pytest.approx((2 / math.pi,) * 3)
    assert paths.point_lights[0].intensity == pytest.approx((10 / math.pi,) * 3)
    for method in ("raster", "raytrace", "pathtrace", "radiosity"):
        assert for_method(scene, method).point_lights[0].attenuation == INVERSE_SQUARE
    phong = floor_under_a_lamp("phong")
    assert for_method(phong, "raster") is phong


@pytest.mark.parametrize("method", ["raster", "raytrace"])
@pytest.mark.parametrize("backend", ["gpu", "reference"])
def test_a_floor_under_a_point_light_is_rho_over_pi_i_cos_over_d_squared(method, backend, gl_contexts):
    """Each pixel's floor point (x, 0, z): rho / pi I h / d^3, d^2 = x^2 + z^2 + h^2, within
    float32's rounding (the rasteriser lights per fragment: Phong shading's default)."""
    width, height = 32, 24
    where = {"context": gl_contexts["egl"]} if backend == "gpu" else {}
    options = RayOptions() if method == "raytrace" else None
    with open_renderer(floor_under_a_lamp(), (width, height), method=method, backend=backend,
                       options=options, **where) as renderer:
        got = renderer.render(linear=True).linear[..., 0].astype(np.float64)
    rows, columns = np.mgrid[0:height, 0:width]
    x = ((columns + 0.5) / width * 2 - 1) * 2 * (width / height)
    z = ((rows + 0.5) / height * 2 - 1) * 2
    d2 = x * x + z * z + 4.0
    expected = 0.6 / math.pi * 10.0 * 2.0 / d2 ** 1.5
    assert np.allclose(got, expected, rtol=2e-5, atol=0), np.abs(got / expected - 1).max()
    phong = 0.6 * 10.0 * 2.0 / np.sqrt(d2)                # the Phong model: no 1/pi, no fall-off
    assert got.max() < 0.2 * phong.min()


def glass_ball_around_the_camera(model):
    """A camera at the centre of a glass ball (k_t = 1, index 1.5) under a sky of 0.2."""
    return scene_from_dict({
        "model": model, "background": [0.2, 0.2, 0.2], "ambient": 0,
        "camera": {"eye": [0, 0, 0], "look": [0, 0, -1], "near": 0.01, "far": 100.0},
        "materials": {"glass": {"kd": [0, 0, 0], "ka": [0, 0, 0], "kt": [1, 1, 1], "ior": 1.5,
                                "fresnel": "exact"}},
        "objects": [{"name": "ball", "shape": {"type": "sphere", "radius": 10.0}, "material": "glass"}]})


@pytest.mark.parametrize("backend", ["gpu", "reference"])
def test_radiance_inside_glass_is_n_squared_times_the_skys(backend, gl_contexts):
    """Every camera ray leaves the ball at normal incidence: F = 0.04 each time, the rest
    transmitted with eta = 1.5, so the sky's 0.2 comes in as 2.25 (1 - F) 0.2 (1 + F) (the
    twice-reflected ray's weight F^2 is under the tracer's cut-off, 2^-9: renderer/core/
    ray_depth.py) = 0.45 (1 - F^2); the Phong model's, without n^2, 0.2 (1 - F^2)."""
    where = {"context": gl_contexts["egl"]} if backend == "gpu" else {}
    F = 0.04
    for model, scale in (("physical", 2.25), ("phong", 1.0)):
        with open_renderer(glass_ball_around_the_camera(model), (16, 12), method="raytrace",
                           backend=backend, options=RayOptions(max_depth=4), **where) as tracer:
            got = tracer.render(linear=True).linear[6, 8, :3]
        assert np.allclose(got, scale * 0.2 * (1 - F ** 2), rtol=1e-5), (model, got)


def furnace(model):
    scene = load_scene(builtin_scenes()["radiosity_furnace"])
    return dataclasses.replace(scene, model=model)


def test_the_physical_furnace_is_e_over_pi_over_one_minus_rho(gl_contexts):
    """Radiosity's image: B / pi = 0.4 / pi in every pixel within 1e-6; the path tracer's mean
    within three standard errors of E (1 - rho^(D + 2)) / (pi (1 - rho))."""
    with open_renderer(furnace("physical"), (32, 24), method="radiosity",
                       options=RadiosityOptions(element_size=0.5, hemicube=16),
                       context=gl_contexts["egl"]) as radiosity:
        image = radiosity.render(linear=True).linear[..., :3]
    assert np.abs(image - 0.4 / math.pi).max() < 1e-6
    with open_renderer(furnace("physical"), (32, 24), method="pathtrace", options=PathOptions(samples=64),
                       context=gl_contexts["egl"]) as tracer:
        values = tracer.render().linear[..., 1].astype(np.float64).ravel()
    truth = 0.2 * (1 - 0.5 ** 34) / (math.pi * 0.5)
    sigma = values.std(ddof=1) / math.sqrt(values.size)
    assert abs(values.mean() - truth) < 3 * sigma, (values.mean(), truth, sigma)


def test_a_physical_scenes_ground_truth_is_not_its_phong_twins(tmp_path):
    """The report's truth cache keys the model: the same data in the two models are two truths."""
    from renderer.study.ground_truth import cache_path
    paths = {cache_path(floor_under_a_lamp(model), 8, 6, tmp_path, "raytrace") for model in ("phong", "physical")}
    assert len(paths) == 2
