"""`renderer compare --methods` (renderer/checks/methods.py): the rasteriser against the ray
tracer, each differing pixel given one cause. The rule on hand-made images (the first step of
the chain that moves a pixel, the ±1 px allowance splitting edges from tessellation), then
scenes whose answer is known, rendered on the GPU at 64 x 48: a sphere's shadow lies under it
(and where the rasteriser's shadow map draws it too, only a texel-wide rim of it differs),
a mirror's reflection on the mirror, meshes lit from the eye show only edges, flat and Gouraud
materials show as shading; then the command line end to end."""

import json

import numpy as np
import pytest

from renderer.checks.methods import CAUSES, CHAIN, NO_DIFFERENCE, compare_methods, explain
from renderer.checks.tolerance import PIPELINE_TOLERANCE
from renderer.core.camera_rays import camera_ray_uniforms
from renderer.core.scene_file import scene_from_dict

W, H = 64, 48
CAUSE = {cause.name: k for k, cause in enumerate(CAUSES)}


def chain_of(*changes, start=100, shape=(3, 3)):
    """The seven images of CHAIN: grey `start` (a number or an (H, W) array), each step adding
    its change (likewise) to every channel of the image before; alpha 255."""
    images = [np.broadcast_to(np.asarray(start, np.int16)[..., None], (*shape, 4))]
    for change in changes:
        images.append(images[-1] + np.asarray(change, np.int16)[..., None])
    images = [np.clip(image, 0, 255).astype(np.uint8) for image in images]
    for image in images:
        image[..., 3] = 255
    return images


def one_pixel(value, shape=(3, 3), at=(1, 1)):
    change = np.zeros(shape, np.int16)
    change[at] = value
    return change


def test_a_pixel_s_cause_is_the_first_step_that_moves_it():
    """Shadow rays (step 5) move the centre by 40, reflection (step 6) by 40 more: shadows."""
    causes = explain(chain_of(0, 0, 0, 0, one_pixel(-40), one_pixel(40 + 40)))
    assert causes[1, 1] == CAUSE["shadows"]
    assert (np.delete(causes.ravel(), 4) == NO_DIFFERENCE).all()


def test_small_steps_that_add_up_go_to_the_largest():
    """No step moves the pixel by more than 2 levels, together they move it by 5: the largest
    step (sampling, 2 levels) is the cause; a pixel moved and moved back has no cause."""
    causes = explain(chain_of(one_pixel(1), 0, 0, one_pixel(2), 0, one_pixel(2)))
    assert causes[1, 1] == CAUSE["sampling"]
    back = explain(chain_of(0, 0, 0, 0, one_pixel(-40), one_pixel(40)))
    assert (back == NO_DIFFERENCE).all()


def test_the_one_pixel_allowance_splits_edges_from_tessellation():
    """From `unshadowed` to `centre` a vertical edge moves one pixel right (edges), and a pixel
    with no match within ±1 px appears beside it (tessellation)."""
    shape = (5, 6)
    phong = np.zeros(shape, np.int16)
    phong[:, :2] = 100
    centre = np.zeros(shape, np.int16)
    centre[:, :3] = 100
    centre[4, 5] = 50
    causes = explain(chain_of(0, 0, centre - phong, 0, 0, 0, start=phong, shape=shape))
    assert (causes[:, 2] == CAUSE["edges"]).all()
    assert causes[4, 5] == CAUSE["tessellation"]
    assert (causes == NO_DIFFERENCE).sum() == causes.size - shape[0] - 1


def test_the_chain_is_seven_images():
    with pytest.raises(ValueError, match="expected the 7 images"):
        explain(chain_of(0, 0, 0, 0, 0, 0)[:6])


def test_a_shadow_map_taken_away_is_a_shadow_cause_too():
    """The map's shadow taken away (step 2) moves a pixel the shadow rays (step 5) do not put
    back (the map shadowed a point the rays light): shadows."""
    causes = explain(chain_of(0, one_pixel(40), 0, 0, 0, 0))
    assert causes[1, 1] == CAUSE["shadows"]


def scene(objects, materials, lights=(), ambient=(0.1, 0.1, 0.1), background=(0, 0, 0),
          eye=(0, 2, 6), look=(0, 0, 0)):
    return scene_from_dict({"background": list(background), "ambient": list(ambient),
                            "camera": {"eye": list(eye), "look": list(look), "fov_y": 40.0},
                            "materials": materials, "lights": list(lights), "objects": objects})


def world_points(s, depth):
    """(H, W, 3) world point of each pixel's centre ray at the frame's view depth."""
    matrices = s.matrices(W, H)
    rays = camera_ray_uniforms(matrices.view, matrices.projection, W, H)
    x, y = np.meshgrid(np.arange(W) + 0.5, H - 1 - np.arange(H) + 0.5)      # row 0 on top
    window = np.stack([x, y, np.ones_like(x)], axis=-1)
    origin, direction = window @ rays["u_ray_origin"].T, window @ rays["u_ray_direction"].T
    return origin + depth[..., None] * direction + np.asarray(s.camera.eye)


FLOOR = {"name": "floor", "shape": {"type": "plane", "normal": [0, 1, 0], "offset": 1.0},
         "material": "floor"}
MATERIALS = {"ball": {"ka": [0.3, 0.1, 0.1], "kd": [0.8, 0.2, 0.1]},
             "floor": {"ka": [0.2, 0.2, 0.2], "kd": [0.7, 0.7, 0.7]},
             "mirror": {"ka": [0, 0, 0], "kd": [0, 0, 0], "kr": [1, 1, 1]},
             "wall": {"ka": [0.9, 0.1, 0.2], "kd": [0, 0, 0], "two_sided": True}}
BALL_ABOVE_FLOOR = {"name": "ball", "shape": {"type": "sphere", "radius": 0.5}, "material": "ball",
                    "translate": [0, 0.5, 0]}
FROM_ABOVE = {"type": "directional", "direction": [0, -1, 0]}


def test_a_sphere_above_a_plane_lit_from_above_shadows_the_plane_under_it(gl_contexts):
    """With the light's shadow map off, only the shadow rays can tell the floor under the ball
    (x² + z² < 0.5² at y = -1) from the rest; every shadow pixel sees that disc, and most of
    the disc's pixels are shadow."""
    s = scene([BALL_ABOVE_FLOOR, FLOOR], MATERIALS, [FROM_ABOVE | {"shadows": False}])
    result = compare_methods(s, W, H, context=gl_contexts["egl"])
    shadow = result.causes == CAUSE["shadows"]
    points = world_points(s, result.raytrace.depth)
    under = (np.hypot(points[..., 0], points[..., 2]) < 0.5) & np.isclose(points[..., 1], -1, atol=1e-3)
    assert shadow.sum() > 20
    assert not (shadow & ~under).any()
    assert shadow.sum() >= 0.9 * under.sum()
    counts = result.counts()
    assert counts["reflection"] == counts["shading"] == counts["sampling"] == 0
    assert counts["shadows"] == result.as_dict()["differing_pixels"] - counts["edges"] - counts["tessellation"]
    assert result.renders == 3          # raster, centre, shadows: the other steps change nothing here


def test_with_its_shadow_map_the_rasteriser_differs_at_the_shadow_s_rim_only(gl_contexts):
    """The same with the shadow map on: the rasteriser draws the shadow too, and the pixels
    still put down to shadows lie within a texel (the map's, at 128 texels here: 0.02 units)
    and a pixel (0.05 units) of the disc's edge; far fewer than the disc's."""
    s = scene([BALL_ABOVE_FLOOR, FLOOR], MATERIALS, [FROM_ABOVE])
    result = compare_methods(s, W, H, context=gl_contexts["egl"])
    shadow = result.causes == CAUSE["shadows"]
    points = world_points(s, result.raytrace.depth)
    radius = np.hypot(points[..., 0], points[..., 2])
    under = (radius < 0.5) & np.isclose(points[..., 1], -1, atol=1e-3)
    assert shadow.sum() < 0.5 * under.sum()
    assert (np.abs(radius[shadow] - 0.5) < 0.1).all()
    assert result.renders == 4          # raster, unshadowed, centre, shadows


def test_a_mirror_sphere_differs_by_reflection_on_the_sphere_only(gl_contexts):
    """A black mirror ball reflecting a red wall behind the camera, no light: the rasteriser
    draws the ball black, the ray tracer red; every reflection pixel sees the ball."""
    wall = {"name": "wall", "shape": {"type": "plane", "normal": [0, 0, -1], "offset": 10.0},
            "material": "wall"}
    s = scene([{"name": "ball", "shape": {"type": "sphere", "radius": 1.0}, "material": "mirror"}, wall],
              MATERIALS, ambient=(1, 1, 1), background=(0, 0.5, 0), eye=(0, 0, 5))
    result = compare_methods(s, W, H, context=gl_contexts["egl"])
    reflection = result.causes == CAUSE["reflection"]
    on_ball = np.isclose(np.linalg.norm(world_points(s, result.raytrace.depth), axis=-1), 1.0, atol=1e-3)
    assert reflection.sum() > 100
    assert not (reflection & ~on_ball).any()
    assert reflection.sum() >= 0.9 * on_ball.sum()
    assert result.counts()["shadows"] == 0
    assert result.renders == 3          # raster, centre, raytrace


MESHES = {"ambient": [0.1, 0.1, 0.1], "camera": {"eye": [0.3, 0.5, 3.5], "look": [0, 0, 0], "fov_y": 40.0},
          "materials": {"red": {"ka": [0.8, 0.2, 0.1], "kd": [0.8, 0.2, 0.1], "ks": [0.6, 0.6, 0.6], "n": 30.0},
                        "blue": {"ka": [0.1, 0.2, 0.6], "kd": [0.1, 0.3, 0.8]}},
          # a light at the eye: every point the camera sees, the light sees (its shadow map off:
          # the map's filter would darken a texel-wide rim around the ball's silhouette)
          "lights": [{"type": "point", "position": [0.3, 0.5, 3.5], "intensity": [0.9, 0.9, 0.9],
                      "shadows": False}],
          "objects": [{"name": "ball", "mesh": {"primitive": "uv_sphere", "radius": 0.8, "segments": 24, "rings": 12},
                       "material": "red"},
                      {"name": "box", "mesh": {"primitive": "cube", "size": 1.0}, "material": "blue",
                       "translate": [0.8, -0.3, -1.0]}]}


def test_meshes_lit_from_the_eye_differ_only_at_edges(gl_contexts):
    """No shadow can be seen, nothing reflects, Phong shading: what differs is primary
    visibility, within the pipeline tolerance (tests/test_raytrace_trace.py shows the two
    agree there)."""
    result = compare_methods(scene_from_dict(MESHES), W, H, context=gl_contexts["egl"])
    counts = result.counts()
    assert counts["edges"] + counts["tessellation"] == result.as_dict()["differing_pixels"]
    assert PIPELINE_TOLERANCE.passes(result.comparison)


def test_a_gouraud_material_differs_by_shading_on_its_object_only(gl_contexts):
    """The scene above with the ball Gouraud-shaded: shading pixels, all on the (red) ball."""
    gouraud = json.loads(json.dumps(MESHES))
    gouraud["materials"]["red"]["shading"] = "gouraud"
    result = compare_methods(scene_from_dict(gouraud), W, H, context=gl_contexts["egl"])
    shading = result.causes == CAUSE["shading"]
    red = result.raytrace.rgba8[..., 0] > result.raytrace.rgba8[..., 2]       # the ball, not the box
    assert shading.sum() > 50
    assert not (shading & ~red).any()


SHADOW_TOML = """
background = [0, 0, 0]
ambient = [0.1, 0.1, 0.1]
[camera]
eye = [0, 2, 6]
look = [0, 0, 0]
fov_y = 40.0
[materials.ball]
kd = [0.8, 0.2, 0.1]
[materials.floor]
kd = [0.7, 0.7, 0.7]
[[lights]]
type = "directional"
direction = [0, -1, 0]
shadows = false
[[objects]]
name = "ball"
shape = { type = "sphere", radius = 0.5, centre = [0, 0.5, 0] }
material = "ball"
[[objects]]
name = "floor"
shape = { type = "plane", normal = [0, 1, 0], offset = 1.0 }
material = "floor"
"""


def test_command_line_end_to_end(tmp_path, capsys):
    """The table on stdout, the four files in --out (the cause map's colours counted as the
    JSON counts them), status 0; what does not go together: status 2, nothing written."""
    from PIL import Image

    from renderer.cli import main
    path = tmp_path / "shadow.toml"
    path.write_text(SHADOW_TOML)
    out = tmp_path / "out"
    assert main(["compare", str(path), "--methods", "--size", f"{W}x{H}", "--context", "osmesa",
                 "--spp", "4", "--pattern", "jittered", "--out", str(out)]) == 0
    table = capsys.readouterr().out
    figures = json.loads((out / "methods.json").read_text())
    assert sorted(p.name for p in out.iterdir()) == ["causes.png", "methods.json", "raster.png", "raytrace.png"]
    assert figures["context"] == "osmesa" and figures["samples"] == 4 and figures["pattern"] == "jittered"
    causes = np.asarray(Image.open(out / "causes.png"))
    for cause in CAUSES:
        row = figures["causes"][cause.name]
        assert row["colour"] == list(cause.colour)
        assert (causes == cause.colour).all(axis=-1).sum() == row["pixels"]
        assert f"{cause.name:<13} {row['pixels']:>8,}" in table
    assert figures["causes"]["shadows"]["pixels"] > 20 and figures["causes"]["sampling"]["pixels"] > 0
    assert sum(row["pixels"] for row in figures["causes"].values()) == figures["differing_pixels"]
    for bad in (["--method", "raster"], ["--method", "raytrace"], ["--spp", "2"], ["--max-depth", "65"]):
        assert main(["compare", str(path), "--methods", "--size", "8x8", "--out", str(tmp_path / "no"), *bad]) == 2
        assert "usage: renderer compare" in capsys.readouterr().err
    path.write_text(SHADOW_TOML.replace("radius = 0.5", "radius = -0.5"))
    assert main(["compare", str(path), "--methods", "--size", "8x8", "--out", str(tmp_path / "no")]) == 2
    assert "radius" in capsys.readouterr().err
    assert not (tmp_path / "no").exists()


def test_notes_name_the_known_differences_a_scene_has():
    """The parallel projection's viewer where some material has a highlight; the shadow
    terminator where some smooth-shaded mesh is in a scene with shadow pixels."""
    from renderer.checks.methods import PARALLEL_VIEWER, SHADOW_TERMINATOR, notes
    meshes = scene_from_dict(MESHES)
    assert notes(meshes, {"shadows": 1}) == [SHADOW_TERMINATOR]
    assert notes(meshes, {"shadows": 0}) == []
    parallel = json.loads(json.dumps(MESHES))
    parallel["camera"] |= {"projection": "parallel", "height": 3.0}
    assert notes(scene_from_dict(parallel), {"shadows": 0}) == [PARALLEL_VIEWER]
    shapes = scene([BALL_ABOVE_FLOOR, FLOOR], MATERIALS, [FROM_ABOVE])
    assert notes(shapes, {"shadows": 1}) == []


@pytest.mark.parametrize("ks", [0.0, 0.8])
def test_a_parallel_projection_s_highlights_differ(gl_contexts, ks):
    """PARALLEL_VIEWER holds: a plane seen in a parallel projection, lit from above: without
    a highlight the two methods agree on every pixel, with one they do not."""
    s = scene_from_dict({"camera": {"eye": [0, 2, 3], "look": [0, 0, 0], "projection": "parallel", "height": 2.0},
                         "materials": {"floor": {"kd": [0.5, 0.5, 0.5], "ks": [ks] * 3, "n": 4.0}},
                         "lights": [{"type": "directional", "direction": [0, -1, -0.3]}], "objects": [FLOOR]})
    counts = compare_methods(s, W, H, context=gl_contexts["egl"]).counts()
    assert (counts["tessellation"] > 100) == (ks > 0)
    assert sum(counts.values()) == counts["tessellation"]
