"""The rasteriser drawing an analytic sphere through the tessellation stages (issue 34;
docs/tessellation.md): the scene file's `tessellation` table, the camera pass's patches on the
GPU and in the twin, and the sphere against the ray tracer's exact one.

By hand: each key read and each refusal one line naming the key; a triangle patch makes at most
3 k (k + 1) + 1 points at a level up to 2k, the bound draws are split by (the twin's tessellator
over every spacing and level). GPU against twin: every shading mode at the largest level (80
patches of up to 3,169 points, drawn PATCHES_PER_DRAW at a time: one draw would wrap llvmpipe's
uint16 indices) and with levels by need, on EGL and OSMesa, within the pipeline tolerance. The
exact sphere: interior pixels within 1 level of the ray tracer's at 0.25 px (the ray tracer
intersects the sphere itself), closer than the untessellated icosphere."""

import dataclasses

import numpy as np
import pytest
from scipy import ndimage

from reference.tessellation.tessellator import tessellate
from renderer.checks.compare import compare_frames
from renderer.checks.tolerance import PIPELINE_TOLERANCE
from renderer.core.scene_file import load_scene, scene_from_dict
from renderer.checks.methods import compare_methods
from renderer.core.tessellation import (MAX_LEVEL, SPACINGS, Tessellation, max_triangle_points, patches_per_draw,
                                        with_tessellated_spheres)
from renderer.errors import SceneError
from renderer.gpu.pipeline import PATCHES_PER_DRAW
from renderer.methods import open_renderer
from tests.tessellation_capture import gpu_against_twin

SIZE = (96, 72)


def ball(tessellation=None, shading="phong", receives_shadows=False, **extra):
    obj = {"name": "ball", "shape": {"type": "sphere", "radius": 1.0},
           "material": {"kd": [0.7, 0.3, 0.2], "ks": [0.5, 0.5, 0.5], "n": 30.0, "shading": shading},
           "receives_shadows": receives_shadows, **extra}
    if tessellation is not None:
        obj["tessellation"] = tessellation
    return {"background": [0.1, 0.1, 0.15], "ambient": [0.1, 0.1, 0.1],
            "camera": {"eye": [0.0, 0.5, 3.0], "look": [0.0, 0.0, 0.0], "fov_y": 45.0},
            "lights": [{"type": "point", "position": [2.0, 3.0, 3.0], "intensity": [1.0, 1.0, 1.0],
                        "shadows": False}],
            "objects": [obj]}


# -- the scene file ------------------------------------------------------------------------------

def test_the_tessellation_table_is_read():
    obj = scene_from_dict(ball({"error": 0.5, "spacing": "equal"})).objects[0]
    assert obj.tessellation == Tessellation(spacing="equal_spacing", error=0.5)
    obj = scene_from_dict(ball({"level": 12.5})).objects[0]
    assert obj.tessellation == Tessellation(level=12.5)
    assert scene_from_dict(ball({})).objects[0].tessellation == Tessellation()
    assert scene_from_dict(ball()).objects[0].tessellation is None


@pytest.mark.parametrize("table, extra, words", [
    ({"error": 0.25, "level": 4}, {}, "give either error"),
    ({"level": 65}, {}, "must be at most 64"),
    ({"level": 0.5}, {}, "objects[0].tessellation.level"),
    ({"spacing": "odd"}, {}, "objects[0].tessellation.spacing"),
    ({"colour": 1}, {}, "objects[0].tessellation"),
    ({}, {"receives_shadows": True, "mesh": {"primitive": "torus"}}, "does not look shadow maps up yet"),
])
def test_a_bad_tessellation_table_is_one_line(table, extra, words):
    data = ball(table, **extra)
    if "mesh" in extra:
        del data["objects"][0]["shape"]
    with pytest.raises(SceneError) as info:
        scene_from_dict(data)
    line = info.value.line()
    assert words in line and "\n" not in line


def test_a_mesh_is_tessellated_as_pn_triangles_and_a_plane_not_at_all():
    data = ball({"level": 3})
    obj = data["objects"][0]
    del obj["shape"]
    obj["mesh"] = {"primitive": "icosphere"}
    assert scene_from_dict(data).objects[0].tessellation == Tessellation(level=3, surface="pn_triangles")
    obj["shape"] = {"type": "plane"}
    del obj["mesh"]
    with pytest.raises(SceneError) as info:
        scene_from_dict(data)
    assert "objects[0].tessellation: a plane is flat" in info.value.line()


# -- splitting the draws ---------------------------------------------------------------------------

@pytest.mark.parametrize("spacing", SPACINGS)
def test_a_patch_makes_at_most_the_bound_the_draws_are_split_by(spacing):
    levels = np.concatenate([np.arange(1, 65), np.arange(1, 65) - 0.5, [MAX_LEVEL]])
    most = max(len(tessellate("triangles", spacing, [a] * 3, [a]).u) for a in levels if a >= 1)
    assert most <= max_triangle_points(MAX_LEVEL) == 3169
    assert PATCHES_PER_DRAW == patches_per_draw() == 20 and PATCHES_PER_DRAW * 3169 <= 65536


# -- GPU against twin ------------------------------------------------------------------------------

def drawn_alike_params():
    """Two cases in the default run (a level whose points need split draws, and levels by
    need), every shading mode at the largest level on both contexts in the full run."""
    cases = [("phong", {"level": 40}), ("phong", {"level": 64}), ("gouraud", {"level": 64}),
             ("flat", {"level": 64}), ("gouraud", {"error": 0.25})]
    quick = {(0, "egl"), (4, "egl")}     # level 40: 80 patches of 1,261 points, still split
    return [pytest.param(kind, *case, marks=() if (i, kind) in quick else pytest.mark.slow)
            for i, case in enumerate(cases) for kind in ("egl", "osmesa")]


@pytest.mark.parametrize("kind, shading, table", drawn_alike_params())
def test_the_gpu_and_the_twin_draw_the_same_tessellated_sphere(gl_contexts, kind, shading, table):
    scene = scene_from_dict(ball(table, shading=shading))
    with open_renderer(scene, SIZE, context=gl_contexts[kind]) as gpu:
        got = gpu.render(depth=False).rgba8
    with open_renderer(scene, SIZE, backend="reference") as twin:
        expected = twin.render(depth=False).rgba8
    result = compare_frames(got, expected)
    assert PIPELINE_TOLERANCE.passes(result), PIPELINE_TOLERANCE.failures(result)
    assert result.max_abs <= 1


# -- the exact sphere --------------------------------------------------------------------------------

def interior_levels(scene, context):
    """Levels off the ray tracer's exact sphere on the pixels both draw, two pixels inside."""
    with open_renderer(scene, (320, 240), context=context) as raster:
        a = raster.render(depth=False).rgba8
    with open_renderer(scene, (320, 240), method="raytrace", context=context) as tracer:
        b = tracer.render(depth=False).rgba8
    interior = ndimage.binary_erosion((a[..., 3] > 0) & (b[..., 3] > 0), iterations=2)
    return np.abs(a[..., :3].astype(int) - b[..., :3].astype(int)).max(-1)[interior]


@pytest.mark.slow
def test_the_tessellated_sphere_meets_the_exact_sphere_within_a_level(gl_contexts):
    """At the default 0.25 px every interior pixel is within 1 level of the ray tracer's exact
    sphere; the icosphere the rasteriser draws without the stages (1,280 triangles) is more than
    1 level off in places."""
    ctx = gl_contexts["egl"]
    tessellated = interior_levels(scene_from_dict(ball({"error": 0.25})), ctx)
    icosphere = interior_levels(scene_from_dict(ball()), ctx)
    assert tessellated.max() <= 1 and tessellated.mean() < icosphere.mean()
    assert icosphere.max() > 1


def test_the_builtin_scene_loads_with_two_tessellated_spheres():
    scene = load_scene("tessellated_sphere")
    spacings = [o.tessellation.spacing for o in scene.objects if o.tessellation is not None]
    assert spacings == ["fractional_odd_spacing", "equal_spacing"]


# -- cracks and extreme cases ------------------------------------------------------------------------

def silhouette_holes(scene, context, size=(160, 120), exact=True):
    """Background pixels where a crack between patches would show it: inside the drawn
    surface's own outline (holes it encloses), and with `exact` inside the exact sphere's
    silhouette shrunk by two pixels (the chords lie inside the sphere by at most the target
    error, a quarter of a pixel). Returns (holes, pixels looked at)."""
    with open_renderer(scene, size, context=context) as gpu:
        frame = gpu.render(depth=False).rgba8
    width, height = size
    matrices = scene.matrices(width, height)
    inverse = np.linalg.inv(matrices.projection @ matrices.view)
    xs = (np.arange(width) + 0.5) / width * 2 - 1
    ys = 1 - (np.arange(height) + 0.5) / height * 2
    far = np.stack(np.broadcast_arrays(xs[None, :], ys[:, None], 1.0, 1.0), -1) @ inverse.T
    direction = far[..., :3] / far[..., 3:]
    direction /= np.linalg.norm(direction, axis=-1, keepdims=True)
    centre = np.asarray(scene.objects[0].shape.centre) - matrices.origin     # camera-relative
    b = direction @ centre
    inside = b * b - (centre @ centre - scene.objects[0].shape.radius ** 2) > 0
    inside = ndimage.binary_erosion(inside, iterations=2) if exact else np.zeros_like(inside)
    drawn = frame[..., 3] > 0
    inside |= ndimage.binary_fill_holes(drawn)
    return int((~drawn & inside).sum()), int(inside.sum())


@pytest.mark.parametrize("table", [{"error": 0.25}, {"level": 1}, {"level": 7.3}, {"error": 0.05,
                                                                                 "spacing": "fractional_even"}])
def test_no_crack_shows_the_background_through_the_sphere(gl_contexts, table):
    """(At a fixed level the chords may lie farther inside than two pixels: the drawn
    outline's own enclosed holes are counted then.)"""
    holes, inside = silhouette_holes(scene_from_dict(ball(table)), gl_contexts["egl"], exact="error" in table)
    assert inside > 1000 and holes == 0


@pytest.mark.slow
@pytest.mark.parametrize("distance", [1.3, 2.0, 4.0, 12.0, 40.0])
def test_no_crack_as_the_camera_comes_closer(gl_contexts, distance):
    """Levels by need change with the distance; at every distance each shared edge gets one
    level from both of its patches (the eye 1.3 radii from the centre fills the view)."""
    data = ball({"error": 0.25})
    data["camera"] = {"eye": [0.0, 0.3 * distance, distance], "look": [0.0, 0.0, 0.0], "fov_y": 45.0,
                      "near": 0.05}
    holes, inside = silhouette_holes(scene_from_dict(data), gl_contexts["egl"])
    assert inside > 5 and holes == 0


@pytest.mark.parametrize("case", ["crossing_near_plane", "tiny_far_away", "edge_on_patches"])
def test_extreme_views_are_drawn_alike_by_the_gpu_and_the_twin(gl_contexts, case):
    """A sphere cut by the near plane (edges behind the eye get the largest level), a sphere a
    few pixels wide 60 radii away (every edge at level 1), patches seen edge on at the
    silhouette of a sphere seen from very near."""
    data = ball({"error": 0.25})
    if case == "crossing_near_plane":
        data["camera"] = {"eye": [0.0, 0.0, 1.05], "look": [0.0, 0.0, 0.0], "fov_y": 60.0, "near": 0.1}
    elif case == "tiny_far_away":
        data["camera"] = {"eye": [0.0, 0.0, 60.0], "look": [0.0, 0.0, 0.0], "fov_y": 45.0, "far": 400.0}
    else:
        data["camera"] = {"eye": [0.0, 0.0, 1.2], "look": [0.0, 0.0, 0.0], "fov_y": 100.0, "near": 0.01}
    scene = scene_from_dict(data)
    with open_renderer(scene, SIZE, context=gl_contexts["egl"]) as gpu:
        got = gpu.render(depth=False).rgba8
    with open_renderer(scene, SIZE, backend="reference") as twin:
        expected = twin.render(depth=False).rgba8
    result = compare_frames(got, expected)
    assert PIPELINE_TOLERANCE.passes(result), PIPELINE_TOLERANCE.failures(result)
    assert (got[..., 3] > 0).any()


# -- shadows, and compare --methods --tessellate -------------------------------------------------------

@pytest.mark.parametrize("kind", ["egl", "osmesa"])
def test_tessellated_spheres_receiving_shadows_are_drawn_alike(gl_contexts, kind):
    """classic with its three spheres through the stages: they cast shadows on each other and
    the floor and receive them (the lookup with the sphere's normal, no crease); GPU against
    twin 0 mismatched pixels."""
    scene, count = with_tessellated_spheres(load_scene("classic"))
    assert count == 3 and all(o.receives_shadows for o in scene.objects)
    result = gpu_against_twin(scene, gl_contexts[kind], (160, 120))
    assert PIPELINE_TOLERANCE.passes(result) and result.mismatched_pixels == 0, \
        PIPELINE_TOLERANCE.failures(result)


def test_with_tessellated_spheres_takes_the_untextured_analytic_spheres_only():
    globe = load_scene("globe")                    # a textured sphere
    assert with_tessellated_spheres(globe)[1] == 0
    scene, count = with_tessellated_spheres(load_scene("tessellated_sphere"), 0.1)
    assert count == 0                              # they ask for their own already
    scene, count = with_tessellated_spheres(load_scene("classic"), 0.1)
    assert [o.tessellation and o.tessellation.error for o in scene.objects] == [None, 0.1, 0.1, 0.1]


@pytest.mark.slow
def test_compare_methods_tessellate_falls_at_640x480(gl_contexts):
    """The "tessellation" cause on classic at 640 x 480: 184 pixels as icospheres, 26 through
    the stages at 0.25 pixel (benchmarks/bench_methods_tessellation.py has every size)."""
    scene = load_scene("classic")
    before = compare_methods(scene, 640, 480, context=gl_contexts["egl"]).counts()["tessellation"]
    after = compare_methods(with_tessellated_spheres(scene)[0], 640, 480,
                            context=gl_contexts["egl"]).counts()["tessellation"]
    assert after < before / 3, (before, after)


@pytest.mark.parametrize("argv, words", [
    (["--tessellate", "0"], "--tessellate: must be a number of pixels above 0"),
    (["--tessellate", "nan"], "--tessellate: must be a number of pixels above 0"),
    (["mesh_file", "--tessellate"], "--tessellate: the scene has no untextured analytic sphere"),
])
def test_compare_tessellate_refuses_in_one_line(cli_here, tmp_path, argv, words):
    scene = [] if argv[0] == "mesh_file" else ["classic"]
    done = cli_here("compare", *scene, "--methods", *argv, "--size", "32x24", "--out", str(tmp_path / "o"))
    lines = done.stderr.strip().splitlines()
    assert done.returncode == 2 and len(lines) == 1 and lines[0].startswith(f"renderer: {words}"), done.stderr
    assert not (tmp_path / "o").exists()
