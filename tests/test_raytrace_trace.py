"""The ray tracer end to end (reference/raytrace/trace.py and pipeline.py; glsl/raytrace/
trace.glsl through renderer/gpu/raytracer.py): colours checked by hand (the lighting equation
on the axis, a shadow, a mirror, a glass sphere), the GPU against the reference within
PIPELINE_TOLERANCE on EGL and OSMesa, and the rasteriser against the ray tracer where they
must agree (primary visibility, Phong, no shadows). Small frames: 65 x 49 (odd, so that a
pixel centre lies on the axis) and 64 x 48."""

import numpy as np
import pytest

from reference.lighting import Lights
from reference.raytrace.pipeline import render as reference_raytrace
from reference.raytrace.trace import trace
from renderer.checks.compare import compare_frames
from renderer.checks.tolerance import PIPELINE_TOLERANCE
from renderer.core.raytrace_scene import ray_scene
from renderer.core.scene_file import scene_from_dict

F32 = np.float32
W, H = 65, 49


def scene(objects, materials, lights=(), ambient=(0.1, 0.1, 0.1), background=(0, 0, 0),
          eye=(0, 0, 5), look=(0, 0, 0)):
    return scene_from_dict({"background": list(background), "ambient": list(ambient),
                            "camera": {"eye": list(eye), "look": list(look), "fov_y": 40.0},
                            "materials": materials, "lights": list(lights), "objects": objects})


def centre(frame):
    return frame.linear[H // 2, W // 2, :3].astype(np.float64)


def test_the_lighting_equation_on_the_axis():
    """One sphere, one directional light along -z, camera on the axis: the centre pixel sees
    (0, 0, 1) with N = L = V, so I = I_a k_a + I_l (k_d + k_s); its depth is 5 - 1."""
    ka, kd, ks, ia, il = (0.5, 0.2, 0.1), (0.4, 0.3, 0.2), (0.3, 0.3, 0.3), (0.2, 0.2, 0.2), (0.9, 0.8, 0.7)
    s = scene([{"name": "ball", "shape": {"type": "sphere", "radius": 1.0}, "material": "m"}],
              {"m": {"ka": list(ka), "kd": list(kd), "ks": list(ks), "n": 10.0}},
              [{"type": "directional", "direction": [0, 0, -1], "intensity": list(il)}], ambient=ia)
    frame = reference_raytrace(s, W, H)
    expected = np.multiply(ia, ka) + np.multiply(il, np.add(kd, ks))
    assert np.allclose(centre(frame), expected, atol=1e-5)
    assert frame.depth[H // 2, W // 2] == pytest.approx(4.0, rel=1e-6)
    assert frame.rgba8[H // 2, W // 2, 3] == 255 and frame.rgba8[0, 0, 3] == 0
    assert np.isinf(frame.depth[0, 0])


def test_a_sphere_shadows_the_plane_below_it():
    """A light straight down, a sphere above the plane y = -1: the point below the sphere gets
    the ambient term only, a point beside it ambient plus diffuse (N.L = 1)."""
    ka, kd, ia, il = (0.3, 0.4, 0.5), (0.6, 0.5, 0.4), (0.2, 0.2, 0.2), (0.7, 0.7, 0.7)
    s = scene([{"name": "ball", "shape": {"type": "sphere", "radius": 0.5}, "material": "m",
                "translate": [0, 1, 0]},
               {"name": "floor", "shape": {"type": "plane", "normal": [0, 1, 0], "offset": 1.0},
                "material": "m"}],
              {"m": {"ka": list(ka), "kd": list(kd)}},
              [{"type": "directional", "direction": [0, -1, 0], "intensity": list(il)}], ambient=ia)
    rs = ray_scene(s)
    eye = np.array(s.camera.eye)
    targets = np.array([(0, -1, 0), (2, -1, 0.5)]) - eye
    colour, hit, _ = trace(rs, Lights.from_scene(s, F32, origin=eye), np.zeros((2, 3), F32),
                           targets.astype(F32), 0.0, np.inf, s.background, 4)
    assert hit.all()
    ambient = np.multiply(ia, ka)
    assert np.allclose(colour[0], ambient, atol=1e-6)
    assert np.allclose(colour[1], ambient + np.multiply(il, kd), atol=1e-5)
    # without shadow rays both are lit
    colour, _, _ = trace(rs, Lights.from_scene(s, F32, origin=eye), np.zeros((2, 3), F32),
                         targets.astype(F32), 0.0, np.inf, s.background, 4, shadows=False)
    assert np.allclose(colour[0], ambient + np.multiply(il, kd), atol=1e-5)


# a wall behind the camera (z = 10, facing it), coloured by the ambient light alone
WALL = {"name": "wall", "shape": {"type": "plane", "normal": [0, 0, -1], "offset": 10.0},
        "material": "wall"}
RED_WALL = {"ka": [0.9, 0.1, 0.2], "kd": [0, 0, 0], "two_sided": True}


def test_a_mirror_sphere_reflects_the_wall_behind_the_camera():
    s = scene([{"name": "ball", "shape": {"type": "sphere", "radius": 1.0}, "material": "mirror"}, WALL],
              {"mirror": {"ka": [0, 0, 0], "kd": [0, 0, 0], "kr": [1, 1, 1]}, "wall": RED_WALL},
              ambient=(1, 1, 1), background=(0, 0.5, 0))
    frame = reference_raytrace(s, W, H)
    assert np.allclose(centre(frame), RED_WALL["ka"], atol=1e-6)
    assert np.allclose(frame.linear[0, 0, :3], (0, 0.5, 0))         # the background
    assert np.allclose(centre(reference_raytrace(s, W, H, max_depth=0)), 0)   # no bounce: black


def test_a_glass_sphere_refracts_the_wall_behind_it():
    """Normal incidence through a glass ball (ior 1.5, k_t = 1) onto a wall: Schlick's
    F = R0 = 0.04 at each surface, so (1 - R0)^2 of the wall comes through; the ray reflected
    twice inside would carry (1 - R0) R0^2 = 0.0015, under the weight cut-off 2^-9, and is not
    spawned (renderer/core/ray_depth.py); the reflections towards the camera see the black
    background. Off the axis the ball shows the wall upside down (a lens): the colour of a
    wall with a gradient flips."""
    s = scene([{"name": "ball", "shape": {"type": "sphere", "radius": 1.0}, "material": "glass"},
               {"name": "wall", "shape": {"type": "plane", "normal": [0, 0, 1], "offset": 3.0},
                "material": "wall"}],
              {"glass": {"ka": [0, 0, 0], "kd": [0, 0, 0], "kt": [1, 1, 1], "ior": 1.5},
               "wall": RED_WALL}, ambient=(1, 1, 1))
    frame = reference_raytrace(s, W, H)
    r0 = 0.04
    through = (1 - r0) ** 2
    assert np.allclose(centre(frame), np.multiply(RED_WALL["ka"], through), atol=1e-5)
    # without refraction (max_depth 0) the ball is black
    assert np.allclose(centre(reference_raytrace(s, W, H, max_depth=0)), 0)


def test_a_glass_sphere_flips_the_image_behind_it():
    lit = {"ka": [0, 0, 0], "kd": [1, 1, 1]}
    s = scene([{"name": "ball", "shape": {"type": "sphere", "radius": 1.0}, "material": "glass"},
               {"name": "wall", "shape": {"type": "plane", "normal": [0, 0, 1], "offset": 3.0},
                "material": "wall"}],
              {"glass": {"ka": [0, 0, 0], "kd": [0, 0, 0], "kt": [1, 1, 1], "ior": 1.5}, "wall": lit},
              [{"type": "point", "position": [0, 3, -2.5], "intensity": [1, 1, 1]}], ambient=(0, 0, 0))
    frame = reference_raytrace(s, W, H)
    column = frame.linear[:, W // 2, 0]
    # the wall is brighter towards the light (up) outside the ball, brighter down inside it
    assert column[2] > column[H - 3]
    assert column[H // 2 - 5] < column[H // 2 + 5]


SHAPES = {"background": [0.1, 0.2, 0.3], "ambient": [0.1, 0.1, 0.1],
          "camera": {"eye": [0, 1, 6], "look": [0, 0, 0], "fov_y": 40.0},
          "materials": {"red": {"ka": [0.8, 0.2, 0.1], "kd": [0.8, 0.2, 0.1], "ks": [0.5, 0.5, 0.5], "n": 20.0},
                        "mirror": {"kd": [0, 0, 0], "ka": [0, 0, 0], "kr": [0.9, 0.9, 0.9]},
                        "glass": {"kd": [0, 0, 0], "ka": [0, 0, 0], "kt": [0.9, 0.9, 0.9], "ior": 1.5},
                        "floor": {"kd": [0.6, 0.6, 0.6], "ka": [0.6, 0.6, 0.6], "two_sided": True}},
          "lights": [{"type": "directional", "direction": [0.3, -1, -0.4]},
                     {"type": "point", "position": [2, 3, 3], "intensity": [0.5, 0.5, 0.5]}],
          "objects": [{"name": "a", "shape": {"type": "sphere", "radius": 0.8}, "material": "red", "translate": [-1, 0, 0]},
                      {"name": "b", "shape": {"type": "sphere", "radius": 0.8}, "material": "mirror", "translate": [1, 0, 0]},
                      {"name": "c", "shape": {"type": "sphere", "radius": 0.5}, "material": "glass", "translate": [0, 0, 1.5]},
                      {"name": "f", "shape": {"type": "plane", "normal": [0, 1, 0], "offset": 0.8}, "material": "floor"},
                      {"name": "m", "mesh": {"primitive": "icosphere", "radius": 0.4, "subdivisions": 2},
                       "material": "red", "translate": [0, 1.2, 0]}]}
MESH = {"ambient": [0.1, 0.1, 0.1], "camera": {"eye": [0.3, 0.5, 3.5], "look": [0, 0, 0], "fov_y": 40.0},
        "materials": {"red": {"ka": [0.8, 0.2, 0.1], "kd": [0.8, 0.2, 0.1], "ks": [0.6, 0.6, 0.6], "n": 30.0}},
        "lights": [{"type": "directional", "direction": [1, -1, -1.2], "intensity": [0.85, 0.85, 0.8]},
                   {"type": "point", "position": [3, 0.5, 2.5], "intensity": [0.45, 0.5, 0.65],
                    "attenuation": [1, 0, 0.02]}],
        "objects": [{"name": "ball", "mesh": {"primitive": "uv_sphere", "radius": 1.0, "segments": 24, "rings": 12},
                     "material": "red"}]}


def assert_within_tolerance(result, reference):
    comparison = compare_frames(result.rgba8, reference.rgba8, result.depth, reference.depth,
                                PIPELINE_TOLERANCE.threshold, PIPELINE_TOLERANCE.deviation)
    assert PIPELINE_TOLERANCE.passes(comparison), PIPELINE_TOLERANCE.failures(comparison)


# shapes at 1 sample is the full run's (--all): the same scene at 4 jittered samples stays, and
# one sample a pixel is held on every ray-traced built-in scene (tests/test_raytrace_scenes.py).
@pytest.mark.parametrize("name,samples", [pytest.param("shapes", 1, marks=pytest.mark.slow),
                                          ("shapes", 4), ("mesh", 4)])
def test_gpu_ray_tracer_against_the_reference(gl_contexts, name, samples):
    from renderer.gpu.raytracer import RayTracer
    s = scene_from_dict(SHAPES if name == "shapes" else MESH)
    reference = reference_raytrace(s, 64, 48, samples=samples, pattern="jittered")
    assert 0.2 < (reference.rgba8[..., 3] > 0).mean() < 1.0 or name == "shapes"
    for kind, ctx in gl_contexts.items():
        with RayTracer(s, 64, 48, context=ctx, samples=samples, pattern="jittered") as tracer:
            frame = tracer.render()
        assert frame.gl_info["context"] in (kind, "external")
        assert_within_tolerance(frame, reference)


def test_rasteriser_and_ray_tracer_agree_on_primary_visibility(gl_contexts):
    """One Phong-shaded sphere mesh, no shadow rays, no secondary rays: the ray tracer's hit
    (the same triangles, vertex normals interpolated by barycentrics) and the rasteriser's
    fragment (perspective-correct weights) light the same point the same way."""
    from renderer.gpu.pipeline import GpuRenderer
    from renderer.gpu.raytracer import RayTracer
    s = scene_from_dict(MESH)
    with GpuRenderer(s, 64, 48, context=gl_contexts["egl"]) as raster:
        rasterised = raster.render()
    with RayTracer(s, 64, 48, context=gl_contexts["egl"], shadows=False) as tracer:
        traced = tracer.render()
    assert_within_tolerance(traced, rasterised)
    assert_within_tolerance(reference_raytrace(s, 64, 48, shadows=False), rasterised)


def test_command_line_ray_traces_and_compares(tmp_path, capsys):
    """`renderer render/compare --method raytrace` in this process (small frames); options of
    the ray tracer are refused with the rasteriser, a pattern that cannot make N samples too."""
    import json
    from renderer.cli import main
    assert main(["render", "sphere", "--method", "raytrace", "--spp", "4", "--pattern", "jittered",
                 "--size", "32x24", "--backend", "reference", "-o", str(tmp_path / "rt.png"), "-q"]) == 0
    assert (tmp_path / "rt.png").is_file()
    capsys.readouterr()
    assert main(["compare", "sphere", "--method", "raytrace", "--size", "32x24",
                 "--out", str(tmp_path / "cmp")]) == 0
    figures = json.loads(capsys.readouterr().out)
    assert figures["method"] == "raytrace" and figures["passes"]
    for bad in (["--spp", "4"], ["--method", "raytrace", "--spp", "2"], ["--method", "raytrace", "--max-depth", "65"]):
        assert main(["render", "sphere", "--size", "8x8", "-o", str(tmp_path / "x.png"), *bad]) == 2


def test_memory_estimates_of_the_ray_tracer():
    from renderer.core import memory
    assert memory.raytrace_gpu_bytes(640, 480, 0, samples=16) == memory.raytrace_gpu_bytes(640, 480, 0)
    assert memory.raytrace_reference_bytes(640, 480, 0, samples=16) > memory.raytrace_reference_bytes(640, 480, 0)
    assert memory.raytrace_reference_bytes(10, 10, 1000) > memory.raytrace_reference_bytes(10, 10, 0)

