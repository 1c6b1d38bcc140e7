"""The ray tracer's numerical stability (docs/conventions.md, "Rays": "Self-intersection",
"Hit ties", "Depth", "Grazing rays"): the float64 twin (the ground truth) by hand, rays that
leave an analytic shape, the weight cut-off and the tree's bound, max depth 64 on the GPU, and
`renderer compare`'s accounting of grazing rays. Small frames; the extreme scenes themselves
are tests/test_extremes.py's."""

import json
import re
from dataclasses import replace
from pathlib import Path

import numpy as np
import pytest

import reference.raytrace.trace as trace_module
from reference.raytrace.bvh import closest_hit
from reference.raytrace.intersect import ray_sphere, ray_sphere_from_surface, ray_triangle
from reference.raytrace.optics import offset_ray_origin
from reference.raytrace.pipeline import render as reference_raytrace
from renderer.checks.compare import compare_frames, either_precision
from renderer.checks.tolerance import PIPELINE_TOLERANCE
from renderer.core.bvh import build_bvh
from renderer.core.ray_depth import MAX_DEPTH_LIMIT, RAY_WEIGHT_CUTOFF, RAYS_PER_DEPTH, max_rays
from renderer.core.scene_file import load_scene, scene_from_dict
from renderer.study.extremes import extreme_scenes

ROOT = Path(__file__).resolve().parent.parent
F64 = np.float64


def glsl_constant(name: str) -> str:
    """The value of `const float NAME = ...;` or `#define NAME ...` in trace.glsl."""
    text = (ROOT / "glsl" / "raytrace" / "trace.glsl").read_text()
    return re.search(rf"(?:const float {name} =|#define {name}) ([^;\n]+)", text).group(1)


# -- the float64 twin ---------------------------------------------------------------------------

def test_float64_hits_a_sphere_at_the_analytic_root():
    # from (0, 0, 5) along -z to the sphere of radius sqrt(2) at the origin: s = 5 - sqrt(2)
    O, D = np.array([[0.0, 0.0, 5.0]]), np.array([[0.0, 0.0, -1.0]])
    hit, s = ray_sphere(O, D, (0, 0, 0), np.sqrt(2.0), 0.0, np.inf)
    assert hit[0] and s.dtype == F64 and s[0] == pytest.approx(5 - np.sqrt(2.0), abs=1e-15)
    # from the surface: the other root only, across the sphere inwards, nothing outwards
    P = O + s[:, None] * D
    hit, s = ray_sphere_from_surface(P, D, (0, 0, 0), np.sqrt(2.0), 0.0, np.inf)
    assert hit[0] and s[0] == pytest.approx(2 * np.sqrt(2.0), rel=1e-15)
    assert not ray_sphere_from_surface(P, -D, (0, 0, 0), np.sqrt(2.0), 0.0, np.inf)[0][0]


def test_a_ray_from_a_huge_sphere_does_not_meet_it_again():
    """Radius 1e4, centre 1e4 below: float32's c = f.f - r^2 cancels to a few units, so the
    plain roots put a shadow ray leaving the surface back into it; the root from the surface
    (q / a) does not use c."""
    C, r = np.array([0.0, -10000.0, -6.0], np.float32), np.float32(10000.0)
    rng = np.random.default_rng(3)
    n = np.column_stack([rng.normal(0, 0.02, 2000), np.ones(2000), rng.normal(0, 0.02, 2000)])
    n /= np.linalg.norm(n, axis=1, keepdims=True)
    P = (C + r * n).astype(np.float32)                 # points on the top of the sphere
    L = np.broadcast_to(np.float32([0.3, 0.9, 0.3]) / np.float32(np.sqrt(0.99)), P.shape)
    assert ray_sphere(P, L, C, r, np.float32(0), np.float32(np.inf))[0].any()   # false shadows
    assert not ray_sphere_from_surface(P, L, C, r, np.float32(0), np.float32(np.inf))[0].any()


def test_float64_offset_moves_256_ulps_of_float64():
    p = np.array([[1.0, -2.0, 0.01]])
    q = offset_ray_origin(p, np.array([[0.6, -0.8, 1.0]]))
    assert q.dtype == F64
    assert (q[0, 0] - 1.0) / np.spacing(1.0) == 153                # int(256 * 0.6)
    assert (-2.0 - q[0, 1]) / np.spacing(2.0) == 204               # away from zero, as n says
    assert q[0, 2] == 0.01 + 2.0 ** -45                            # near 0: n 2^-16 eps64/eps32


def test_the_float64_bvh_walk_finds_the_brute_force_hit_of_float64_triangles():
    """Triangles whose float64 vertices float32 cannot hold: the walk widens the float32 boxes
    by an ulp and tests the float64 triangles, so it finds every hit brute force finds."""
    rng = np.random.default_rng(5)
    V = rng.uniform(-1, 1, (60, 3, 3)) * [1, 1, 0.05] + rng.uniform(-1, 1, (60, 1, 3))
    bvh = build_bvh(V)
    O = np.column_stack([rng.uniform(-1.5, 1.5, (300, 2)), np.full(300, 3.0)])
    D = np.column_stack([rng.uniform(-0.3, 0.3, (300, 2)), -np.ones(300)])
    hit, s, _, tri = closest_hit(bvh, O, D, vertices=V)
    assert s.dtype == F64 and hit.sum() > 100
    pairs = (len(O), len(V), 3)
    h, s_all, _ = ray_triangle(np.broadcast_to(O[:, None], pairs), np.broadcast_to(D[:, None], pairs),
                               V[None, :, 0], V[None, :, 1], V[None, :, 2], 0.0, np.inf)
    nearest = np.argmin(s_all, 1)
    assert np.array_equal(hit, h.any(1))
    assert np.array_equal(s[hit], s_all[hit, nearest[hit]]) and np.array_equal(tri[hit], nearest[hit])


def test_float32_and_float64_agree_but_at_grazing_rays():
    scene = load_scene("classic")
    frame32 = reference_raytrace(scene, 48, 36, samples=4, pattern="jittered")
    frame64 = reference_raytrace(scene, 48, 36, samples=4, pattern="jittered", dtype=F64)
    tie, tie_depth, _ = either_precision(frame32, frame64)
    figures = compare_frames(frame32.rgba8, frame64.rgba8, frame32.depth, frame64.depth,
                             reference_tie=tie, reference_tie_depth=tie_depth)
    assert PIPELINE_TOLERANCE.passes(figures), PIPELINE_TOLERANCE.failures(figures)
    assert figures.max_abs <= 1


# -- depth ----------------------------------------------------------------------------------------

def test_the_tree_bound_and_the_glsl_constants():
    assert [max_rays(d) for d in (0, 1, 4, 10, 11, 64)] == [1, 3, 31, 2047, 3583, 84991]
    assert RAYS_PER_DEPTH * RAY_WEIGHT_CUTOFF == 3           # 3 channels of weight 1
    assert glsl_constant("TRACE_WEIGHT_CUTOFF") == "1.0 / 512.0" and RAY_WEIGHT_CUTOFF == 1 / 512
    assert int(glsl_constant("TRACE_RAYS_PER_DEPTH")) == RAYS_PER_DEPTH
    assert eval(glsl_constant("TRACE_HIT_TIE")) == trace_module.HIT_TIE


def mirror_scene(kr: float, wall_depth: float = 4.0):
    """The camera looks at a mirror (k_r = kr, black otherwise) that reflects a wall of
    colour 1 (k_a = 1 under ambient 1) behind the camera."""
    return scene_from_dict({
        "ambient": [1, 1, 1], "camera": {"eye": [0, 0, 5], "look": [0, 0, 0], "fov_y": 20.0},
        "objects": [{"name": "mirror", "shape": {"type": "plane", "normal": [0, 0, 1]},
                     "material": {"ka": 0, "kd": 0, "kr": kr}},
                    {"name": "wall", "shape": {"type": "plane", "normal": [0, 0, -1], "offset": 5 + wall_depth},
                     "material": {"ka": 1, "kd": 0}}]})


def test_a_ray_lighter_than_the_cut_off_is_not_spawned():
    """kr = 2^-9 reflects the wall (colour 2^-9); a weight just below it is not traced at all."""
    at = reference_raytrace(mirror_scene(RAY_WEIGHT_CUTOFF), 9, 7)
    below = reference_raytrace(mirror_scene(0.0019), 9, 7)
    assert np.allclose(at.linear[3, 4, :3], RAY_WEIGHT_CUTOFF, rtol=1e-6)
    assert np.array_equal(below.linear[3, 4, :3], [0, 0, 0])


def test_a_branching_tree_stays_within_the_bound():
    """Glass with k_r = k_t = 0.5 between two such walls: every hit spawns two rays; the
    wavefront of depth d never holds more than min(2^d, 1536) rays per camera ray, and the
    cut-off ends the tree long before depth 64."""
    glass = {"ka": 0, "kd": 0, "kr": 0.5, "kt": 0.5, "ior": 1.5}
    scene = scene_from_dict({
        "camera": {"eye": [0, 0, 0.5], "look": [0.3, 0, -1], "fov_y": 10.0},
        "objects": [{"shape": {"type": "sphere", "centre": [0, 0, -2.0], "radius": 1.0}, "material": glass},
                    {"shape": {"type": "plane", "normal": [0, 0, 1], "offset": 5.0}, "material": glass},
                    {"shape": {"type": "plane", "normal": [0, 0, -1], "offset": 1.0}, "material": glass}]})
    sizes = []
    scene_hit = trace_module.scene_hit

    def counting(rs, O, D, s_min, s_max, *rest):
        if np.ndim(s_max) == 0:                   # a wavefront (shadow rays pass an array)
            sizes.append(len(O))
        return scene_hit(rs, O, D, s_min, s_max, *rest)

    trace_module.scene_hit = counting
    try:
        reference_raytrace(scene, 1, 1, max_depth=MAX_DEPTH_LIMIT, shadows=False)
    finally:
        trace_module.scene_hit = scene_hit
    assert sizes[:3] == [1, 2, 4]
    assert all(n <= min(2 ** d, RAYS_PER_DEPTH) for d, n in enumerate(sizes))
    assert 9 < len(sizes) < MAX_DEPTH_LIMIT and sum(sizes) <= max_rays(MAX_DEPTH_LIMIT)


def test_max_depth_64_on_the_gpu_matches_the_twin(gl_contexts):
    from renderer.gpu.raytracer import RayTracer
    scene = load_scene(extreme_scenes()["rt_mirrors"])
    with RayTracer(scene, 32, 24, context=gl_contexts["egl"], max_depth=MAX_DEPTH_LIMIT) as tracer:
        frame = tracer.render()
        assert tracer.defines["MAX_DEPTH"] == 64
    expected = reference_raytrace(scene, 32, 24, max_depth=MAX_DEPTH_LIMIT)
    figures = compare_frames(frame.rgba8, expected.rgba8, frame.depth, expected.depth)
    assert PIPELINE_TOLERANCE.passes(figures), PIPELINE_TOLERANCE.failures(figures)
    with pytest.raises(ValueError, match="max_depth: must be between 0 and 64, got 65"):
        RayTracer(scene, 8, 8, max_depth=MAX_DEPTH_LIMIT + 1)


# -- `renderer compare` and grazing rays ----------------------------------------------------------

@pytest.fixture
def raytrace_stand_in(monkeypatch):
    """raytrace_stand_in(frame): `compare --method raytrace`'s GPU frame, in this test."""
    from renderer.cli import compare

    def stand_in(frame):
        monkeypatch.setattr(compare, "_render_gpu", lambda scene, args, frames=1:
                            (frame, 1.0, {"GL_RENDERER": "llvmpipe (stand-in)", "context": "stand-in"},
                             None))
    return stand_in


def compare(capsys, tmp_path, scene, size="64x48"):
    from renderer.cli import main
    status = main(["compare", str(scene), "--method", "raytrace", "--size", size,
                   "--out", str(tmp_path / "cmp")])
    return status, json.loads(capsys.readouterr().out)


def test_compare_counts_grazing_rays_and_accepts_either_precision_only_there(
        capsys, tmp_path, raytrace_stand_in):
    """rt_grazing_sphere looks at a sphere's limb through a 1e-5 degree field of view: float32
    and float64 disagree on whole columns of tangent rays. compare counts them and accepts the
    float64 colour there; a mismatch elsewhere still fails; a scene without grazing counts 0."""
    path = extreme_scenes()["rt_grazing_sphere"]
    scene = load_scene(path)
    frame32 = reference_raytrace(scene, 64, 48)
    frame64 = reference_raytrace(scene, 64, 48, dtype=F64)
    grazing = frame32.ray_tree != frame64.ray_tree
    differs = (frame32.rgba8 != frame64.rgba8).any(-1)
    assert (grazing & differs).sum() >= 24                # a column at least
    gpu = replace(frame32, rgba8=np.where(grazing[..., None], frame64.rgba8, frame32.rgba8),
                  depth=np.where(grazing, frame64.depth, frame32.depth), ray_tree=None)
    raytrace_stand_in(gpu)                                # the GPU took float64's side everywhere
    status, figures = compare(capsys, tmp_path, path)
    assert status == 0 and figures["passes"] and figures["mismatched_pixels"] == 0
    assert figures["grazing_ray_pixels"] == grazing.sum() and figures["depth_tie_pixels"] == 0
    far = tuple(np.argwhere(~grazing & ~differs & (frame32.rgba8[..., 3] == 255))[0])
    gpu.rgba8[far] = (255, 255, 255, 255)                 # a mismatch away from the grazing rays
    status, figures = compare(capsys, tmp_path, path)
    assert status == 1 and figures["mismatched_pixels"] == 1 and not figures["passes"]
    calm = extreme_scenes()["rt_tiny_sphere"]              # spheres and a plane, no grazing
    raytrace_stand_in(reference_raytrace(load_scene(calm), 32, 24))
    status, figures = compare(capsys, tmp_path, calm, "32x24")
    assert status == 0 and figures["grazing_ray_pixels"] == 0
