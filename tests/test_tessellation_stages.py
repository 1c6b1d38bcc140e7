"""The rasteriser's tessellation stages (issue 34; glsl/tess_control.glsl, tess_evaluation.glsl,
twins reference/tessellation/control.py, evaluation.py): a sphere drawn from a coarse patch
mesh, each edge's level from renderer/core/tessellation.py's rule, every generated point on
the exact sphere.

By hand: the rule's level keeps the worst segment's sagitta at the target error (the middle
segment, computed here from the arc it spans) and one level less would not; a flat surface
gets level 1; an edge behind the eye the largest level. GPU against twin, by transform feedback:
every patch's levels, every generated point and normal, bit for bit, in primitive order, on EGL
and OSMesa, for each spacing. Crack-free: every point on a patch edge is, bit for bit, a point
of the neighbouring patch too (the shared edge gets one level, and the tessellator places its
points symmetrically)."""

import numpy as np
import pytest

from reference.tessellation.control import ControlUniforms, edge_levels, patch_levels
from reference.tessellation.evaluation import evaluate
from reference.tessellation.tessellator import primitive_vertices, tessellate
from renderer.core import transforms
from renderer.core.primitives import icosphere
from renderer.core.tessellation import MAX_LEVEL, SPACINGS, TARGET_PIXEL_ERROR
from renderer.gpu.shaders import TESSELLATION_SPACING_DEFINES
from tests.tessellation_capture import STAGE_OUTPUTS, capture_stages

CENTRE, RADIUS = (0.2, 0.1, -0.3), 0.5
MODEL = transforms.translate(1.0, 0.5, -2.0) @ transforms.rotate_y(0.3) @ transforms.scale(1.5, 1.5, 1.5)
VIEW = transforms.look_at((0.0, 1.0, 3.0), (1.0, 0.5, -2.0), (0.0, 1.0, 0.0))
PROJECTION = transforms.perspective(np.radians(50.0), 4 / 3, 0.1, 50.0)
HEIGHT = 240
CAPTURED = STAGE_OUTPUTS


def uniforms(radius_world=1.5 * RADIUS, target=TARGET_PIXEL_ERROR, view=VIEW):
    return ControlUniforms(MODEL, view, PROJECTION, HEIGHT, target, radius_world, MAX_LEVEL)


def patch_mesh(subdivisions=1):
    """The coarse sphere: (patches' corners (P, 3, 3), normals (P, 3, 3)) object space, float32."""
    mesh = icosphere(RADIUS, subdivisions)
    corners = (mesh.positions + np.asarray(CENTRE))[mesh.faces]
    return corners.astype(np.float32), mesh.normals[mesh.faces].astype(np.float32)


def gpu_capture(ctx, corners, normals, u: ControlUniforms, spacing):
    """The evaluation stage's points, normals and levels of every primitive vertex in order
    (a sphere's normals are its own: the stages may drop in_normal)."""
    rows = np.concatenate([corners.reshape(-1, 3), normals.reshape(-1, 3)], axis=1)
    return capture_stages(ctx, {"SURFACE_SPHERE": True, TESSELLATION_SPACING_DEFINES[spacing]: True}, rows,
                          "3f 3f", ("in_position", "in_normal"), u, {"u_sphere": (*CENTRE, RADIUS)})


def twin(corners, normals, u: ControlUniforms, spacing):
    """The same from the twins: levels, the tessellator's primitives, the evaluated points."""
    levels = patch_levels(corners, u)
    records = []
    for patch, level in enumerate(levels):
        t = tessellate("triangles", spacing, level[:3], level[3:])
        coords = primitive_vertices(t)
        position, normal = evaluate(coords, np.repeat(corners[patch][None], len(coords), 0),
                                    np.repeat(normals[patch][None], len(coords), 0), (CENTRE, RADIUS))
        record = np.zeros(len(coords), CAPTURED)
        record["position"], record["normal"], record["levels"] = position, normal, level
        records.append(record)
    return np.concatenate(records), levels


# -- the rule, by hand -------------------------------------------------------------------------

def test_the_level_keeps_the_middle_segments_sagitta_at_the_target():
    """Edges of the coarse sphere: with L = ceil(level) equal parts, the middle part's arc (the
    longest) deviates from its chord by at most the target in pixels at the edge's midpoint;
    with L - 1 parts, by more (where the level is above 1 and below the cap)."""
    corners, _ = patch_mesh()
    u = uniforms()
    world = (corners.reshape(-1, 3).astype(np.float64) @ MODEL[:3, :3].T + MODEL[:3, 3]).reshape(-1, 3, 3)
    a, b = world[:, 1], world[:, 2]
    level = edge_levels(a.astype(np.float32), b.astype(np.float32), u).astype(np.float64)
    R = u.surface_radius
    mid = (PROJECTION @ VIEW @ np.concatenate([(a + b) / 2, np.ones((len(a), 1))], axis=1).T).T
    target_world = TARGET_PIXEL_ERROR * 2 * mid[:, 3] / (HEIGHT * PROJECTION[1, 1])
    c = np.linalg.norm(a - b, axis=1)
    d = np.sqrt(R * R - c * c / 4)

    def sagitta(parts):
        half = np.arctan(c / (2 * parts * d))               # half the middle segment's angle
        return R * (1 - np.cos(half))

    inside = (level > 1) & (level < MAX_LEVEL)
    assert inside.sum() > 20
    parts = np.ceil(level)
    assert np.all(sagitta(parts) <= target_world * (1 + 1e-5))
    assert np.all(sagitta(parts[inside] - 1) > target_world[inside])


def test_a_flat_surface_gets_level_1_and_an_edge_behind_the_eye_the_largest():
    a = np.array([[0.0, 0.0, -5.0]], np.float32)
    b = np.array([[1.0, 0.0, -5.0]], np.float32)
    assert edge_levels(a, b, uniforms(radius_world=0.0))[0] == 1.0
    behind = transforms.look_at((0.0, 0.0, -10.0), (0.0, 0.0, -20.0), (0.0, 1.0, 0.0))
    assert edge_levels(a, b, uniforms(view=behind))[0] == MAX_LEVEL
    assert edge_levels(a, b, uniforms(radius_world=0.3, target=1e9))[0] == 1.0   # error larger than the sphere


# -- GPU against twin ----------------------------------------------------------------------------

@pytest.mark.parametrize("spacing", SPACINGS)
@pytest.mark.parametrize("kind", ["egl", "osmesa"])
def test_the_stages_place_the_points_as_their_twins_do(gl_contexts, kind, spacing):
    corners, normals = patch_mesh()
    u = uniforms()
    got = gpu_capture(gl_contexts[kind], corners, normals, u, spacing)
    expected, levels = twin(corners, normals, u, spacing)
    assert len(np.unique(levels[:, :3])) > 20 and levels.max() > 2           # the levels vary
    assert len(got) == len(expected)
    for field in ("levels", "position", "normal"):
        assert np.array_equal(got[field].view(np.uint32), expected[field].view(np.uint32)), field
    distance = np.linalg.norm(got["position"].astype(np.float64) - CENTRE, axis=1)
    assert np.abs(distance - RADIUS).max() < 1e-6                            # on the sphere


def test_no_crack_every_edge_point_is_a_point_of_the_neighbour_too(gl_contexts):
    corners, normals = patch_mesh()
    got = gpu_capture(gl_contexts["egl"], corners, normals, uniforms(), "fractional_odd_spacing")
    gpu_points = {p.tobytes() for p in got["position"]}
    # the points on each coarse edge (a barycentric coordinate 0), and the patches that make them
    u = uniforms()
    levels = patch_levels(corners, u)
    seen_by = {}
    for patch, level in enumerate(levels):
        t = tessellate("triangles", "fractional_odd_spacing", level[:3], level[3:])
        coords = primitive_vertices(t)
        position, _ = evaluate(coords, np.repeat(corners[patch][None], len(coords), 0),
                               np.repeat(normals[patch][None], len(coords), 0), (CENTRE, RADIUS))
        on_edge = (coords == 0).any(axis=1)
        for p in position[on_edge]:
            seen_by.setdefault(p.tobytes(), set()).add(patch)
    assert seen_by.keys() <= gpu_points
    lonely = [key for key, patches in seen_by.items() if len(patches) < 2]
    assert len(seen_by) > 200 and not lonely          # 282: each made by two patches or more
