"""Depth of field: the ray tracer's thin lens (docs/conventions.md, "Depth of field";
renderer/core/camera_rays.py lens_uniforms, glsl/raytrace/camera.glsl thin_lens_ray and its twin
reference/raytrace/camera.py). Each rule by hand: the uniforms, lens points inside the disc,
every lens ray of a sample meeting the pinhole ray on the focus plane, s still the view depth;
then the thin-lens formula's circle of confusion, converged in the float64 twin; the limit,
aperture 0 being the pinhole tracer bit for bit (the twin, and the GPU with every feature
compiled in); and the GPU against the twin within PIPELINE_TOLERANCE (small frames here, the
depth_of_field scene at 320x240, 4 and 16 samples, EGL and OSMesa in the full run)."""

import math
from pathlib import Path

import numpy as np
import pytest

from reference.raytrace.camera import camera_ray, lens_point, pixel_windows, thin_lens_ray
from reference.raytrace.pipeline import render as reference_raytrace
from renderer.core.camera_rays import camera_ray_uniforms, lens_uniforms
from renderer.core.ray_sampling import ray_sampling
from renderer.core.scene import Camera
from renderer.core.scene_file import scene_from_dict

from test_raytrace_trace import SHAPES, assert_within_tolerance

F32 = np.float32


def with_camera(data, **camera):
    """A copy of the scene dict `data` with camera keys set."""
    return {**data, "camera": {**data["camera"], **camera}}


# --------------------------------------------------------------------------- the rules by hand

def test_the_camera_keys_and_their_defaults():
    plain = Camera(eye=(0.0, 3.0, 4.0), look=(0.0, 0.0, 0.0))
    assert plain.aperture is None and not plain.has_lens and plain.focus == 5.0
    pinhole = scene_from_dict({"camera": {"aperture": 0}}).camera
    assert pinhole.aperture == 0.0 and not pinhole.has_lens       # a lens of radius 0
    lens = scene_from_dict({"camera": {"aperture": 0.25, "focus_distance": 3.5}}).camera
    assert lens.has_lens and (lens.aperture, lens.focus) == (0.25, 3.5)


def test_the_lens_uniforms_are_the_aperture_times_the_cameras_right_and_up():
    """Looking down -z from (0, 0, 5): right +x, up +y; looking down -x from (5, 0, 0):
    right -z, up +y. 1/f by default from |look - eye|."""
    for eye, right in (((0, 0, 5), (1, 0, 0)), ((5, 0, 0), (0, 0, -1))):
        camera = Camera(eye=eye, look=(0, 0, 0), aperture=0.5)
        view = scene_from_dict({"camera": {"eye": list(eye), "look": [0, 0, 0]}}).matrices(4, 3).view
        u = lens_uniforms(view, camera.aperture, camera.focus)
        assert np.allclose(u["u_lens_right"], np.multiply(0.5, right), atol=1e-15)
        assert np.allclose(u["u_lens_up"], (0, 0.5, 0), atol=1e-15)
        assert u["u_inverse_focus"] == 1 / 5
    zero = lens_uniforms(view, 0.0, 5.0)
    assert not zero["u_lens_right"].any() and not zero["u_lens_up"].any()


LENS_W, LENS_H = 40, 30


def lens_rays(k, dtype=np.float64, aperture=0.3, focus=4.0, pattern="jittered", samples=16):
    """Sample k's pinhole rays (O, D) and lens rays (O', D') of every pixel of a camera
    looking from (1, 2, 5) at the origin, the camera's forward vector, its lens points and
    its uniforms."""
    s = scene_from_dict({"camera": {"eye": [1, 2, 5], "look": [0, 0, 0], "fov_y": 50.0,
                                    "aperture": aperture, "focus_distance": focus}})
    m = s.matrices(LENS_W, LENS_H)
    sampling = ray_sampling(pattern, samples)
    y, x = np.divmod(np.arange(LENS_W * LENS_H, dtype=np.uint32), np.uint32(LENS_W))
    windows = pixel_windows(LENS_W, LENS_H).reshape(-1, 2)
    O, D = camera_ray(windows.astype(dtype), camera_ray_uniforms(m.view, m.projection, LENS_W, LENS_H))
    points = lens_point(x, y, k, 0, sampling, dtype)
    uniforms = lens_uniforms(m.view, aperture, focus)
    O2, D2 = thin_lens_ray(points, O, D, uniforms)
    return O, D, O2, D2, -m.view[2, :3], points, uniforms


def test_lens_points_lie_inside_the_unit_disc_and_the_offsets_inside_the_aperture():
    """Every sample's lens point |l| <= 1 (float32 rounding aside); the origin moves by at
    most the aperture, across the view axis; the points cover the disc (all four quadrants,
    out to beyond 0.9 of the radius)."""
    points = []
    for k in range(16):
        O, _, O2, _, forward, l, _ = lens_rays(k, dtype=F32)
        radius = np.hypot(*l.astype(np.float64).T)
        assert (radius <= 1 + 2 ** -21).all()
        offset = (O2 - O).astype(np.float64)
        assert (np.linalg.norm(offset, axis=-1) <= 0.3 * (1 + 2 ** -20)).all()
        assert np.abs(offset @ forward).max() <= 1e-6
        points.append(l)
    l = np.concatenate(points).astype(np.float64)
    assert np.hypot(*l.T).max() > 0.9
    assert {(bool(a), bool(b)) for a, b in zip(l[:, 0] > 0, l[:, 1] > 0)} == {(True, True), (True, False), (False, True), (False, False)}


def test_every_lens_ray_of_a_sample_meets_its_pinhole_ray_on_the_focus_plane_and_s_is_the_view_depth():
    """In float64: O' + f D' = O + f D for every pixel and sample (the focus plane, view depth
    f = 4, is imaged sharp), and the point O' + s D' lies at view depth s (the eye is the
    camera-relative origin), so near < s < far clips as the rasteriser does."""
    for k in (0, 5, 15):
        O, D, O2, D2, forward, _, _ = lens_rays(k)
        assert np.abs((O2 + 4.0 * D2) - (O + 4.0 * D)).max() <= 1e-14
        for s in (0.5, 4.0, 30.0):
            assert np.allclose((O2 + s * D2) @ forward, s, rtol=1e-14, atol=1e-14)
        assert not np.allclose(O2, O)


# --------------------------------------------------------------------------- the circle of confusion

COC_W, COC_H, COC_FOV, COC_SPP = 96, 64, 30.0, 64
COC_APERTURE, COC_FOCUS = 1.0, 10.0
# Two small self-lit balls (k_a 1 under ambient 1: colour 1 wherever seen, black background),
# one nearer than the focus plane and one beyond it, side by side: (centre, radius) relative to
# the eye, which looks down -z.
COC_BALLS = (((-0.8, 0.0, -5.0), 0.1), ((3.2, 0.0, -20.0), 0.4))


def coc_scene(aperture):
    eye = np.array([0.0, 0.0, 5.0])
    return scene_from_dict({
        "ambient": 1.0, "background": 0.0,
        "camera": {"eye": eye.tolist(), "look": [0, 0, 0], "fov_y": COC_FOV, "far": 100.0,
                   "aperture": aperture, "focus_distance": COC_FOCUS},
        "materials": {"lit": {"ka": 1.0, "kd": 0.0}},
        "objects": [{"name": f"ball{i}", "material": "lit",
                     "shape": {"type": "sphere", "centre": (eye + centre).tolist(), "radius": r}}
                    for i, (centre, r) in enumerate(COC_BALLS)]})


def moments(image, columns):
    """(total, centroid (x, y), mean squared distance from it) of the image's intensity in
    pixel units, over the given column range."""
    part = image[:, columns]
    y, x = np.mgrid[0:part.shape[0], 0:part.shape[1]]
    x = x + columns.start
    total = part.sum()
    cx, cy = (part * x).sum() / total, (part * y).sum() / total
    return total, (cx, cy), (part * ((x - cx) ** 2 + (y - cy) ** 2)).sum() / total


def test_a_defocused_ball_blurs_into_the_thin_lens_circle_of_confusion():
    """A point at view depth z images to a disc of radius a |z - f| / z on the focus plane,
    a |z - f| / z * H / (2 f tan(fov / 2)) pixels (docs/conventions.md): 11.94 px for the ball
    at z = 5, 5.97 px at z = 20 (f = 10, a = 1, H = 64, fov 30 degrees). The lens image of a
    small ball is its pinhole image spread over that disc, so the intensity's second moment
    about its centroid grows by the uniform disc's, R^2 / 2: R is measured from the two
    renders (float64 twin, 64 jittered samples per pixel), within 1.5 % (+ 0.05 px): measured
    -0.1 % and +0.9 %, at 256 samples +0.03 % and +0.26 % (converging on the formula); the
    centroid stays; and no pixel is lit farther than R + (the pinhole image's reach) + a
    pixel's diagonal from it."""
    pinhole = reference_raytrace(coc_scene(0.0), COC_W, COC_H, samples=COC_SPP, pattern="jittered",
                                 dtype=np.float64).linear[..., 0].astype(np.float64)
    lens = reference_raytrace(coc_scene(COC_APERTURE), COC_W, COC_H, samples=COC_SPP,
                              pattern="jittered", dtype=np.float64).linear[..., 0].astype(np.float64)
    pixels_per_unit = COC_H / (2 * COC_FOCUS * math.tan(math.radians(COC_FOV) / 2))
    halves = (slice(0, COC_W // 2), slice(COC_W // 2, COC_W))
    for (centre, _), columns in zip(COC_BALLS, halves):
        z = -centre[2]
        expected = COC_APERTURE * abs(z - COC_FOCUS) / z * pixels_per_unit
        total_p, centroid_p, second_p = moments(pinhole, columns)
        total_l, centroid_l, second_l = moments(lens, columns)
        measured = math.sqrt(2 * (second_l - second_p))
        assert abs(measured - expected) <= 0.015 * expected + 0.05, (z, measured, expected)
        assert np.allclose(centroid_l, centroid_p, atol=0.1)
        y, x = np.nonzero(pinhole[:, columns] > 0)
        reach = np.hypot(x + columns.start - centroid_p[0], y - centroid_p[1]).max()
        y, x = np.nonzero(lens[:, columns] > 0)
        assert np.hypot(x + columns.start - centroid_l[0], y - centroid_l[1]).max() \
            <= expected + reach + math.sqrt(2)


def test_the_depth_of_field_scene_focuses_on_its_middle_sphere(traced_references):
    """The built-in scene's five spheres recede from the camera; the focus plane (the default
    focus distance, |look - eye|) passes the middle one's centre, so its circle of confusion is
    0 there, and at 320x240 the nearest sphere's is over 14 px, the farthest's over 5 px, every
    other's over 2 px."""
    s = traced_references.scene("depth_of_field")
    cam = s.camera
    assert cam.focus_distance is None and cam.aperture > 0
    view = s.matrices(320, 240).view
    spheres = sorted((-(view[:3, :3] @ (np.subtract(o.shape.centre, cam.eye)))[2], o.name)
                     for o in s.objects if o.shape is not None and hasattr(o.shape, "radius"))
    assert [name for _, name in spheres] == ["nearest", "near", "middle", "far", "farthest"]
    scale = 240 / (2 * cam.focus * math.tan(math.radians(cam.fov_y) / 2))
    coc = {name: cam.aperture * abs(z - cam.focus) / z * scale for z, name in spheres}
    assert coc["middle"] < 1e-12
    assert coc["nearest"] > 14 and coc["farthest"] > 5 and min(coc["near"], coc["far"]) > 2


# --------------------------------------------------------------------------- aperture 0

# test_raytrace_trace's shapes (mirror, glass, diffuse spheres, a floor), without its mesh
LIMIT_SCENE = {**SHAPES, "objects": [obj for obj in SHAPES["objects"] if "shape" in obj]}
LIMIT_W, LIMIT_H = 32, 24


def test_aperture_0_is_the_pinhole_camera_bit_for_bit(gl_contexts):
    """The twin runs the lens whenever the camera has an aperture, 0 included, and
    RayTracer(specialise=False) always compiles it in: at aperture 0 (focused anywhere) both
    give the plain tracer's frame of the scene without the key, bit for bit, rgba8 and linear
    (spheres, a plane, mirror and glass: every secondary and shadow ray starts where the
    camera ray's hit is)."""
    from renderer.gpu.raytracer import RayTracer
    plain = scene_from_dict(LIMIT_SCENE)
    zero = scene_from_dict(with_camera(LIMIT_SCENE, aperture=0, focus_distance=2.5))
    options = {"samples": 4, "pattern": "jittered"}
    reference = reference_raytrace(plain, LIMIT_W, LIMIT_H, **options)
    lensed = reference_raytrace(zero, LIMIT_W, LIMIT_H, **options)
    assert np.array_equal(lensed.rgba8, reference.rgba8) and np.array_equal(lensed.linear, reference.linear)
    with RayTracer(plain, LIMIT_W, LIMIT_H, context=gl_contexts["egl"], **options) as tracer:
        assert not tracer.defines["LENS"]
        gpu = tracer.render()
    with RayTracer(zero, LIMIT_W, LIMIT_H, context=gl_contexts["egl"], specialise=False, **options) as every:
        assert every.defines["LENS"]
        gpu_zero = every.render()
    assert np.array_equal(gpu_zero.rgba8, gpu.rgba8) and np.array_equal(gpu_zero.linear, gpu.linear)
    assert_within_tolerance(gpu, reference)


# --------------------------------------------------------------------------- the command line

def test_command_line_aperture_and_focus_distance(tmp_path, cli_here):
    """`--aperture` and `--focus-distance` set the scene's lens for the ray tracer (the image
    changes, and equals the scene file's with those keys); a value the scene file would refuse
    is refused naming the option, status 2, nothing written: the line and the usage as any
    option's range (RayOptions), the line alone where the scene's camera refuses it (a lens
    on a parallel camera); with the rasteriser they are refused (the line and the usage)."""
    from PIL import Image
    small = ["--size", "24x18", "--backend", "reference", "--spp", "4", "--pattern", "jittered", "-q"]
    out = {name: tmp_path / f"{name}.png" for name in ("pinhole", "option", "file")}
    traced = ["render", "depth_of_field", "--method", "raytrace", *small]
    assert cli_here(*traced, "-o", out["pinhole"], "--aperture", "0").returncode == 0
    assert cli_here(*traced, "-o", out["option"], "--aperture", "0.4", "--focus-distance", "3").returncode == 0
    text = (Path(__file__).resolve().parents[1] / "assets" / "scenes" / "depth_of_field.toml").read_text()
    assert "aperture = 0.25\n" in text
    lensed = tmp_path / "lensed.toml"
    lensed.write_text(text.replace("aperture = 0.25\n", "aperture = 0.4\nfocus_distance = 3\n"))
    traced[1] = lensed
    assert cli_here(*traced, "-o", out["file"]).returncode == 0
    image = {name: np.asarray(Image.open(path)) for name, path in out.items()}
    assert np.array_equal(image["option"], image["file"])
    assert not np.array_equal(image["option"], image["pinhole"])
    for args, line in (
            (["sphere", "--method", "raytrace", "--aperture", "-1"],
             "renderer render: --aperture -1: must be >= 0, got -1"),
            (["sphere", "--method", "raytrace", "--aperture", "nan"],
             "renderer render: --aperture nan: expected a finite number, got nan"),
            (["sphere", "--method", "raytrace", "--focus-distance", "0"],
             "renderer render: --focus-distance 0: must be > 0, got 0"),
            (["orthographic", "--method", "raytrace", "--aperture", "0.1"],
             "renderer: --aperture 0.1: must be 0 with a parallel camera, got 0.1: a lens focuses "
             "rays from one eye, and a parallel camera has none"),
            (["sphere", "--aperture", "0.3"], "renderer render: --aperture 0.3: is for method raytrace, not raster")):
        result = cli_here("render", *args, "--size", "8x6", "-o", tmp_path / "no.png")
        assert result.returncode == 2 and result.stderr.splitlines()[0] == line, result.stderr
        assert "Traceback" not in result.stderr and not (tmp_path / "no.png").exists()
        assert len(result.stderr.splitlines()) == (2 if "usage" in result.stderr else 1)
    result = cli_here("compare", "sphere", "--focus-distance", "2", "--out", tmp_path / "cmp")
    assert result.returncode == 2 and result.stderr.startswith(
        "renderer compare: --focus-distance 2: is for method raytrace, not raster")


# --------------------------------------------------------------------------- GPU against twin

def test_gpu_lens_against_the_twin_small(gl_contexts, traced_references):
    """depth_of_field at 64x48, 4 jittered samples (a regular pattern's single sample would
    sit at the lens's centre), EGL: 0 mismatched pixels after the +-1 px allowance."""
    from renderer.gpu.raytracer import RayTracer
    s = traced_references.scene("depth_of_field")
    assert s.camera.has_lens
    reference = traced_references.frame("depth_of_field", 64, 48, samples=4, pattern="jittered")
    with RayTracer(s, 64, 48, context=gl_contexts["egl"], samples=4, pattern="jittered") as tracer:
        assert tracer.defines["LENS"]
        assert_within_tolerance(tracer.render(), reference)


@pytest.mark.slow
@pytest.mark.parametrize("context_kind", ("egl", "osmesa"))
@pytest.mark.parametrize("samples", (4, 16))
def test_gpu_lens_against_the_twin(samples, context_kind, gl_contexts, traced_references):
    """Issue 16's rule on depth_of_field: 320x240, 4 and 16 samples (regular: the lens points
    at the centres of their shuffled strata), EGL and OSMesa; the reference frames are
    traced once per run (the 4-sample one shared with tests/test_raytrace_scenes.py)."""
    from renderer.gpu.raytracer import RayTracer
    with RayTracer(traced_references.scene("depth_of_field"), 320, 240,
                   context=gl_contexts[context_kind], samples=samples) as tracer:
        frame = tracer.render()
    assert frame.gl_info["context"] == context_kind
    assert_within_tolerance(frame, traced_references.frame("depth_of_field", 320, 240, samples=samples))
