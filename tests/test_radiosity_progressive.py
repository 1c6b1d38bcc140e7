"""Radiosity a step at a time, for the viewer (renderer/core/radiosity_progressive.py): the
direct light first, the hemicubes a batch a step, then shots, the unshot light falling at
every step; the end is the progressive solver's answer on the same form factors (bit for bit),
the same on the GPU and in the twin (their item buffers identical but for flagged depth ties),
and Gauss-Seidel's to the tolerance; a change of lights keeps the form factors;
a scene where light cannot bounce is exact at the first step. The window's side is
tests/test_viewer.py."""

import dataclasses

import numpy as np

from renderer.core.builtin import builtin_scenes
from renderer.core.radiosity import elements_for, lighting_for
from renderer.core.radiosity_options import RadiosityOptions
from renderer.core.radiosity_progressive import VIEW_TOLERANCE
from renderer.core.radiosity_solve import progressive
from renderer.core.scene_file import load_scene, scene_from_dict
from renderer.methods import open_renderer

OPTIONS = RadiosityOptions(element_size=0.5, hemicube=16, light_buffer=64, solver="progressive")


def corner():
    """A glossy floor, a wall and a box on legs of air (nothing meets: no depth tie) under a
    point light, a grey sky: 338 elements."""
    plane = {"primitive": "plane", "size": 1.0}
    return scene_from_dict({
        "background": [0.2, 0.2, 0.25], "ambient": [0.0, 0.0, 0.0],
        "camera": {"eye": [0.0, 1.5, 3.0], "look": [0.0, 0.3, 0.0], "fov_y": 60.0},
        "materials": {"floor": {"kd": [0.6, 0.5, 0.4], "ks": [0.4, 0.4, 0.4], "n": 20.0},
                      "wall": {"kd": [0.7, 0.7, 0.7]}, "box": {"kd": [0.2, 0.4, 0.7]}},
        "lights": [{"type": "point", "position": [0.5, 2.0, 0.5], "intensity": [2.0, 2.0, 2.0],
                    "attenuation": [0.0, 0.0, 1.0]}],
        "objects": [{"name": "floor", "mesh": plane, "scale": [3.0, 1.0, 3.0], "material": "floor"},
                    {"name": "wall", "mesh": plane, "scale": [3.0, 1.0, 2.0], "rotate": [90.0, 0.0, 0.0],
                     "translate": [0.0, 1.05, -1.4], "material": "wall"},
                    {"name": "box", "mesh": {"primitive": "cube", "size": 0.6}, "translate": [-0.4, 0.4, -0.3],
                     "material": "box"}]})


def steps(renderer, scene=None, **keywords):
    return list(renderer.progressive(scene, hemicubes_per_step=16, shots_per_step=16, **keywords))


def test_the_steps_converge_to_the_progressive_solvers_answer_gpu_and_twin_alike(gl_contexts):
    scene = corner()
    from renderer.gpu.radiosity import RadiosityRenderer
    with RadiosityRenderer(scene, 32, 24, OPTIONS, context=gl_contexts["egl"], solve=False) as gpu:
        assert gpu.solution is None and (gpu.render().rgba8[..., 3] == 0).all()    # nothing yet
        made = steps(gpu)
        final = gpu.solution
        frame = gpu.render(depth=False).rgba8
    phases = [p.phase for p in made]
    elements = len(final.elements)
    assert phases[0] == "lights" and phases[-1] == "converged" and made[-1].done
    assert phases.count("hemicubes") == -(-elements // 16) and "shooting" in phases
    assert phases == sorted(phases, key=["lights", "hemicubes", "shooting", "converged"].index)
    unshot = [p.line for p in made if p.phase == "shooting"]
    fractions = [float(line.split("unshot ")[1].split("%")[0]) for line in unshot]
    assert all(b <= a for a, b in zip(fractions, fractions[1:])) and fractions[-1] < fractions[0]
    expected = progressive(final.form_factors, final.elements.areas, final.elements.reflectance, final.source,
                           tolerance=VIEW_TOLERANCE)
    assert np.array_equal(final.solution.radiosity, expected.radiosity)
    assert final.solution.iterations == expected.iterations and final.solution.converged
    with open_renderer(scene, (32, 24), method="radiosity", backend="reference", options=OPTIONS) as twin:
        twin_steps = steps(twin)
        assert [p.phase for p in twin_steps] == phases
        # identical item buffers but for pixels the twin flags as depth ties (2 of 432,640 here,
        # an element seen edge on: docs/radiosity.md, "GPU against twin"): those two elements
        # differ by about a pixel's delta form factor at N = 16, the others by the tolerance
        off = np.abs(twin.solution.solution.radiosity / final.solution.radiosity - 1).max(axis=1)
        assert (off > 1e-5).sum() <= 2 and off.max() < 1e-3
    with open_renderer(scene, (32, 24), method="radiosity", options=OPTIONS, context=gl_contexts["egl"]) as solved:
        assert np.allclose(solved.solution.solution.radiosity, final.solution.radiosity, rtol=1e-3, atol=1e-4)


def test_a_change_of_lights_keeps_the_form_factors(gl_contexts):
    from renderer.gpu.radiosity import RadiosityRenderer
    scene = corner()
    with RadiosityRenderer(scene, 32, 24, OPTIONS, context=gl_contexts["egl"], solve=False) as gpu:
        steps(gpu)
        assert (gpu.form_factor_draws, gpu.light_draws) == (1, 1)
        matrix = gpu.solution.form_factors
        dimmer = dataclasses.replace(scene, point_lights=[dataclasses.replace(
            scene.point_lights[0], intensity=(1.0, 1.0, 1.0))])
        again = steps(gpu, dimmer)
        assert "hemicubes" not in [p.phase for p in again] and again[0].phase == "lights"
        assert (gpu.form_factor_draws, gpu.light_draws) == (1, 2) and gpu.solution.form_factors is matrix
        assert [p.phase for p in steps(gpu)] == ["converged"]                # nothing changed


def test_where_light_cannot_bounce_the_first_step_is_exact(gl_contexts):
    from renderer.gpu.radiosity import RadiosityRenderer
    scene = load_scene(builtin_scenes()["radiosity_plates"])
    dark = dataclasses.replace(scene, objects=[dataclasses.replace(
        o, material=dataclasses.replace(o.material, kd=(0.0, 0.0, 0.0))) for o in scene.objects])
    with RadiosityRenderer(dark, 32, 24, OPTIONS, context=gl_contexts["egl"], solve=False) as gpu:
        made = steps(gpu)
        assert [p.phase for p in made] == ["converged"] and gpu.form_factor_draws == 0
        elements = elements_for(dark, OPTIONS)
        assert np.array_equal(gpu.solution.solution.radiosity, elements.emission)
        assert lighting_for(dark, OPTIONS).sources == ()
