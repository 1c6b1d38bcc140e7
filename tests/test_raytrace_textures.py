"""Textured hits in the ray tracer (issue 17; docs/conventions.md, "Textures in the ray
tracer"): renderer/core/ray_textures.py, reference/raytrace/textures.py and
glsl/raytrace/textures.glsl.

By hand: the atan2 both twins share, the sphere rule at known hits (the +z point reads
u = 1/2), a plane's UVs at the `plane` primitive's vertices, a triangle's barycentric UV, a
turned globe moves its marker, a spinning globe at an instant is the globe posed then, and
shutter [0, 0] is the still textured image bit for bit; the slots' limit; untextured scenes
have no texture code. Then the GPU against the twin: a small frame in the default run, the
textured scenes at 320x240, 4 samples, on EGL and OSMesa in the full run.
"""

import dataclasses
import math
from pathlib import Path

import numpy as np
import pytest

from reference.raytrace.pipeline import render as reference_raytrace
from reference.raytrace.textures import texture_uv, texture_sphere_uv, texture_atan2
from reference.raytrace.trace import scene_hit, surface
from renderer.checks.compare import compare_frames
from renderer.checks.tolerance import PIPELINE_TOLERANCE
from renderer.core.builtin import builtin_scenes
from renderer.core.ray_textures import TEXTURE_SLOTS, ray_sampler
from renderer.core.raytrace_scene import ray_scene
from renderer.core.scene_file import load_scene, scene_from_dict
from renderer.core.textures import MaterialTexture, Sampler, Texture, checkerboard, mip_chain
from renderer.errors import SceneError

F32 = np.float32
GREY, RED = (0.5, 0.5, 0.5), (1.0, 0.0, 0.0)


def textured(scene, material_texture, names=None):
    """`scene` with the objects named (every one by default) given `material_texture`."""
    for obj in scene.objects:
        if names is None or obj.name in names:
            obj.material = dataclasses.replace(obj.material, texture=material_texture)
    return scene


def marker_texture(column, width=8, height=4):
    """A grey texture (linear values) with one red column of texels."""
    rgba = np.ones((height, width, 4))
    rgba[..., :3] = GREY
    rgba[:, column, :3] = RED
    return Texture(mip_chain(rgba), f"marker column {column}", "linear")


def globe(rotate_y=0.0, **obj):
    """A unit sphere shape at the origin seen from +z along the axis, ambient light only (k_a
    1, k_d 0), so that a pixel's colour is its texel's."""
    return scene_from_dict({"ambient": [1, 1, 1],
                            "camera": {"eye": [0, 0, 5], "look": [0, 0, 0], "fov_y": 30.0},
                            "objects": [{"name": "globe", "shape": {"type": "sphere", "radius": 1.0},
                                         "rotate": [0, rotate_y, 0], **obj,
                                         "material": {"ka": [1, 1, 1], "kd": [0, 0, 0]}}]})


def rays_at(scene, points, origins=None):
    """The UVs (float64) of the hits of rays from world `origins` (default: the eye) towards
    world `points` (camera-relative float32 rays, as the twins trace)."""
    if not any(obj.material.textured for obj in scene.objects):
        textured(scene, MaterialTexture(checkerboard(2, (GREY, RED), 4)))
    rs = ray_scene(scene)
    eye = np.asarray(scene.camera.eye, np.float64)
    origins = eye if origins is None else np.asarray(origins, np.float64)
    D = (np.asarray(points, np.float64) - origins).astype(F32)
    O = np.broadcast_to(origins - eye, D.shape).astype(F32)
    kind, index, s, uv = scene_hit(rs, O, D, F32(0), F32(np.inf))
    P = surface(rs, O, D, kind, index, s, uv)[0]
    return texture_uv(rs, kind, index, P, uv).astype(np.float64)


# --------------------------------------------------------------------------- by hand

def test_texture_atan2_is_within_3e_7_of_atan2():
    """Both twins' own atan2 (float32) against float64's, over every octant and scale, and at
    the axes exactly: 0, pi/2, pi (y = -0 too: the seam's u is 1 from either side)."""
    rng = np.random.default_rng(17)
    y, x = (rng.standard_normal((2, 100_000)) * 10.0 ** rng.uniform(-6, 6, (2, 100_000))).astype(F32)
    error = np.abs(texture_atan2(y, x).astype(np.float64) - np.arctan2(y.astype(np.float64), x))
    assert error.max() < 3e-7          # about an ulp of pi in float32
    axes = texture_atan2(np.array([0, 1, 0, -0.0, 0, -1], F32), np.array([1, 0, -1, -1, 0, 0], F32))
    assert axes.tolist() == [0.0, F32(np.pi / 2), F32(np.pi), F32(np.pi), 0.0, -F32(np.pi / 2)]


def test_the_sphere_rule_at_known_hits():
    """A ray straight at the sphere's +z point reads u = v = 1/2 exactly; its +x point (to the
    right seen from +z) u = 3/4, -x u = 1/4, the north pole v = 1, the south pole v = 0."""
    points = np.array([(0, 0, 1), (1, 0, 0), (-1, 0, 0), (0, 1, 0), (0, -1, 0)], np.float64)
    uv = rays_at(globe(), points, origins=3 * points)                # each from straight out
    assert uv[0].tolist() == [0.5, 0.5]
    np.testing.assert_allclose(uv[1:3, 0], [0.75, 0.25], atol=1e-6)
    np.testing.assert_allclose(uv[3:, 1], [1.0, 0.0], atol=1e-6)
    d = np.array([[0.3, -0.4, 0.5], [-2, 1, -0.1]], F32)
    expected = [[0.5 + math.atan2(x, z) / (2 * math.pi), 0.5 + math.asin(y / math.dist(p, (0, 0, 0))) / math.pi]
                for p in d.astype(np.float64) for x, y, z in [p]]
    np.testing.assert_allclose(texture_sphere_uv(d), expected, atol=1e-7)      # no normalising needed


def test_a_turned_globe_moves_the_marker():
    """Texel column 5 of 8 red (u in [5/8, 3/4)): the unturned globe shows u = 1/2 at the
    centre pixel, grey; turned by 67.5 degrees about y (the notes' y rotation turns +x towards
    +z: its +x side comes to face the camera) the centre reads u = 1/2 + 67.5/360 = 0.6875,
    the red column's centre."""
    marker = MaterialTexture(marker_texture(5), Sampler("repeat", "nearest"), modulate=("ka",))
    centre = []
    for angle in (0.0, 67.5):
        frame = reference_raytrace(textured(globe(angle), marker), 33, 25)
        centre.append(frame.linear[12, 16, :3])
    np.testing.assert_allclose(centre[0], GREY, atol=1 / 255)       # 0.5 is texel 128
    np.testing.assert_allclose(centre[1], RED, atol=1e-6)
    assert rays_at(globe(67.5), [(0, 0, 1)])[0, 0] == pytest.approx(0.6875, abs=1e-6)


def test_a_planes_uvs_are_the_plane_primitives():
    """An analytic plane (normal +y, offset 0) and a `plane` primitive under the same turned,
    stretched and moved transform: the plane's map at the primitive's world vertices gives the
    primitive's UVs; and a tilted analytic plane's map gives its own tessellation's UVs."""
    transform = {"scale": [2, 1, 0.5], "rotate": [20, 35, -10], "translate": [0.5, -1, -2]}
    scene = scene_from_dict({"camera": {"eye": [1, 2, 6], "look": [0, 0, 0]}, "objects": [
        {"name": "shape", "shape": {"type": "plane", "normal": [0, 1, 0]}, **transform},
        {"name": "tilted", "shape": {"type": "plane", "normal": [0.3, 1, -0.2], "offset": 0.7},
         "rotate": [0, 40, 0]},
        {"name": "mesh", "mesh": {"primitive": "plane", "size": 3.0, "segments": 2}, **transform}]})
    textured(scene, MaterialTexture(checkerboard(2, (GREY, RED), 4)))
    rs = ray_scene(scene)
    eye = np.asarray(scene.camera.eye)
    world = scene.world_matrices()
    for plane, k in ((0, 2), (1, 1)):
        mesh = scene.objects[k].mesh
        points = mesh.positions @ world[k][:3, :3].T + world[k][:3, 3] - eye
        U = rs.textures.plane_map[plane]
        np.testing.assert_allclose(points @ U[:, :3].T + U[:, 3], mesh.uvs, atol=1e-12)


def test_a_triangles_uv_is_its_vertices_weighted_by_the_barycentrics():
    """A hit at barycentrics (u, v) of a triangle reads (1 - u - v) uv_A + u uv_B + v uv_C."""
    scene = scene_from_dict({"camera": {"eye": [0, 0, 5], "look": [0, 0, 0]},
                             "objects": [{"name": "quad", "mesh": {"primitive": "plane"},
                                          "rotate": [90, 0, 0]}]})
    textured(scene, MaterialTexture(checkerboard(2, (GREY, RED), 4)))
    rs = ray_scene(scene)
    points = np.array([(0.3, 0.2, 0.0), (-0.7, -0.1, 0.0), (0.9, -0.9, 0.0)])
    uv = rays_at(scene, points)
    # the plane primitive's rule through the 90-degree turn: u = x, v = -z_object = y
    np.testing.assert_allclose(uv, points[:, :2], atol=1e-6)
    assert len(rs.textures.triangle_uvs) == len(rs.triangles)


def spinning_globe(time=None, spin=0.0):
    """The globe with column 2 red spinning at 90 degrees per unit time about y (the right-hand
    rule, shutter [t, t]), or still (time None) and turned by `spin` degrees (the notes' y
    rotation: -spin by the right-hand rule)."""
    obj = {} if time is None else {"angular_velocity": [0, 90, 0]}
    scene = globe(spin, **obj)
    if time is not None:
        scene.camera = dataclasses.replace(scene.camera, shutter=(time, time))
    return textured(scene, MaterialTexture(marker_texture(2), Sampler("repeat", "nearest"),
                                           modulate=("ka",)))


def test_a_spinning_globe_at_an_instant_is_the_globe_posed_then():
    """Shutter [t, t], t = 0.75: the texture turned by 67.5 degrees with the sphere (the hit
    moved back to its time-0 frame: the centre reads u = 0.3125, the red column) as the still
    globe turned so; at t = 0 (the motion code running) the still unturned globe bit for bit."""
    moving = reference_raytrace(spinning_globe(0.75), 33, 25)
    posed = reference_raytrace(spinning_globe(spin=-67.5), 33, 25)
    np.testing.assert_allclose(moving.linear[12, 16, :3], RED, atol=1e-6)
    assert (moving.rgba8 != posed.rgba8).any(-1).mean() < 0.01        # texel edges may flip
    assert ray_scene(spinning_globe(0.0)).motion is not None
    assert np.array_equal(reference_raytrace(spinning_globe(0.0), 33, 25).rgba8,
                          reference_raytrace(spinning_globe(), 33, 25).rgba8)


def test_the_ray_tracer_reads_level_0_with_the_magnification_filter():
    """The LOD rule: nearest stays nearest, every other filter is bilinear at level 0; the
    wrap is kept; and two materials on one texture and filter share a slot."""
    assert ray_sampler(Sampler("mirror", "nearest")) == Sampler("mirror", "nearest")
    for name in ("bilinear", "mip-nearest", "trilinear"):
        assert ray_sampler(Sampler("clamp", name)) == Sampler("clamp", "bilinear")
    assert ray_sampler(Sampler("repeat", "anisotropic", 8)) == Sampler("repeat", "bilinear")
    image = checkerboard(2, (GREY, RED), 4)
    scene = globe()
    scene.objects.append(dataclasses.replace(scene.objects[0], name="other"))
    textured(scene, MaterialTexture(image, Sampler("repeat", "trilinear")), ["globe"])
    textured(scene, MaterialTexture(image, Sampler("repeat", "bilinear"), uv_scale=(2, 2)), ["other"])
    tx = ray_scene(scene).textures
    assert len(tx.textures) == 1 and tx.slot.tolist() == [0, 0]
    assert tx.uv_transform.tolist() == [[1, 1, 0, 0], [2, 2, 0, 0]]


def test_more_textures_than_slots_is_refused():
    scene = globe()
    scene.objects += [dataclasses.replace(scene.objects[0], name=f"ball {k}") for k in range(TEXTURE_SLOTS)]
    for obj in scene.objects:
        textured(scene, MaterialTexture(checkerboard(2, (GREY, RED), 4)), [obj.name])
    with pytest.raises(SceneError, match=f"at most {TEXTURE_SLOTS} textures"):
        ray_scene(scene)


def test_the_glsl_chain_has_a_branch_per_slot():
    text = (Path(__file__).resolve().parents[1] / "glsl/raytrace/textures.glsl").read_text()
    branches = [int(k) for k in __import__("re").findall(r"TEXTURE_SLOT\((\d+)\)\n", text)]
    assert branches == list(range(TEXTURE_SLOTS))


def test_untextured_scenes_have_no_texture_code(gl_contexts):
    """No material textured: no RayTextures, no TEXTURES define, no sampler array or texture
    lookup in the program (every feature compiled in too)."""
    from renderer.gpu.raytracer import RayTracer
    scene = globe()
    assert ray_scene(scene).textures is None
    for specialise in (True, False):
        with RayTracer(scene, 8, 6, context=gl_contexts["egl"], specialise=specialise) as tracer:
            assert "TEXTURES" not in tracer.defines and "NUM_TEXTURES" not in tracer.defines
            for name in ("u_textures", "u_texture_materials", "u_sphere_rotation"):
                assert name not in tracer.program


# --------------------------------------------------------------------------- GPU against twin

def assert_within_tolerance(frame, reference):
    result = compare_frames(frame.rgba8, reference.rgba8, frame.depth, reference.depth,
                            PIPELINE_TOLERANCE.threshold, PIPELINE_TOLERANCE.deviation)
    assert PIPELINE_TOLERANCE.passes(result), (PIPELINE_TOLERANCE.failures(result), result.as_dict())


def mixed_scene(sampler):
    """A turned textured sphere, a textured floor and a textured cube (its primitive's UVs) under
    a directional and a point light, k_a, k_d and k_s all modulated, uv_scale 2 on the floor."""
    scene = scene_from_dict({
        "background": [0.1, 0.1, 0.2],
        "camera": {"eye": [0, 1.5, 6], "look": [0, 0, 0], "fov_y": 45.0},
        "materials": {"shiny": {"kd": [0.9, 0.9, 0.9], "ks": [0.3, 0.3, 0.3], "n": 20},
                      "matte": {"kd": [0.8, 0.8, 0.8]}},
        "lights": [{"type": "directional", "direction": [-1, -1, -1]},
                   {"type": "point", "position": [2, 3, 2]}],
        "objects": [{"name": "ball", "shape": {"type": "sphere", "radius": 1.0}, "material": "shiny",
                     "rotate": [20, 30, 0], "translate": [-1, 0, 0]},
                    {"name": "floor", "shape": {"type": "plane", "normal": [0, 1, 0], "offset": 1.0},
                     "material": "matte", "rotate": [0, 15, 0]},
                    {"name": "box", "mesh": {"primitive": "cube", "size": 1.0}, "material": "matte",
                     "translate": [1.5, 0, 0], "rotate": [0, 30, 0]}]})
    image = checkerboard(8, ((1.0, 0.2, 0.2), (0.2, 0.2, 1.0)), 64)
    textured(scene, MaterialTexture(image, sampler, modulate=("ka", "kd", "ks")), ["ball", "box"])
    return textured(scene, MaterialTexture(image, sampler, uv_scale=(2.0, 2.0)), ["floor"])


@pytest.mark.parametrize("sampler", [Sampler("repeat", "nearest"), Sampler("mirror", "trilinear")],
                         ids=["nearest-repeat", "trilinear-mirror"])
def test_the_gpu_textures_hits_as_the_twin_small(sampler, gl_contexts):
    """64 x 48, 1 sample, EGL: within the pipeline tolerance, and textured (the box and ball
    are not one colour)."""
    from renderer.gpu.raytracer import RayTracer
    scene = mixed_scene(sampler)
    reference = reference_raytrace(scene, 64, 48)
    with RayTracer(scene, 64, 48, context=gl_contexts["egl"]) as tracer:
        assert tracer.defines["TEXTURES"] and tracer.defines["NUM_TEXTURES"] == 1
        frame = tracer.render()
    assert_within_tolerance(frame, reference)
    assert len(np.unique(reference.rgba8[10:40, 10:30].reshape(-1, 4), axis=0)) > 20


def test_a_textured_tracer_follows_a_new_eye(gl_contexts):
    """update() after the eye moved (the planes' UV maps are camera-relative) draws what a new
    tracer draws, bit for bit."""
    from renderer.gpu.raytracer import RayTracer
    scene = mixed_scene(Sampler("repeat", "bilinear"))
    ctx = gl_contexts["egl"]
    with RayTracer(scene, 40, 30, context=ctx) as tracer:
        tracer.render()
        scene.camera = dataclasses.replace(scene.camera, eye=(1.0, 2.5, 5.0))
        tracer.update()
        moved = tracer.render()
    with RayTracer(scene, 40, 30, context=ctx) as tracer:
        fresh = tracer.render()
    assert np.array_equal(moved.rgba8, fresh.rgba8) and np.array_equal(moved.depth, fresh.depth)


def test_the_gpu_textures_moving_shapes_as_the_twin_small(gl_contexts):
    """Motion blur: a spinning textured globe over a sliding textured floor, shutter [0, 1],
    4 jittered samples, 48 x 36 on EGL: within the tolerance."""
    from renderer.gpu.raytracer import RayTracer
    scene = spinning_globe(0.0)
    scene.camera = dataclasses.replace(scene.camera, shutter=(0.0, 1.0))
    floor = scene_from_dict({"objects": [{"name": "floor", "velocity": [0.5, 0, 0],
                                          "shape": {"type": "plane", "normal": [0, 0, 1], "offset": 1.5},
                                          "material": {"ka": [1, 1, 1], "kd": [0, 0, 0]}}]}).objects[0]
    scene.objects.append(floor)
    textured(scene, MaterialTexture(checkerboard(4, (GREY, RED), 16), Sampler("clamp", "bilinear"),
                                    uv_scale=(0.5, 0.5), modulate=("ka",)), ["floor"])
    options = dict(samples=4, pattern="jittered")
    reference = reference_raytrace(scene, 48, 36, **options)
    with RayTracer(scene, 48, 36, context=gl_contexts["egl"], **options) as tracer:
        assert tracer.defines["MOTION"] and tracer.defines["TEXTURES"]
        frame = tracer.render()
    assert_within_tolerance(frame, reference)


SCENE_DIR = Path(__file__).resolve().parent / "scenes"
# The analytic shapes' textured scenes (tests/scenes/), and the built-in textured scenes (meshes:
# a UV sphere, a plane primitive, a glTF box) where the rasteriser's branch has brought them.
TEXTURED_SCENES = [str(SCENE_DIR / f"{name}.toml") for name in ("rt_globe", "rt_checker_horizon")] \
    + [name for name in ("globe", "checker_horizon", "textured_mesh") if name in builtin_scenes()]


def with_filter(scene, name):
    """`scene` with every texture sampled by filter `name` (its wrap kept)."""
    for obj in scene.objects:
        if obj.material.textured:
            sampler = Sampler(obj.material.texture.sampler.wrap, name)
            textured(scene, dataclasses.replace(obj.material.texture, sampler=sampler), [obj.name])
    return scene


@pytest.fixture(scope="module")
def textured_references():
    """The twin's 320 x 240, 4 jittered sample frame of each textured scene and filter, once."""
    frames = {}

    def frame(name, filter_name):
        if (name, filter_name) not in frames:
            scene = with_filter(load_scene(name), filter_name)
            frames[name, filter_name] = (scene, reference_raytrace(scene, 320, 240, samples=4,
                                                                   pattern="jittered"))
        return frames[name, filter_name]
    return frame


@pytest.mark.slow
@pytest.mark.parametrize("context_kind", ("egl", "osmesa"))
@pytest.mark.parametrize("filter_name", ("nearest", "trilinear"))
@pytest.mark.parametrize("name", TEXTURED_SCENES, ids=lambda name: Path(name).stem)
def test_the_gpu_textures_the_scenes_as_the_twin(name, filter_name, context_kind, gl_contexts,
                                                 textured_references):
    """320 x 240, 4 jittered samples, EGL and OSMesa: within PIPELINE_TOLERANCE (trilinear is
    read as bilinear at level 0, the LOD rule)."""
    from renderer.gpu.raytracer import RayTracer
    scene, reference = textured_references(name, filter_name)
    with RayTracer(scene, 320, 240, context=gl_contexts[context_kind], samples=4,
                   pattern="jittered") as tracer:
        frame = tracer.render()
    assert frame.gl_info["context"] == context_kind
    assert_within_tolerance(frame, reference)


@pytest.mark.slow
def test_level_0_aliases_and_samples_average_it_out(gl_contexts):
    """The checkerboard to the horizon at 160 x 120 against 256 jittered samples (GPU): the
    RMSE (0-255) falls from 1 regular sample to 4 and 16 jittered ones, about as 1/sqrt(N)
    (measured 22.6, 10.3, 4.5; benchmarks/bench_texture_aliasing.py prints them), and most of
    it is the texture's: the untextured plane's edges leave under a tenth of it."""
    from renderer.gpu.raytracer import RayTracer
    scene = load_scene(str(SCENE_DIR / "rt_checker_horizon.toml"))

    def frame(samples, pattern, untextured=False):
        s = scene
        if untextured:
            s = dataclasses.replace(scene, objects=[dataclasses.replace(
                obj, material=dataclasses.replace(obj.material, texture=None)) for obj in scene.objects])
        with RayTracer(s, 160, 120, context=gl_contexts["egl"], samples=samples, pattern=pattern) as rt:
            return rt.render().rgba8[..., :3].astype(np.float64)

    def rmse(a, b):
        return float(np.sqrt(np.mean((a - b) ** 2)))
    truth = frame(256, "jittered")
    errors = [rmse(frame(n, p), truth) for n, p in ((1, "regular"), (4, "jittered"), (16, "jittered"))]
    assert errors[0] > 1.5 * errors[1] > 2.25 * errors[2] > 0
    assert errors[0] > 10                                           # level 0 aliases
    assert rmse(frame(1, "regular", True), frame(256, "jittered", True)) < errors[0] / 10


def test_the_glsl_sphere_rule_is_the_twins(gl_contexts):
    """textures.glsl's texture_sphere_uv and texture_atan2 against the twin's on 64 x 64
    directions of every octant and scale (the axes and -0 among them), EGL: bit for bit."""
    from glsl_harness import ShaderProbe
    rng = np.random.default_rng(3)
    d = (rng.standard_normal((64 * 64, 3)) * 10.0 ** rng.uniform(-3, 3, (64 * 64, 1))).astype(F32)
    d[:8] = [(0, 0, 1), (1, 0, 0), (-1, 0, 0), (0, 1, 0), (0, -1, 0), (-0.0, 0, -1), (0, 0, -1), (0, 0, 0)]
    ctx = gl_contexts["egl"]
    with ShaderProbe(ctx, "raytrace_textures.frag", {}, (64, 64), 4, dtype="f4") as probe:
        inputs = ctx.texture((64, 64), 4, np.concatenate([d, np.zeros((len(d), 1), F32)], 1).tobytes(),
                             dtype="f4")
        inputs.use(0)
        out = probe.run(u_inputs=0).reshape(-1, 4)
        inputs.release()
    assert np.array_equal(out[:, :2], texture_sphere_uv(d))
    assert np.array_equal(out[:, 2], texture_atan2(d[:, 1], d[:, 0]))
