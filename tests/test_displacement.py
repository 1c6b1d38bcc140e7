"""A mesh displaced by a height image through the tessellation stages (issue 34;
renderer/core/tessellation.py Displacement, the SURFACE_DISPLACED paths of
glsl/tess_control.glsl and tess_evaluation.glsl, twins reference/tessellation/control.py
displaced_patch_levels and evaluation.py evaluate_displaced).

By hand: the scene file's `displacement` table and its refusals; a flat height image asks for
level 1; on the built-in height image each edge's level keeps the displaced edge (its heights
read at 2,001 points along it) within the target of the chords between ceil(level) equal parts,
or where a part per texel caps it, within half the image's largest step between texels. GPU against twin, by transform feedback: levels, points and
normals bit for bit for each spacing (the height read by textureLod in the evaluation stage and
by reference/sampler.py); the built-in scene displaced_plane drawn alike at 320 x 240 on EGL
and OSMesa. Crack-free: every point on a patch edge is a point of the neighbouring patch too,
and no background pixel shows inside the displaced plane's outline."""

from pathlib import Path

import numpy as np
import pytest
from scipy import ndimage

from reference.sampler import sample
from reference.tessellation.control import ControlUniforms, displaced_patch_levels, displaced_tangents
from reference.tessellation.evaluation import evaluate_displaced
from reference.tessellation.tessellator import primitive_vertices, tessellate
from renderer.checks.tolerance import PIPELINE_TOLERANCE
from renderer.core import primitives, transforms
from renderer.core.scene_file import load_scene, scene_from_dict
from renderer.core.tessellation import (DISPLACEMENT_SAMPLER, EDGE_ERROR_SHARE, MAX_LEVEL, SPACINGS,
                                        TARGET_PIXEL_ERROR, Displacement, displaced_patches)
from renderer.core.textures import load_texture, texture_from_linear
from renderer.errors import SceneError
from renderer.gpu.shaders import TESSELLATION_SPACING_DEFINES
from renderer.gpu.textures import TextureCache
from renderer.gpu.uniforms import DISPLACEMENT_TEXTURE_UNIT
from renderer.methods import open_renderer
from tests.tessellation_capture import STAGE_OUTPUTS, capture_stages, gpu_against_twin, lonely_edge_points

HEIGHTS = Path(__file__).resolve().parents[1] / "assets" / "textures" / "heights.png"
MODEL = transforms.translate(0.2, -0.3, -1.0) @ transforms.rotate_y(0.3) @ transforms.scale(1.1, 1.0, 0.9)
VIEW = transforms.look_at((0.0, 2.5, 3.0), (0.0, 0.0, -1.0), (0.0, 1.0, 0.0))
PROJECTION = transforms.perspective(np.radians(45.0), 4 / 3, 0.1, 50.0)
HEIGHT = 240
SCALE, UV_SCALE, UV_OFFSET = 0.8, (0.25, 0.25), (0.5, 0.5)


def uniforms(fixed=0.0, target=TARGET_PIXEL_ERROR * EDGE_ERROR_SHARE):
    return ControlUniforms(MODEL, VIEW, PROJECTION, HEIGHT, target, 0.0, MAX_LEVEL, fixed)


def patches():
    """A 4 x 4 plane of side 4 (32 patches), its UVs mapped onto the image: corners (P, 3, 3),
    normals (P, 3, 3), lookup coordinates (P, 3, 2), float32."""
    corners, normals, uv = displaced_patches(primitives.plane(4.0, 4))
    st = uv * np.asarray(UV_SCALE, np.float32) + np.asarray(UV_OFFSET, np.float32)
    return corners, normals, st.astype(np.float32)


def heights():
    return load_texture(HEIGHTS, "linear")


def levels_of(texture, u=None):
    corners, normals, st = patches()
    return displaced_patch_levels(corners, normals, st, u or uniforms(), (texture.width, texture.height),
                                  Displacement(texture, SCALE).slope, SCALE)


# -- the scene file ------------------------------------------------------------------------------

def terrain(displacement, mesh=None, shape=None):
    obj = {"name": "terrain", "receives_shadows": False,
           "tessellation": {"error": 0.25, "displacement": displacement}}
    obj |= {"shape": shape} if shape else {"mesh": mesh or {"primitive": "plane", "size": 4.0, "segments": 4}}
    return {"camera": {"eye": [0.0, 2.0, 3.0], "look": [0.0, 0.0, 0.0]},
            "lights": [{"type": "directional", "direction": [0.0, -1.0, -0.2], "shadows": False}],
            "objects": [obj]}


def test_the_displacement_table_is_read():
    obj = scene_from_dict(terrain({"image": str(HEIGHTS), "scale": 0.5, "uv_scale": [0.25, 0.25],
                                   "uv_offset": [0.5, 0.5]})).objects[0]
    assert obj.tessellation.surface == "displaced"
    displacement = obj.tessellation.displacement
    assert (displacement.scale, displacement.uv_scale, displacement.uv_offset) == (0.5, (0.25, 0.25), (0.5, 0.5))
    assert displacement.texture.width == 64 and displacement.slope == pytest.approx(21 / 255)


@pytest.mark.parametrize("displacement, where, words", [
    ({"scale": 0.5}, None, "displacement.image: is required"),
    ({"image": str(HEIGHTS)}, None, "displacement.scale: is required"),
    ({"image": str(HEIGHTS), "scale": 0.5, "colour": 1}, None, "objects[0].tessellation.displacement"),
    ({"image": str(HEIGHTS), "scale": 0.5}, "sphere", "an analytic shape has none to move"),
    ({"image": "missing.png", "scale": 0.5}, None, "image file not found"),
])
def test_a_bad_displacement_table_is_one_line(displacement, where, words):
    data = terrain(displacement, shape={"type": "sphere"} if where == "sphere" else None)
    with pytest.raises(SceneError) as info:
        scene_from_dict(data)
    line = info.value.line()
    assert words in line and "\n" not in line


def test_a_mesh_without_texture_coordinates_cannot_be_displaced(tmp_path):
    (tmp_path / "t.obj").write_text("v 0 0 0\nv 1 0 0\nv 0 0 -1\nf 1 2 3\n")
    data = terrain({"image": str(HEIGHTS), "scale": 0.5}, mesh={"file": str(tmp_path / "t.obj")})
    with pytest.raises(SceneError, match="no texture coordinates"):
        scene_from_dict(data)


# -- the levels, by hand ---------------------------------------------------------------------------

def test_a_flat_height_image_asks_for_level_1():
    flat = texture_from_linear(np.full((16, 16, 3), 0.4), "flat", "linear")
    assert np.all(levels_of(flat) == 1.0)


@pytest.mark.parametrize("target", [TARGET_PIXEL_ERROR * EDGE_ERROR_SHARE, 16.0])
def test_the_edge_level_keeps_the_displaced_edge_within_its_bound(target):
    """Along every patch edge the displaced surface (heights read by the twin's sampler at
    2,001 points, in world units) strays from the chords between ceil(level) equal parts by at
    most the target at the edge's midpoint, or where a part per texel caps the level, by at
    most half the image's largest step between texels, g S_w / 2. At the default target every
    edge of this view is capped; at 16 pixels none is, and the levels follow the distance."""
    texture = heights()
    corners, normals, st = patches()
    u = uniforms(target=target)
    levels = levels_of(texture, u)
    capped_bound = Displacement(texture, SCALE).slope * SCALE * np.linalg.norm(MODEL[:3, :3] @ [0, 1, 0]) / 2
    if target == 16.0:
        assert 1 < levels[:, :3].max() < 16 and len(np.unique(levels)) > 10
    else:
        assert np.all(levels == 16)                          # 64 texels over 4 squares
    world = lambda p: p @ MODEL[:3, :3].T + MODEL[:3, 3]             # noqa: E731
    s = np.linspace(0.0, 1.0, 2001)
    for k in range(3):
        i, j = (k + 1) % 3, (k + 2) % 3
        for patch in range(len(corners)):
            a, b = corners[patch, i].astype(np.float64), corners[patch, j].astype(np.float64)
            sa, sb = st[patch, i].astype(np.float64), st[patch, j].astype(np.float64)
            lookup = sa + (sb - sa) * s[:, None]
            h = sample(texture, DISPLACEMENT_SAMPLER, lookup[:, 0], lookup[:, 1])[:, 0].astype(np.float64)
            points = world(a + (b - a) * s[:, None] + normals[patch, i] * (SCALE * h)[:, None])
            parts = np.ceil(levels[patch, k])
            knots = np.round(np.linspace(0, len(s) - 1, int(parts) + 1)).astype(int)
            chords = np.concatenate([points[k0] + (points[k1] - points[k0]) * ((np.arange(k0, k1) - k0) / (k1 - k0))[:, None]
                                     for k0, k1 in zip(knots, knots[1:])] + [points[-1:]])
            stray = np.linalg.norm(points - chords, axis=1).max()
            mid = np.append(world((a + b) / 2), 1.0) @ (PROJECTION @ VIEW).T
            target_world = u.target_error * 2 * mid[3] / (HEIGHT * PROJECTION[1, 1])
            texels = np.abs(sb - sa) * (texture.width, texture.height)
            capped = levels[patch, k] >= texels.max() * (1 - 1e-6)
            assert stray <= (capped_bound if capped else target_world) * 1.001, (patch, k, stray)
            assert levels[patch, k] <= max(1.0, texels.max() * (1 + 1e-6))


# -- GPU against twin ----------------------------------------------------------------------------

def gpu_capture(ctx, texture, u, spacing):
    corners, normals, st = patches()
    cache = TextureCache(ctx)
    try:
        cache.texture(texture).use(DISPLACEMENT_TEXTURE_UNIT)
        cache.sampler(DISPLACEMENT_SAMPLER).use(DISPLACEMENT_TEXTURE_UNIT)
        # the corners' UVs are the lookup coordinates here: uv_scale 1, uv_offset 0
        rows = np.concatenate([corners, normals, st], axis=2).reshape(-1, 8)
        size = np.asarray([texture.width, texture.height], np.float32)
        return capture_stages(ctx, {"SURFACE_DISPLACED": True, TESSELLATION_SPACING_DEFINES[spacing]: True},
                              rows, "3f 3f 2f", ("in_position", "in_normal", "in_uv"), u,
                              {"u_height": DISPLACEMENT_TEXTURE_UNIT, "u_height_size": tuple(size),
                               "u_height_texel": tuple(np.float32(1) / size),
                               "u_height_slope": Displacement(texture, SCALE).slope,
                               "u_displacement_scale": SCALE, "u_height_uv_scale": (1.0, 1.0),
                               "u_height_uv_offset": (0.0, 0.0)})
    finally:
        cache.sampler(DISPLACEMENT_SAMPLER).clear(DISPLACEMENT_TEXTURE_UNIT)
        cache.release()


def twin(texture, u, spacing):
    corners, normals, st = patches()
    tangent_s, tangent_t = displaced_tangents(corners, st)
    levels = levels_of(texture, u)
    records, edge_points = [], []
    for patch, level in enumerate(levels):
        coords = np.asarray(primitive_vertices(tessellate("triangles", spacing, level[:3], level[3:])), np.float32)

        def each(value):
            return np.broadcast_to(value[patch], (len(coords), *value.shape[1:]))
        position, normal = evaluate_displaced(coords, each(corners), each(normals), each(st), each(tangent_s),
                                              each(tangent_t), texture, SCALE)
        record = np.zeros(len(coords), STAGE_OUTPUTS)
        record["position"], record["normal"], record["levels"] = position, normal, level
        records.append(record)
        edge_points.append((patch, position[(coords == 0).any(axis=1)]))
    return np.concatenate(records), edge_points


@pytest.mark.parametrize("spacing", SPACINGS)
@pytest.mark.parametrize("kind", ["egl", pytest.param("osmesa", marks=pytest.mark.slow)])
def test_the_stages_displace_the_points_as_their_twins_do(gl_contexts, kind, spacing):
    texture, u = heights(), uniforms()
    got = gpu_capture(gl_contexts[kind], texture, u, spacing)
    expected, _ = twin(texture, u, spacing)
    assert len(got) == len(expected)
    for field in ("levels", "position", "normal"):
        assert np.array_equal(got[field].view(np.uint32), expected[field].view(np.uint32)), field
    assert np.ptp(got["position"][:, 1]) > 0.3                   # displaced


def test_no_crack_every_edge_point_is_a_point_of_the_neighbour_too(gl_contexts):
    texture, u = heights(), uniforms()
    got = gpu_capture(gl_contexts["egl"], texture, u, "fractional_odd_spacing")
    _, edge_points = twin(texture, u, "fractional_odd_spacing")
    border = lambda p: np.isclose(np.abs(np.frombuffer(p, np.float32)[[0, 2]]), 2.0).any()   # noqa: E731
    points, lonely = lonely_edge_points(got["position"], edge_points, exempt=border)
    assert points > 300 and not lonely


# -- the rasteriser ------------------------------------------------------------------------------

@pytest.mark.parametrize("kind", ["egl", "osmesa"])
def test_the_builtin_scene_is_drawn_alike_by_the_gpu_and_the_twin(gl_contexts, kind):
    result = gpu_against_twin(load_scene("displaced_plane"), gl_contexts[kind])
    assert PIPELINE_TOLERANCE.passes(result) and result.mismatched_pixels == 0, \
        PIPELINE_TOLERANCE.failures(result)


@pytest.mark.parametrize("table", [{"error": 0.25}, {"level": 1}, {"level": 9.5}])
def test_no_crack_shows_the_background_through_the_displaced_plane(gl_contexts, table):
    data = terrain({"image": str(HEIGHTS), "scale": 1.0, "uv_scale": [0.25, 0.25], "uv_offset": [0.5, 0.5]})
    data["objects"][0]["tessellation"] |= table
    if "level" in table:
        del data["objects"][0]["tessellation"]["error"]
    data["camera"] = {"eye": [0.0, 4.0, 1.5], "look": [0.0, 0.0, 0.0], "fov_y": 60.0}
    with open_renderer(scene_from_dict(data), (160, 120), context=gl_contexts["egl"]) as gpu:
        drawn = gpu.render(depth=False).rgba8[..., 3] > 0
    inside = ndimage.binary_fill_holes(drawn)
    assert drawn.sum() > 3000 and not (inside & ~drawn).any()
