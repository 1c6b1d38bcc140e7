"""The texture knobs of `renderer report` and the textured ground truth
(renderer/study/texture_report.py, textures.resampled): the resampling rule by hand, what each
setting changes, the truth's texture and filter, and the truth integrating a checkerboard over
the pixel on scenes whose answer is known."""

from dataclasses import replace

import numpy as np
import pytest

from renderer.core.builtin import builtin_scenes
from renderer.core.primitives import plane
from renderer.core.scene import Camera, Material, Scene, SceneObject, Transform
from renderer.core.scene_file import load_scene
from renderer.core.textures import MaterialTexture, Sampler, checkerboard, resampled, texture_from_linear
from renderer.study.ground_truth import render_truth, truth_scene
from renderer.study.report import EXHAUSTIVE, QUICK, RasterStudy, run_report, settings
from renderer.study.texture_report import (FILTER_SETTINGS, TEXTURE_RESOLUTIONS, TRUTH_FILTER,
                                           TRUTH_TEXELS, with_texture_setting)

COLOURS = ((0.9, 0.9, 0.9), (0.08, 0.08, 0.1))


def test_resampling_averages_texels_as_squares_of_colour():
    # One row of three texels, 0, 90 and 180 of 255: two texels of 1.5 each, six of 0.5.
    row = texture_from_linear(np.array([[[0.0] * 3, [90 / 255] * 3, [180 / 255] * 3]]), "row", "linear")
    assert list(resampled(row, 2, 1).levels[0][0, :, 0]) == [30, 150]     # (90 / 2) / 1.5, (45 + 180) / 1.5
    assert list(resampled(row, 6, 1).levels[0][0, :, 0]) == [0, 0, 90, 90, 180, 180]
    assert [level.shape[:2] for level in resampled(row, 6, 1).levels] == [(1, 6), (1, 3), (1, 1)]


@pytest.mark.parametrize("resolution", (8, 32, 256))
def test_a_checkerboard_resampled_is_the_same_checkerboard(resolution):
    authored = checkerboard(8, COLOURS, 64)
    again = resampled(authored, resolution, resolution)
    made = checkerboard(8, COLOURS, resolution)
    np.testing.assert_array_equal(again.levels[0], made.levels[0])
    # The levels above within 1: 0.9 is 229.5 of 255, a tie of unorm8 rounding, which the mip
    # chain's running sums of 0.9 (float64) round either way texel by texel, and of 230/255 not.
    assert len(again.levels) == len(made.levels)
    for level, expected in zip(again.levels, made.levels):
        assert np.abs(level.astype(int) - expected).max() <= 1


def globe_twice():
    """The globe scene with a second sphere sharing the globe's material texture, and an
    untextured third."""
    scene = load_scene(builtin_scenes()["globe"])
    globe = scene.objects[0]
    plain = replace(globe, name="plain", material=replace(globe.material, texture=None))
    return replace(scene, objects=[globe, replace(globe, name="twin"), plain])


def test_a_texture_setting_changes_every_textured_material_and_nothing_else():
    scene = globe_twice()
    authored = scene.objects[0].material.texture
    aniso = with_texture_setting(scene, "filter", ("anisotropic", 8))
    for obj in aniso.objects[:2]:
        assert obj.material.texture == replace(authored, sampler=Sampler(authored.sampler.wrap, "anisotropic", 8))
        assert replace(obj.material, texture=None) == scene.objects[2].material     # the rest as it was
    assert aniso.objects[2] == scene.objects[2]
    smaller = with_texture_setting(scene, "resolution", 128)
    first, second = (obj.material.texture.texture for obj in smaller.objects[:2])
    assert first is second and (first.width, first.height) == (128, 64)             # 512 x 256, resampled once
    assert smaller.objects[0].material.texture.sampler == authored.sampler
    assert with_texture_setting(scene, "resolution", 512).objects[0].material.texture.texture is authored.texture


def test_the_texture_knobs_go_to_textured_scenes_only():
    plan = settings(EXHAUSTIVE, [1])
    texture_settings = [s for s in plan if s.variant[0] == "texture"]
    assert {(s.knob, s.setting) for s in texture_settings} == {
        *(("filter", name) for name in ("nearest", "bilinear", "mip-nearest", "trilinear", "anisotropic 2",
                                        "anisotropic 4", "anisotropic 8", "anisotropic 16")),
        *(("texture_resolution", f"{r} texels") for r in (64, 128, 256, 512, 1024))}
    assert len(texture_settings) == 2 * (len(FILTER_SETTINGS) + len(TEXTURE_RESOLUTIONS))   # both backends
    assert all(s.sampling == ("pattern", "regular", 1) for s in texture_settings)
    study = RasterStudy()
    sphere = load_scene(builtin_scenes()["sphere"])
    assert not any(s.variant[0] == "texture" for s in study.scene_settings(plan, sphere, 160, 120))
    assert [s for s in study.scene_settings(plan, globe_twice(), 160, 120)
            if s.variant[0] == "texture"] == texture_settings
    assert {s.knob for s in settings(QUICK, [1]) if s.variant[0] == "texture"} == {"filter", "texture_resolution"}


def test_the_truth_samples_each_texture_repeated_to_1024_texels_trilinearly():
    for name, size in (("checker_horizon", (1024, 1024)), ("textured_mesh", (1120, 672))):
        scene = load_scene(builtin_scenes()[name])
        authored = scene.objects[0].material.texture
        truth = truth_scene(scene).objects[0].material.texture
        assert (truth.texture.width, truth.texture.height) == size              # k = ceil(1024 / long side)
        assert max(size) >= TRUTH_TEXELS and size[0] % authored.texture.width == 0
        assert truth.sampler == Sampler(authored.sampler.wrap, TRUTH_FILTER)
        assert (truth.uv_scale, truth.uv_offset, truth.modulate) == (authored.uv_scale, authored.uv_offset,
                                                                      authored.modulate)
    sphere = load_scene(builtin_scenes()["sphere"])
    assert [o.material for o in truth_scene(sphere).objects] == [o.material for o in sphere.objects]


def facing_checker(uv_scale: float, filter_name: str = "trilinear") -> Scene:
    """A 2 x 2-square checker on a square facing a parallel camera that sees [-4/3, 4/3] x [-1, 1]
    at 8 x 6 pixels (a pixel 1/3 of a unit, one pixel edge on each axis), lit by an ambient 1
    alone: a pixel is its texels. The square's UVs are its world x and y (the plane rule)."""
    texture = MaterialTexture(checkerboard(2, COLOURS, 2), Sampler("repeat", filter_name),
                              uv_scale=(uv_scale, uv_scale), modulate=("ka",))
    square = SceneObject("square", plane(4.0), Material(ka=(1.0, 1.0, 1.0), kd=(0.0, 0.0, 0.0), texture=texture),
                         transform=Transform(rotate=(90.0, 0.0, 0.0)))
    return Scene(camera=Camera(eye=(0.0, 0.0, 5.0), look=(0.0, 0.0, 0.0), projection="parallel", height=2.0),
                 objects=[square], ambient=(1.0, 1.0, 1.0))


def test_the_truth_of_squares_on_whole_pixels_is_their_colours():
    # uv_scale 3/8: a square is 4/3 units, 4 x 4 pixels, its edges on pixel edges.
    truth = render_truth(facing_checker(0.375), 8, 6)
    light, dark = (np.round(np.array(c) * 255) / 255 for c in COLOURS)    # the texture's unorm8 colours
    left = np.arange(8) < 4             # u = 3x/8 in [-1/2, 0): square column 1 (repeat), else 0
    bottom = np.arange(6) >= 3          # v = 3y/8 in [-1/2, 0): square row 1, else 0
    expected = np.where((left[None, :] == bottom[:, None])[..., None], light, dark)   # (0, 0) light
    np.testing.assert_allclose(truth, expected, atol=1e-6)


def test_the_truth_of_many_squares_a_pixel_is_their_mean():
    # uv_scale 12: a square is 1/24 of a unit, an eighth of a pixel: each pixel holds 64 squares
    # whole, half of each colour. One nearest lookup per pixel gives one of the two.
    truth = render_truth(facing_checker(12.0), 8, 6)
    mean = np.mean([np.round(np.array(c) * 255) / 255 for c in COLOURS], axis=0)
    assert np.abs(truth - mean).max() < 1 / 255
    from reference import render
    nearest = render(facing_checker(12.0, "nearest"), 8, 6, linear=True).linear[..., :3]
    assert np.abs(nearest - mean).min() > 0.3                              # every pixel all light or all dark


@pytest.mark.slow                       # about 5 s idle: a textured truth, plots, 40 frames
def test_a_tiny_texture_sweep_writes_its_rows_plots_and_section(tmp_path):
    scene = load_scene(builtin_scenes()["checker_horizon"])
    sweep = replace(QUICK, texture_filters=(("nearest", 1), ("trilinear", 1)), texture_resolutions=(16, 64), runs=1)
    result = run_report([scene], tmp_path, size=(32, 24), knobs=("filter", "texture_resolution"),
                        sweep=sweep, cache_dir=tmp_path / "cache", context_kind="egl")
    assert [(r["knob"], r["setting"], r["backend"]) for r in result.rows] == [
        (knob, setting, backend) for knob, setting in (("filter", "nearest"), ("filter", "trilinear"),
                                                       ("texture_resolution", "16 texels"),
                                                       ("texture_resolution", "64 texels"))
        for backend in ("gpu", "reference")]
    errors = {(r["setting"], r["backend"]): r["rmse"] for r in result.rows}
    for backend in ("gpu", "reference"):                   # the mip levels fade the far checks
        assert errors[("trilinear", backend)] < errors[("nearest", backend)]
        assert errors[("64 texels", backend)] == pytest.approx(errors[("trilinear", backend)])   # as authored
    assert sorted(p.name for p in (tmp_path / "plots").iterdir()) == [
        "checker_horizon-filter.png", "checker_horizon-texture_resolution.png"]
    report = (tmp_path / "report.md").read_text()
    assert "## Textures: filter and resolution" in report and "### checker_horizon" in report
    assert "| filter | nearest |" in report and "Pareto front, gpu (fastest first): " in report
    assert "| checker_horizon | 128 | 128 | checker 8x8 at 64 (64x64, trilinear, repeat) |" in report
    assert "## Convergence" not in report and "Anti-aliasing only" not in report
