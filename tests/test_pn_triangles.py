"""PN triangles through the tessellation stages (issue 34; renderer/core/tessellation.py, the
SURFACE_PN paths of glsl/tess_control.glsl and tess_evaluation.glsl, twins
reference/tessellation/control.py pn_net / pn_patch_levels and evaluation.py evaluate_pn).

By hand: which edges stay straight (a cube's creases, none of a smooth mesh's, a cylinder's
rims); the stages' surface, written as the flat triangle plus offsets, is Vlachos et al.'s
cubic Bezier triangle written from the paper's control points in float64; a flat patch stays
flat and a patch's corners are its mesh's; the edge level keeps the edge's cubic within the
target of the chords between ceil(level) equal parts, the worst edge close to it.
GPU against twin, by transform feedback: every patch's levels, every point and normal, bit for
bit, in primitive order, for each spacing, on EGL and OSMesa; the built-in scene pn_triangles
drawn alike at 320 x 240 on both. Crack-free: every point on a patch edge is, bit for bit, a
point of the neighbouring patch too, curved and straight edges alike, and no background pixel
shows inside a closed mesh's outline at fixed levels, by need, and from near and far."""

from pathlib import Path

import numpy as np
import pytest
from scipy import ndimage

from reference.tessellation.control import ControlUniforms, pn_net, pn_patch_levels
from reference.tessellation.evaluation import evaluate_pn
from reference.tessellation.tessellator import primitive_vertices, tessellate
from renderer.checks.tolerance import PIPELINE_TOLERANCE
from renderer.core import primitives, transforms
from renderer.core.scene_file import load_scene, scene_from_dict
from renderer.core.tessellation import (EDGE_ERROR_SHARE, MAX_LEVEL, SPACINGS, TARGET_PIXEL_ERROR,
                                        PatchNet, pn_patches)
from renderer.gpu.shaders import TESSELLATION_SPACING_DEFINES
from renderer.methods import open_renderer
from tests.tessellation_capture import STAGE_OUTPUTS, capture_stages, gpu_against_twin, lonely_edge_points

OCTAHEDRON = Path(__file__).resolve().parents[1] / "assets" / "meshes" / "octahedron.ply"

# a non-uniform scale: the net is made in object space, the levels measure it in world space
MODEL = transforms.translate(0.5, 0.2, -2.0) @ transforms.rotate_y(0.4) @ transforms.scale(1.2, 0.8, 1.0)
VIEW = transforms.look_at((0.0, 1.5, 2.5), (0.5, 0.2, -2.0), (0.0, 1.0, 0.0))
PROJECTION = transforms.perspective(np.radians(50.0), 4 / 3, 0.1, 50.0)
HEIGHT = 240
CAPTURED = STAGE_OUTPUTS


def uniforms(target=TARGET_PIXEL_ERROR * EDGE_ERROR_SHARE, fixed=0.0):
    return ControlUniforms(MODEL, VIEW, PROJECTION, HEIGHT, target, 0.0, MAX_LEVEL, fixed)


def test_an_edge_stays_straight_where_the_mesh_splits_its_normals():
    """A cube's 12 edges (24 patch edges) are creases; its faces' diagonals curve (and are
    flat: the offsets are 0 where the normals are square to the edge). A smooth icosphere or
    torus (its seam's vertices duplicated with equal normals) has none; a cylinder's rims are
    creases, its sides' edges curve."""
    assert pn_patches(primitives.cube()).straight.sum() == 24
    assert pn_patches(primitives.icosphere(1.0, 1)).straight.sum() == 0
    assert pn_patches(primitives.torus(1.0, 0.3, 12, 8)).straight.sum() == 0
    cylinder = pn_patches(primitives.cylinder(1.0, 2.0, 8))
    assert cylinder.straight.sum() == 2 * 2 * 8


def vlachos(corners, normals, t):
    """The paper's cubic Bezier triangle in float64 (Vlachos et al. 2001, its b_ijk and n_ijk),
    at barycentric t (N, 3) of one patch: position and unit normal (N, 3)."""
    P, N = np.asarray(corners, np.float64), np.asarray(normals, np.float64)

    def w(i, j):
        return (P[j] - P[i]) @ N[i]

    def b(i, j):                                        # the net's point near i on the edge to j
        return (2 * P[i] + P[j] - w(i, j) * N[i]) / 3

    edge_points = [b(0, 1), b(1, 0), b(1, 2), b(2, 1), b(2, 0), b(0, 2)]
    E = sum(edge_points) / 6
    V = (P[0] + P[1] + P[2]) / 3
    b111 = E + (E - V) / 2
    u, v, s = t[:, 0:1], t[:, 1:2], t[:, 2:3]
    position = (P[0] * u ** 3 + P[1] * v ** 3 + P[2] * s ** 3
                + 3 * b(0, 1) * u * u * v + 3 * b(1, 0) * u * v * v + 3 * b(1, 2) * v * v * s
                + 3 * b(2, 1) * v * s * s + 3 * b(2, 0) * s * s * u + 3 * b(0, 2) * s * u * u
                + 6 * b111 * u * v * s)

    def n(i, j):
        e = P[j] - P[i]
        h = N[i] + N[j] - 2 * (e @ (N[i] + N[j])) / (e @ e) * e
        return h / np.linalg.norm(h)
    normal = (N[0] * u * u + N[1] * v * v + N[2] * s * s
              + n(0, 1) * u * v + n(1, 2) * v * s + n(2, 0) * s * u)
    return position, normal / np.linalg.norm(normal, axis=1, keepdims=True)


def test_the_stages_surface_is_the_papers_cubic():
    """On a low torus's curved patches, at every point the tessellator makes at level 6, the
    offsets' form equals the paper's control points' within float32 rounding."""
    net = pn_patches(primitives.torus(1.0, 0.35, 10, 6))
    offsets, centres, mids = pn_net(net.positions, net.normals, net.straight)
    t = np.asarray(primitive_vertices(tessellate("triangles", "equal_spacing", [6] * 3, [6])), np.float32)
    worst_position = worst_normal = 0.0
    for patch in range(net.count):
        def each(value):
            return np.broadcast_to(value[patch], (len(t), *value.shape[1:]))
        position, normal = evaluate_pn(t, each(net.positions), each(net.normals), each(offsets),
                                       each(centres), each(mids))
        exact_position, exact_normal = vlachos(net.positions[patch], net.normals[patch], t.astype(np.float64))
        worst_position = max(worst_position, np.abs(position - exact_position).max())
        worst_normal = max(worst_normal, np.abs(normal - exact_normal).max())
    assert worst_position < 1e-6 and worst_normal < 1e-6
    assert np.abs(offsets).max() > 0.02                  # the patches do curve


def test_a_flat_patch_stays_flat_and_its_corners_are_the_meshs():
    corners = np.array([[[0, 0, 0], [1, 0, 0], [0, 1, 0]]], np.float32)
    normals = np.array([[[0, 0, 1]] * 3], np.float32)
    offsets, centre, _ = pn_net(corners, normals, np.zeros((1, 3), np.float32))
    assert not offsets.any() and not centre.any()
    curved = np.array([[[0, 0, 0], [1, 0, 0], [0, 1, 0]]], np.float32)
    bent = np.array([[[-0.6, -0.6, 0.53], [0.6, 0, 0.8], [0, 0.6, 0.8]]], np.float32)
    bent /= np.linalg.norm(bent, axis=2, keepdims=True)
    net = pn_net(curved, bent, np.zeros((1, 3), np.float32))
    t = np.eye(3, dtype=np.float32)
    position, normal = evaluate_pn(t, np.repeat(curved, 3, 0), np.repeat(bent, 3, 0),
                                   *(np.repeat(part, 3, 0) for part in net))
    assert np.array_equal(position, curved[0]) and np.allclose(normal, bent[0], atol=1e-7)


def test_the_edge_level_keeps_the_edges_cubic_within_the_target():
    """Each edge of a coarse torus: its cubic (from the twin's offsets, in float64, in world
    space) strays from the chords between ceil(level) equal parts by at most the target in
    pixels at the edge's midpoint (the fractional spacings' parts are no longer), and the
    worst edge comes close to it: the bound is not loose."""
    net = pn_patches(primitives.torus(1.0, 0.35, 10, 6))
    offsets, _, _ = pn_net(net.positions, net.normals, net.straight)
    u = uniforms()
    levels = pn_patch_levels(net.positions, offsets, np.zeros((net.count, 3), np.float32), u)
    world = lambda p: p @ MODEL[:3, :3].T + MODEL[:3, 3]            # noqa: E731
    checked, closest = 0, []
    for k in range(3):
        i, j = (k + 1) % 3, (k + 2) % 3
        a, b = world(net.positions[:, i].astype(np.float64)), world(net.positions[:, j].astype(np.float64))
        o_ab = offsets[:, 2 * k].astype(np.float64) @ MODEL[:3, :3].T
        o_ba = offsets[:, 2 * k + 1].astype(np.float64) @ MODEL[:3, :3].T
        mid = np.concatenate([(a + b) / 2, np.ones((len(a), 1))], axis=1) @ (PROJECTION @ VIEW).T
        target = u.target_error * 2 * mid[:, 3] / (HEIGHT * PROJECTION[1, 1])

        def stray(parts):                                # the curve's farthest from its chords
            s = np.linspace(0, 1, 401)[None, :, None]
            curve = lambda x: (a[:, None] * (1 - x) + b[:, None] * x + 3 * x * (1 - x)     # noqa: E731
                               * ((1 - x) * o_ab[:, None] + x * o_ba[:, None]))
            points = curve(s)
            knots = np.floor(s * parts[:, None, None]) / parts[:, None, None]
            after = np.minimum(knots + 1 / parts[:, None, None], 1.0)
            x0, x1 = curve(knots), curve(after)
            f = (s - knots) * parts[:, None, None]
            return np.linalg.norm(points - (x0 + (x1 - x0) * f), axis=2).max(axis=1)

        level = levels[:, k].astype(np.float64)
        inside = (level > 1) & (level < MAX_LEVEL)
        parts = np.ceil(level)
        assert np.all(stray(parts) <= target * (1 + 1e-4))
        closest.append((stray(parts[inside]) / target[inside]).max())
        checked += inside.sum()
    assert checked > 50
    assert max(closest) > 0.8             # a bound, and a close one: the worst edge at 0.93 of it


# -- GPU against twin ----------------------------------------------------------------------------

def mesh_patches():
    """A coarse torus (curved every way) and beside it a low cylinder (curved sides, straight
    rims, flat caps), scaled unevenly by MODEL."""
    torus = pn_patches(primitives.torus(0.8, 0.3, 10, 6))
    cylinder = pn_patches(primitives.cylinder(0.6, 1.2, 9))
    beside = np.asarray([2.0, 0.0, 0.0], np.float32)
    return PatchNet(np.concatenate([torus.positions, cylinder.positions + beside]),
                    np.concatenate([torus.normals, cylinder.normals]),
                    np.concatenate([torus.straight, cylinder.straight]))


def gpu_capture(ctx, net, u: ControlUniforms, spacing):
    corners = np.concatenate([net.positions, net.normals, net.straight[..., None]], axis=2).reshape(-1, 7)
    return capture_stages(ctx, {"SURFACE_PN": True, TESSELLATION_SPACING_DEFINES[spacing]: True}, corners,
                          "3f 3f 1f", ("in_position", "in_normal", "in_straight"), u)


def twin(net, u: ControlUniforms, spacing):
    offsets, centres, mids = pn_net(net.positions, net.normals, net.straight)
    levels = pn_patch_levels(net.positions, offsets, centres, u)
    records, edge_points = [], []
    for patch, level in enumerate(levels):
        coords = np.asarray(primitive_vertices(tessellate("triangles", spacing, level[:3], level[3:])), np.float32)

        def each(value):
            return np.broadcast_to(value[patch], (len(coords), *value.shape[1:]))
        position, normal = evaluate_pn(coords, each(net.positions), each(net.normals), each(offsets),
                                       each(centres), each(mids))
        record = np.zeros(len(coords), CAPTURED)
        record["position"], record["normal"], record["levels"] = position, normal, level
        records.append(record)
        edge_points.append((patch, position[(coords == 0).any(axis=1)]))
    return np.concatenate(records), levels, edge_points


@pytest.mark.parametrize("spacing", SPACINGS)
@pytest.mark.parametrize("kind", ["egl", pytest.param("osmesa", marks=pytest.mark.slow)])
def test_the_stages_make_the_pn_points_as_their_twins_do(gl_contexts, kind, spacing):
    net = mesh_patches()
    u = uniforms()
    got = gpu_capture(gl_contexts[kind], net, u, spacing)
    expected, levels, _ = twin(net, u, spacing)
    assert len(np.unique(levels)) > 10 and levels.max() > 3                 # the levels vary
    assert len(got) == len(expected)
    for field in ("levels", "position", "normal"):
        assert np.array_equal(got[field].view(np.uint32), expected[field].view(np.uint32)), field


def test_a_fixed_level_is_every_edges_and_the_inner_one(gl_contexts):
    net = mesh_patches()
    got = gpu_capture(gl_contexts["egl"], net, uniforms(fixed=5.5), "fractional_even_spacing")
    assert np.all(got["levels"] == 5.5)


def test_no_crack_every_edge_point_is_a_point_of_the_neighbour_too(gl_contexts):
    """Along the sides' curved edges and the rims' straight ones alike (the caps' edges on the
    rim are the sides' too)."""
    net = mesh_patches()
    got = gpu_capture(gl_contexts["egl"], net, uniforms(), "fractional_odd_spacing")
    _, _, edge_points = twin(net, uniforms(), "fractional_odd_spacing")
    points, lonely = lonely_edge_points(got["position"], edge_points)
    assert points > 300 and not lonely


# -- the rasteriser ------------------------------------------------------------------------------

@pytest.mark.parametrize("kind", ["egl", "osmesa"])
def test_the_builtin_scene_is_drawn_alike_by_the_gpu_and_the_twin(gl_contexts, kind):
    """pn_triangles at 320 x 240: an octahedron, a torus and a cylinder as PN triangles, levels
    by need; 0 mismatched pixels after the pipeline's allowance."""
    scene = load_scene("pn_triangles")
    assert {o.name for o in scene.objects if o.tessellation} == {"octahedron", "torus", "cylinder"}
    result = gpu_against_twin(scene, gl_contexts[kind])
    assert PIPELINE_TOLERANCE.passes(result) and result.mismatched_pixels == 0, \
        PIPELINE_TOLERANCE.failures(result)


def blob(mesh, table, eye=(0.0, 1.6, 2.2)):
    return scene_from_dict({
        "background": [0.0, 0.0, 0.0], "ambient": [0.2, 0.2, 0.2],
        "camera": {"eye": list(eye), "look": [0.0, 0.0, 0.0], "fov_y": 45.0, "near": 0.05},
        "lights": [{"type": "directional", "direction": [-0.3, -1.0, -0.5], "shadows": False}],
        # back faces culled: through a crack the far side's inside would not hide the background
        "objects": [{"name": "blob", "mesh": mesh, "receives_shadows": False, "tessellation": table,
                     "cull": "back", "material": {"kd": [0.6, 0.6, 0.6], "shading": "gouraud"}}]})


@pytest.mark.parametrize("table", [{"error": 0.25}, {"level": 1}, {"level": 7.3},
                                   {"error": 0.05, "spacing": "fractional_even"}])
@pytest.mark.parametrize("mesh", [{"file": str(OCTAHEDRON)},
                                  {"primitive": "cylinder", "radius": 0.6, "height": 0.8, "segments": 7}])
def test_no_crack_shows_the_background_through_a_closed_mesh(gl_contexts, mesh, table):
    """A closed mesh drawn as PN triangles, seen from above, has no background pixel inside its
    outline: its patches' shared edges, curved (the octahedron's, the cylinder's sides) and
    straight (the cylinder's rims), are the same curve from both sides. (Were the rims curved,
    the sides would bow out from the flat caps: 104 background pixels at level 7.3.)"""
    with open_renderer(blob(mesh, table), (160, 120), context=gl_contexts["egl"]) as gpu:
        drawn = gpu.render(depth=False).rgba8[..., 3] > 0
    inside = ndimage.binary_fill_holes(drawn)
    assert inside.sum() > 2000 and not (inside & ~drawn).any()


@pytest.mark.slow
@pytest.mark.parametrize("distance", [1.2, 2.0, 5.0, 20.0])
def test_no_crack_as_the_camera_comes_closer(gl_contexts, distance):
    scene = blob({"file": str(OCTAHEDRON)}, {"error": 0.25}, eye=(0.0, 0.6 * distance, distance))
    with open_renderer(scene, (160, 120), context=gl_contexts["egl"]) as gpu:
        drawn = gpu.render(depth=False).rgba8[..., 3] > 0
    inside = ndimage.binary_fill_holes(drawn)
    assert inside.sum() > 5 and not (inside & ~drawn).any()
