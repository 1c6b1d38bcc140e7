"""Radiosity as a method (issue 33; renderer/methods/radiosity.py): the built-in radiosity scenes
rendered on the GPU (renderer/gpu/radiosity.py) and by the twin (reference/radiosity/), held to
what the two do not share and to each other.

By hand: the white furnace's image is E / (1 - rho) = 0.4 in every pixel; the facing plates'
white plate has a mean radiosity of rho E F, F Howell's C-11. GPU against twin: the Cornell box
within the pipeline tolerance with 0 mismatched pixels (at 320 x 240, every radiosity scene, on
EGL and OSMesa, in the full run). The solution is kept while only the camera moves."""

import dataclasses
import functools

import numpy as np
import pytest

from renderer.checks.compare import compare_frames
from renderer.checks.form_factor_closed_forms import parallel_rectangles
from renderer.checks.tolerance import PIPELINE_TOLERANCE
from renderer.core.builtin import builtin_scenes
from renderer.core.radiosity_options import RadiosityOptions
from renderer.core.scene_file import load_scene
from renderer.errors import OptionError
from renderer.methods import open_renderer

from conftest import RADIOSITY_SCENES


def scene(name):
    return load_scene(builtin_scenes()[name])


def both(name, size, options, kind="egl", contexts=None):
    where = {"context": contexts[kind]} if contexts else {}
    with open_renderer(scene(name), size, method="radiosity", options=options, **where) as gpu:
        gpu_frame = gpu.render(linear=True)
    with open_renderer(scene(name), size, method="radiosity", options=options, backend="reference") as twin:
        twin_frame = twin.render(linear=True)
    return gpu_frame, twin_frame


@pytest.mark.parametrize("kind", ["egl", "osmesa"])
def test_the_furnace_shows_e_over_one_minus_rho_in_every_pixel(gl_contexts, kind):
    options = RadiosityOptions(element_size=0.5, hemicube=16)
    gpu, twin = both("radiosity_furnace", (64, 48), options, kind, gl_contexts)
    for frame in (gpu, twin):
        assert (frame.rgba8[..., 3] == 255).all()                    # the camera is inside the room
        assert np.abs(frame.linear[..., :3] - 0.4).max() < 1e-6


def test_the_white_plate_gets_rho_e_times_c11(gl_contexts):
    """The white plate's area-weighted mean radiosity against 0.8 x 1 x F(C-11), within the
    hemicubes' and the elements' error (measured: 1.6 % at elements of 0.1 and N = 64; the
    plates' edges run along pixel rows, so that it does not fall steadily with N:
    tests/test_form_factors.py), plus the sky's: the background's radiosity times what each
    element's hemicube saw of nothing, times rho."""
    options = RadiosityOptions(element_size=0.1, hemicube=64)
    with open_renderer(scene("radiosity_plates"), (32, 24), method="radiosity", options=options,
                       context=gl_contexts["egl"]) as renderer:
        solution = renderer.solution
    elements, b = solution.elements, solution.solution.radiosity
    white = elements.obj == 1
    mean = (elements.areas[white, None] * b[white]).sum(axis=0) / elements.areas[white].sum()
    unseen = (elements.areas[white] * solution.form_factors.unseen[white]).sum() / elements.areas[white].sum()
    exact = 0.8 * (parallel_rectangles(1, 1, 1) + unseen * np.array(scene("radiosity_plates").background))
    assert np.allclose(mean, exact, rtol=0.02), (mean, exact)
    assert np.all(b[~white] == 1.0)                                # black emitter: E only
    assert solution.form_factors.unseen.min() > 0.7                # open: most light leaves


@pytest.mark.parametrize("kind", ["egl", "osmesa"])
def test_the_cornell_box_gpu_and_twin_agree(gl_contexts, kind):
    options = RadiosityOptions(element_size=0.12, hemicube=16)
    gpu, twin = both("cornell_box_radiosity", (160, 120), options, kind, gl_contexts)
    result = compare_frames(gpu.rgba8, twin.rgba8, gpu.depth, twin.depth, reference_tie=twin.rgba8_tie)
    assert PIPELINE_TOLERANCE.passes(result), PIPELINE_TOLERANCE.failures(result)
    assert result.mismatched_pixels == 0 and result.max_abs <= 1


@functools.lru_cache(maxsize=None)
def twin_frame(name, size):
    """The twin's frame at the default options (the same for either context)."""
    with open_renderer(scene(name), size, method="radiosity", backend="reference") as twin:
        return twin.render()


@pytest.mark.slow
@pytest.mark.xdist_group("radiosity_twin_frames")          # one worker: each twin frame made once
@pytest.mark.parametrize("kind", ["egl", "osmesa"])
@pytest.mark.parametrize("name", sorted(RADIOSITY_SCENES))
def test_every_radiosity_scene_gpu_and_twin_agree_at_320x240(gl_contexts, name, kind):
    with open_renderer(scene(name), (320, 240), method="radiosity", context=gl_contexts[kind]) as gpu:
        gpu = gpu.render()
    twin = twin_frame(name, (320, 240))
    result = compare_frames(gpu.rgba8, twin.rgba8, gpu.depth, twin.depth, reference_tie=twin.rgba8_tie)
    assert PIPELINE_TOLERANCE.passes(result), PIPELINE_TOLERANCE.failures(result)
    assert result.mismatched_pixels == 0


def test_the_solution_is_kept_while_only_the_camera_moves(gl_contexts):
    """A new camera draws no hemicube and solves nothing; a new emission solves again with the
    same form factors; moved geometry draws the hemicubes again."""
    options = RadiosityOptions(element_size=0.2, hemicube=16)
    room = scene("cornell_box_radiosity")
    with open_renderer(room, (32, 24), method="radiosity", options=options,
                       context=gl_contexts["egl"]) as renderer:
        first = renderer.render(linear=True)
        assert (renderer.form_factor_draws, renderer.solves) == (1, 1)
        room.camera = dataclasses.replace(room.camera, eye=(0.3, 0.25, -0.6))
        renderer.update(room)
        moved = renderer.render(linear=True)
        assert (renderer.form_factor_draws, renderer.solves) == (1, 1)
        assert not np.array_equal(moved.rgba8, first.rgba8)
        room.objects[3].material.emission = (10.0, 10.0, 10.0)
        renderer.update(room)
        assert (renderer.form_factor_draws, renderer.solves) == (1, 2)
        room.objects[0].transform.translate = (0.0, 0.01, 0.0)
        renderer.update(room)
        assert (renderer.form_factor_draws, renderer.solves) == (2, 3)


def test_both_solvers_draw_the_same_image(gl_contexts):
    frames = []
    for solver in ("gauss-seidel", "progressive"):
        options = RadiosityOptions(element_size=0.12, hemicube=16, solver=solver, tolerance=1e-8)
        with open_renderer(scene("cornell_box_radiosity"), (80, 60), method="radiosity",
                           options=options, context=gl_contexts["egl"]) as renderer:
            frames.append(renderer.render(linear=True).linear)
    assert np.abs(frames[0] - frames[1]).max() < 1e-5


def test_the_options_are_checked_by_name():
    for field, value, words in (("hemicube", 48, "a power of two from 4 to 1024"),
                                ("element_size", 0.0, "must be a number > 0"),
                                ("solver", "jacobi", "unknown solver 'jacobi'"),
                                ("tolerance", 2.0, "between 0 and 1")):
        with pytest.raises(OptionError, match=words) as refused:
            RadiosityOptions(**{field: value})
        assert refused.value.fields == (field,)


def test_the_command_line_renders_radiosity_and_refuses_in_one_line(cli, tmp_path):
    out = tmp_path / "box.png"
    ran = cli("render", "cornell_box_radiosity", "--method", "radiosity", "--size", "32x24",
              "--element-size", "0.2", "--hemicube", "16", "--solver", "progressive", "-o", out)
    assert ran.returncode == 0, ran.stderr
    assert out.exists() and "radiosity, hemicubes of 16, progressive" in ran.stdout + ran.stderr
    bad = cli("render", "cornell_box_radiosity", "--method", "radiosity", "--hemicube", "48",
              "-o", tmp_path / "bad.png")
    assert bad.returncode == 2 and not (tmp_path / "bad.png").exists()
    assert bad.stderr.strip().splitlines()[0].endswith("--hemicube 48: must be a power of two from 4 to 1024, got 48")
    other = cli("render", "sphere", "--element-size", "0.1", "-o", tmp_path / "other.png")
    assert other.returncode == 2 and "--element-size 0.1: is for method radiosity, not raster" in other.stderr
    big = cli("render", "cornell_box_radiosity", "--method", "radiosity", "--element-size", "0.005",
              "--max-memory", "2G", "-o", tmp_path / "big.png")
    assert big.returncode == 2 and not (tmp_path / "big.png").exists()
    assert len(big.stderr.strip().splitlines()) == 1 and "radiosity of cornell_box_radiosity (" in big.stderr
    assert "over the limit of 2.0 GiB" in big.stderr


def test_a_scene_where_light_does_not_bounce_draws_no_hemicube(gl_contexts):
    """The rule of leaving out what a scene does not need: with nothing emitting, or nothing
    reflecting, B = E exactly and no hemicube is drawn; once light can bounce, they are. One
    convex solid lit from outside (the sphere under its two lights) cannot light itself:
    B = rho (H + sky), its hemicubes seeing nothing but the background, and none is drawn."""
    options = RadiosityOptions(element_size=0.25, hemicube=16)
    plates = scene("radiosity_plates")
    plates.objects[1].material.kd = (0.0, 0.0, 0.0)               # nothing reflects
    with open_renderer(plates, (32, 24), method="radiosity", options=options,
                       context=gl_contexts["egl"]) as renderer:
        frame = renderer.render(linear=True)
        assert renderer.form_factor_draws == 0 and not renderer.solution.form_factors.drawn
        b, e = renderer.solution.solution.radiosity, renderer.solution.elements.emission
        assert np.array_equal(b, e)
        assert frame.rgba8[..., 3].any()
        plates.objects[1].material.kd = (0.8, 0.8, 0.8)           # now it does
        renderer.update(plates)
        assert renderer.form_factor_draws == 1 and renderer.solution.form_factors.drawn
        white = renderer.solution.elements.obj == 1
        assert (renderer.solution.solution.radiosity[white] > 0).all()
    with open_renderer(scene("sphere"), (16, 12), method="radiosity", options=options.replace(light_buffer=64),
                       backend="reference") as twin:
        frame = twin.render(linear=True)
        solution = twin.solution
        assert solution.form_factors.drawn is False and not solution.elements.see_each_other
        sky = np.array(scene("sphere").background)
        assert np.allclose(solution.solution.radiosity, solution.elements.reflectance * (solution.irradiance + sky),
                           rtol=1e-12, atol=0)
        drawn = frame.rgba8[..., 3] == 255
        assert drawn.any() and frame.linear[drawn][:, :3].any()
