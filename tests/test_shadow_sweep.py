"""The light-elevation sweep (renderer/study/shadow_sweep.py): the template at each elevation,
the GPU's visibility from three linear renders against the same ratio of the reference's
images, and against ray-cast truth: no acne at any elevation on either backend at the
default settings (the issue's rule), while the same measure finds acne with no bias."""

import json
import math
from dataclasses import replace

import numpy as np
import pytest

import reference
from renderer.core.shadow_settings import BiasRule
from renderer.core.shadows import plan_shadows, shadow_layout
from renderer.study.shadow_sweep import (ELEVATIONS, MIN_TERM, elevation_scene, gpu_visibility,
                                         light_direction, measure_sweep, sweep_acne, truth_figures)

SIZE = (64, 48)


def test_the_sweep_runs_from_1_to_89_degrees_and_the_light_is_at_each_elevation():
    assert ELEVATIONS[0] == 1 and ELEVATIONS[-1] == 89 and list(ELEVATIONS) == sorted(ELEVATIONS)
    for elevation in (1, 30, 89):
        d = np.array(light_direction(elevation))
        assert np.linalg.norm(d) == pytest.approx(1.0)
        assert math.degrees(math.asin(-d[1])) == pytest.approx(elevation)   # below the horizon


def test_the_ground_is_in_its_own_map_so_that_acne_can_show():
    for elevation in (1, 89):
        scene = elevation_scene(elevation)
        [shadow_pass] = plan_shadows(scene, scene.matrices(*SIZE), shadow_layout(scene, *SIZE)).passes
        assert [scene.objects[i].name for i in shadow_pass.casters] == ["ground", "box", "ball"]


def _reference_visibility(scene):
    """gpu_visibility's ratio of three reference images (the twin's own v)."""
    [light] = scene.directional_lights
    renders = [reference.render(s, *SIZE, linear=True).linear for s in (
        scene, replace(scene, directional_lights=[replace(light, shadow=replace(light.shadow, enabled=False))]),
        replace(scene, directional_lights=[replace(light, intensity=(0.0, 0.0, 0.0))]))]
    shadowed, unshadowed, ambient = (r[..., :3].sum(axis=2) for r in renders)
    term = unshadowed - ambient
    return np.where(term >= MIN_TERM, (shadowed - ambient) / np.where(term > 0, term, 1.0), np.nan)


def test_the_gpu_visibility_is_the_ratio_of_the_lights_terms(gl_contexts):
    scene = elevation_scene(30)
    expected = _reference_visibility(scene)
    for ctx in gl_contexts.values():
        v = gpu_visibility(scene, SIZE, ctx)
        both = np.isfinite(v) & np.isfinite(expected)
        assert both.sum() > 0.5 * v.size                         # the ground, the box, the ball
        assert ((v[both] == 0.0).sum() > 20) and ((v[both] == 1.0).sum() > 1000)   # a shadow; lit
        assert (np.abs(v[both] - expected[both]) > 0.02).sum() <= 3   # the twins' ties at most


@pytest.mark.slow
def test_no_acne_at_any_elevation_on_either_backend(gl_contexts):
    rows = measure_sweep((160, 120), gl_contexts)
    assert [row["elevation"] for row in rows] == list(ELEVATIONS)
    for row in rows:
        assert set(row) == {"elevation", "reference", "egl", "osmesa"}
        assert all(row[k]["considered_pixels"] > 5000 for k in ("reference", "egl", "osmesa")), row
        assert sweep_acne(row) == 0, row


@pytest.mark.slow
def test_without_a_bias_the_same_measure_finds_acne(gl_contexts):
    scene = elevation_scene(30)
    [light] = scene.directional_lights
    scene = replace(scene, directional_lights=[replace(light, shadow=replace(light.shadow, bias=BiasRule()))])
    # The ground, a convex box, cannot shadow itself: its map covers where the box and the ball
    # can shadow it (their boxes across the light), and there, with no bias, it is acne:
    # 211 of the 2,191 pixels the light reaches at 64x48, in the twin and on the GPU alike.
    assert truth_figures(scene, SIZE)["acne_pixels"] > 150
    assert truth_figures(scene, SIZE, gpu_visibility(scene, SIZE, gl_contexts["egl"]))["acne_pixels"] > 150


@pytest.mark.slow
def test_renderer_extremes_writes_the_sweep(tmp_path, cli):
    result = cli("extremes", "--out", str(tmp_path), "--size", "64x48", "--context", "egl",
                 "--method", "raster")
    assert result.returncode == 0, result.stdout + result.stderr
    rows = json.loads((tmp_path / "extremes.json").read_text())["light_elevation_sweep"]
    assert [row["elevation"] for row in rows] == list(ELEVATIONS)
    table = (tmp_path / "extremes.md").read_text()
    assert "## Light-elevation sweep" in table and "| 1° |" in table and "| 89° |" in table
    assert "light elevation 89: 0 acne pixels" in result.stdout
