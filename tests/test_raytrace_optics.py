"""Camera rays (glsl/raytrace/camera.glsl, reference/raytrace/camera.py, uniforms from
renderer/core/camera_rays.py) and optics (glsl/raytrace/optics.glsl, reference/raytrace/optics.py):
hand-checked angles, the rasteriser's matrices taking a ray's points back to its pixel sample, the
self-intersection offset against the intersect twin, and the GLSL on llvmpipe (EGL, OSMesa)
against the twins (the offset bit for bit)."""

import math
from pathlib import Path

import numpy as np
import pytest

from reference.raytrace.camera import camera_ray, pixel_windows
from reference.raytrace.intersect import ray_plane, ray_sphere
from reference.raytrace.optics import (fresnel_schlick, offset_ray_origin, ray_reflect,
                                       ray_refract)
from renderer.core.camera_rays import camera_ray_uniforms
from renderer.core.sampling import jittered
from renderer.core.scene import Camera, Scene
from renderer.gpu.shaders import shader_source

GLSL = Path(__file__).parent / "glsl"
F32 = np.float32
EPS32 = float(np.finfo(np.float32).eps)


def unit(v):
    v = np.asarray(v, dtype=np.float64)
    return v / np.linalg.norm(v, axis=-1, keepdims=True)


def incoming(theta_deg):
    """A unit direction hitting the plane z = 0 from above (N = +z) at angle theta to the normal."""
    t = math.radians(theta_deg)
    return np.array([math.sin(t), 0.0, -math.cos(t)])


UP = np.array([0.0, 0.0, 1.0])


# -- optics by hand ------------------------------------------------------------------------------

@pytest.mark.parametrize("theta", [0.0, 30.0, 45.0, 60.0, 89.0])
def test_reflection_angle_equals_incidence(theta):
    R = ray_reflect(incoming(theta), UP)
    assert np.allclose(R, [math.sin(math.radians(theta)), 0, math.cos(math.radians(theta))], atol=1e-15)
    # the normal's side does not matter for a reflection; length is kept
    assert np.allclose(ray_reflect(incoming(theta), -UP), R, atol=1e-15)
    assert np.allclose(ray_reflect(3 * incoming(theta), UP), 3 * R, atol=1e-14)


def test_snell_air_to_glass_at_30_degrees():
    refracted, T = ray_refract(incoming(30.0), UP, 1.0 / 1.5)
    assert refracted
    sin_t = math.sin(math.radians(30)) / 1.5                      # = 1/3
    assert math.isclose(T[0], sin_t, abs_tol=1e-15)               # tangential component
    assert math.isclose(T[2], -math.sqrt(1 - sin_t ** 2), abs_tol=1e-15)
    assert math.isclose(np.linalg.norm(T), 1.0, abs_tol=1e-15)
    assert math.isclose(math.degrees(math.asin(T[0])), 19.471220634490695, abs_tol=1e-12)


def test_snell_glass_to_air_and_total_internal_reflection():
    critical = math.degrees(math.asin(1 / 1.5))                   # 41.81 degrees
    assert math.isclose(critical, 41.810314895778596)
    refracted, T = ray_refract(incoming(30.0), UP, 1.5)           # below: refracts, bends away
    assert refracted and math.isclose(T[0], 1.5 * 0.5, abs_tol=1e-15)
    for theta in (critical + 0.01, 45.0, 60.0, 89.0):            # beyond: TIR, T the reflection
        refracted, T = ray_refract(incoming(theta), UP, 1.5)
        assert not refracted
        assert np.allclose(T, ray_reflect(incoming(theta), UP), atol=0)
    refracted, T = ray_refract(incoming(critical - 0.01), UP, 1.5)
    assert refracted and math.isclose(T[0], 1.5 * math.sin(math.radians(critical - 0.01)),
                                      abs_tol=1e-14) and T[0] > 0.9998   # nearly grazing
    refracted, T = ray_refract(incoming(0.0), UP, 1.5)            # normal incidence: straight on
    assert refracted and np.allclose(T, [0, 0, -1], atol=1e-15)
    # batch: 30, 41 (refract), 42, 60 (TIR)
    D = np.stack([incoming(t) for t in (30, 41, 42, 60)])
    assert ray_refract(D, UP, 1.5)[0].tolist() == [True, True, False, False]


def test_schlick_normal_incidence_and_grazing():
    for n1, n2 in ((1.0, 1.5), (1.5, 1.0), (1.0, 1.33)):
        r0 = ((n1 - n2) / (n1 + n2)) ** 2
        assert math.isclose(fresnel_schlick(incoming(0), UP, n1 / n2), r0, rel_tol=1e-14)
    assert math.isclose(fresnel_schlick(incoming(0), UP, 1 / 1.5), 0.04, rel_tol=1e-14)
    assert math.isclose(fresnel_schlick(incoming(90), UP, 1 / 1.5), 1.0, abs_tol=1e-15)
    assert fresnel_schlick(incoming(89.9), UP, 1 / 1.5) > 0.99
    # glass to air: the cosine on the air side; beyond the critical angle F = 1 exactly
    assert fresnel_schlick(incoming(45), UP, 1.5) == 1.0
    cos_t = math.sqrt(1 - (1.5 * 0.5) ** 2)
    assert math.isclose(fresnel_schlick(incoming(30), UP, 1.5), 0.04 + 0.96 * (1 - cos_t) ** 5,
                        rel_tol=1e-14)
    # monotonic in the angle from air
    F = fresnel_schlick(np.stack([incoming(t) for t in range(0, 91, 5)]), UP, 1 / 1.5)
    assert (np.diff(F) >= 0).all()


# -- the self-intersection offset ------------------------------------------------------------------

def ulps_between(a, b):
    a = np.asarray(a, F32).view(np.int32).astype(np.int64)
    b = np.asarray(b, F32).view(np.int32).astype(np.int64)
    a = np.where(a < 0, -(a & 0x7FFFFFFF), a)
    b = np.where(b < 0, -(b & 0x7FFFFFFF), b)
    return np.abs(a - b)


def test_offset_by_hand():
    p = np.array([[1.0, -2.0, 0.01], [100.0, 0.0, -0.03]], F32)
    n = np.array([[0.6, -0.8, 0.0], [0.0, 1.0, -1.0]], F32)
    q = offset_ray_origin(p, n)
    assert q.dtype == F32
    # |p| >= 1/32: int(256 * 0.6) = 153 ulps up (away from zero: p > 0, n > 0); -2 moves
    # int(256 * -0.8) = -204 ulps with the sign flipped: 204 ulps more negative
    assert ulps_between(q[0, 0], p[0, 0]) == 153 and q[0, 0] > p[0, 0]
    assert ulps_between(q[0, 1], p[0, 1]) == 204 and q[0, 1] < p[0, 1]
    assert q[0, 2] == F32(0.01)                                   # near 0, n = 0: p + 0
    assert q[1, 0] == F32(100.0)
    assert q[1, 1] == F32(1 / 65536)                              # near 0: p + n / 65536
    assert q[1, 2] == F32(-0.03) - F32(1 / 65536)


def assert_close_offset(Q, P):
    """Each coordinate moved by at most int_scale = 256 ulps, or, within 1/32 of 0, by at most
    float_scale = 2^-16 (plus the rounding of that sum)."""
    far = np.abs(P) >= F32(1 / 32)
    assert (ulps_between(Q[far], P[far]) <= 256).all()
    step = np.abs(Q[~far].astype(np.float64) - P[~far])
    assert (step <= 2.0 ** -16 + np.spacing(F32(1 / 32))).all()


def test_offset_leaves_plane_and_sphere_and_stays_close():
    rng = np.random.default_rng(6)
    # plane z = c (tilted by a rotation below), hit points at many scales
    for scale in (0.01, 1.0, 100.0, 1e4):
        xy = rng.uniform(-scale, scale, (2000, 2))
        normal = unit([0.3, -0.2, 1.0])
        d = -float(scale) * 0.7
        # points on the plane P.N + d = 0, rounded to float32
        P = np.concatenate([xy, np.zeros((2000, 1))], 1)
        P[:, 2] = -(d + P[:, 0] * normal[0] + P[:, 1] * normal[1]) / normal[2]
        P32, N32 = P.astype(F32), np.broadcast_to(normal.astype(F32), P.shape)
        for side in (+1, -1):                                    # leave to either side
            Q = offset_ray_origin(P32, side * N32)
            # rays leaving into the half space of side*N, every direction there
            D = unit(rng.normal(size=P.shape))
            D = np.where(((D @ normal) * side)[:, None] < 0, -D, D).astype(F32)
            hit, _ = ray_plane(Q, D, normal.astype(F32), F32(d), F32(0), F32(np.inf))
            assert not hit.any(), (scale, side, hit.sum())
            assert_close_offset(Q, P32)
    # sphere of radius r around C, reflected rays leaving outward and refracted ones inward
    for C, r in (((0, 0, 0), 1.0), ((50, -20, 30), 10.0), ((0, 0, -1000), 300.0)):
        C = np.asarray(C, np.float64)
        n = unit(rng.normal(size=(4000, 3)))
        P32 = (C + r * n).astype(F32)
        N32 = unit(P32.astype(np.float64) - C).astype(F32)
        D = unit(rng.normal(size=n.shape))
        outward = np.where(((D * n).sum(-1) < 0)[:, None], -D, D).astype(F32)
        Q = offset_ray_origin(P32, N32)
        hit, s = ray_sphere(Q, outward, C.astype(F32), F32(r), F32(0), F32(np.inf))
        assert not hit.any(), (r, hit.sum())
        # inward: the only hit is the far side, not the point left
        Q = offset_ray_origin(P32, -N32)
        inward = -outward
        hit, s = ray_sphere(Q, inward, C.astype(F32), F32(r), F32(0), F32(np.inf))
        far = Q + s[:, None] * inward
        assert hit.all() and (np.linalg.norm(far.astype(np.float64) - P32, axis=-1) > 1e-3 * r).all()
        assert_close_offset(Q, P32)


# -- camera rays against the rasteriser's matrices -------------------------------------------------

CAMERAS = {
    "perspective": Camera(eye=(3.0, 2.0, 7.0), look=(0.5, -0.25, 0.0), up=(0, 1, 0), fov_y=50.0),
    "perspective far": Camera(eye=(1e5, 2e5, -3e5), look=(1e5 + 1, 2e5, -3e5 + 2), fov_y=30.0,
                              near=0.5, far=1e3, reversed_z=True),
    "parallel": Camera(eye=(-2.0, 4.0, 3.0), look=(0.0, 0.0, 0.0), up=(0, 0, 1),
                       projection="parallel", height=3.0),
}
SIZE = (64, 48)
OFFSETS = [(0.0, 0.0), (0.25, -0.375), (-0.5, 0.4375)] + [tuple(o) for o in jittered(2)]  # incl. the edge -0.5


def window_of(points, view, projection, width, height):
    """The rasteriser's map of camera-relative points (..., 3) to window (x_w, y_w), float64."""
    clip = np.concatenate([points, np.ones(points.shape[:-1] + (1,))], -1) @ (projection @ view).T
    ndc = clip[..., :3] / clip[..., 3:]
    return np.stack([(ndc[..., 0] + 1) * width / 2, (ndc[..., 1] + 1) * height / 2], -1), clip


@pytest.mark.parametrize("name", CAMERAS)
@pytest.mark.parametrize("offset", OFFSETS)
def test_camera_rays_project_back_to_their_pixel_sample(name, offset):
    width, height = SIZE
    scene = Scene(camera=CAMERAS[name])
    plain = scene.matrices(width, height)
    jittered = scene.matrices(width, height, sample_offset=offset)
    windows = pixel_windows(width, height, offset)
    centres = pixel_windows(width, height)
    # two ways to the same rays: the plain matrices at the sample point, or the jittered
    # projection (transforms.jitter, as a supersampling pass) at the pixel centre
    u_plain = camera_ray_uniforms(plain.view, plain.projection, width, height)
    u_jitter = camera_ray_uniforms(jittered.view, jittered.projection, width, height)
    O, D = camera_ray(windows, u_plain)
    O2, D2 = camera_ray(centres, u_jitter)
    assert np.allclose(O, O2, atol=1e-12) and np.allclose(D, D2, atol=1e-12)
    forward = -plain.view[2, :3]
    assert np.allclose(D @ forward, 1.0, atol=1e-12)              # s is the view depth
    cam = scene.camera
    if cam.projection == "perspective":
        assert (O == 0).all()
    else:
        assert np.allclose(O @ forward, 0, atol=1e-12) and np.allclose(D, forward, atol=0)
    for s in (cam.near, 0.5 * (cam.near + cam.far), cam.far * 0.999):
        P = O + s * D
        back, clip = window_of(P, plain.view, plain.projection, width, height)
        assert np.abs(back - windows).max() < 1e-9 * max(1.0, s)
        back, clip = window_of(P, jittered.view, jittered.projection, width, height)
        assert np.abs(back - centres).max() < 1e-9 * max(1.0, s)
        assert np.allclose(-(P @ plain.view[:3, :3].T)[..., 2], s, rtol=1e-12)   # depth s
        # inside the clip volume in x and y (every pixel sample is on screen)
        assert (np.abs(clip[..., :2]) <= clip[..., 3:]).all()
    # in float32 (as the GPU evaluates them) the rays still land within float32 rounding
    O32, D32 = camera_ray(windows.astype(F32), u_plain)
    P = O32.astype(np.float64) + 10.0 * D32.astype(np.float64)
    back, _ = window_of(P, plain.view, plain.projection, width, height)
    assert np.abs(back - windows).max() < 64 * EPS32 * max(width, height)


def test_camera_ray_matches_a_rasterised_point():
    """The ray tracer sees what the rasteriser samples: a point rasterised (by the matrices) at a
    pixel sample lies on that pixel's ray."""
    width, height = SIZE
    scene = Scene(camera=CAMERAS["perspective"])
    m = scene.matrices(width, height)
    u = camera_ray_uniforms(m.view, m.projection, width, height)
    world = np.array([0.3, -0.7, 1.1]) - m.origin                  # camera-relative
    (x, y), clip = window_of(world, m.view, m.projection, width, height)
    O, D = camera_ray(np.array([x, y]), u)
    s = -(m.view[:3, :3] @ world)[2]
    assert np.allclose(O + s * D, world, atol=1e-12)


# -- GLSL against the twins ------------------------------------------------------------------------

WIDTH, HEIGHT = 128, 64


def optics_inputs():
    rng = np.random.default_rng(61)
    N = unit(rng.normal(size=(HEIGHT, WIDTH, 3)))
    D = unit(rng.normal(size=(HEIGHT, WIDTH, 3)))
    D = np.where(((D * N).sum(-1) > 0)[..., None], -D, D)          # D.N <= 0
    eta = rng.choice([1 / 1.5, 1.5, 1 / 1.33, 1.33, 1 / 2.4, 2.4, 1.0], (HEIGHT, WIDTH, 1))
    scale = 10.0 ** rng.uniform(-4, 5, (HEIGHT, WIDTH, 1))
    P = rng.normal(size=(HEIGHT, WIDTH, 3)) * scale
    return (np.concatenate([D, eta], -1).astype(F32), N.astype(F32), P.astype(F32))


def gpu_run(ctx, uniforms, offset, inputs):
    from renderer.gpu.context import activate
    activate(ctx)                   # another test's renderer may have left its own context current
    program = ctx.program(vertex_shader=shader_source("fullscreen.vert", directory=GLSL).text,
                          fragment_shader=shader_source("raytrace_optics.frag", directory=GLSL).text)
    textures = [ctx.texture((WIDTH, HEIGHT), a.shape[-1], np.ascontiguousarray(a).tobytes(), dtype="f4")
                for a in inputs]
    outputs = [ctx.texture((WIDTH, HEIGHT), 4, dtype="f4") for _ in range(5)]
    framebuffer = ctx.framebuffer(outputs)
    vao = ctx.vertex_array(program, [])
    try:
        for unit_, (texture, name) in enumerate(zip(textures, ("u_directions", "u_normals", "u_points"))):
            texture.filter = (ctx.NEAREST, ctx.NEAREST)
            texture.use(unit_)
            program[name].value = unit_
        for name, value in uniforms.items():
            program[name].write(np.asarray(value, np.float64).T.astype(F32).tobytes())  # column-major
        program["u_sample_offset"].value = tuple(offset)
        framebuffer.use()
        vao.render(vertices=3)
        return [np.frombuffer(t.read(), F32).reshape(HEIGHT, WIDTH, 4) for t in outputs]
    finally:
        for thing in (vao, framebuffer, program, *textures, *outputs):
            thing.release()


@pytest.mark.parametrize("name, offset", [("perspective", (0.0, 0.0)), ("parallel", (0.25, -0.375)),
                                          ("perspective far", (-0.5, 0.4375))])
def test_glsl_camera_and_optics_agree_with_the_twins(gl_contexts, name, offset):
    scene = Scene(camera=CAMERAS[name])
    m = scene.matrices(WIDTH, HEIGHT)
    uniforms = camera_ray_uniforms(m.view, m.projection, WIDTH, HEIGHT)
    u32 = {k: v.astype(F32) for k, v in uniforms.items()}
    windows = pixel_windows(WIDTH, HEIGHT, offset, dtype=F32)
    O, D = camera_ray(windows, u32)
    DE, N, P = optics_inputs()
    Din, eta = DE[..., :3], DE[..., 3]
    R = ray_reflect(Din, N)
    F = fresnel_schlick(Din, N, eta)
    refracted, T = ray_refract(Din, N, eta)
    Q = offset_ray_origin(P, N)
    k = 1 - eta.astype(np.float64) ** 2 * (1 - ((Din * N).sum(-1).astype(np.float64)) ** 2)
    assert 0.05 < (~refracted).mean() < 0.5
    # camera tolerance: 4 eps32 of the sum of the terms' magnitudes (a fused multiply-add may
    # round once where the twin rounds twice)
    def bound(U):
        U = np.abs(U.astype(np.float64))
        return 4 * EPS32 * (np.abs(windows[..., :1]) * U[:, 0] + np.abs(windows[..., 1:]) * U[:, 1] + U[:, 2])
    for kind, ctx in gl_contexts.items():
        out_O, out_D, out_R, out_T, out_Q = gpu_run(ctx, uniforms, offset, (DE, N, P))
        assert (np.abs(out_O[..., :3] - O) <= bound(u32["u_ray_origin"])).all(), kind
        assert (np.abs(out_D[..., :3] - D) <= bound(u32["u_ray_direction"])).all(), kind
        # the offset: integer arithmetic on float bits, bit for bit
        assert (out_Q[..., :3].view(np.int32) == Q.view(np.int32)).all(), (kind, (out_Q[..., :3] != Q).sum())
        # reflection: a few eps32 (unit vectors)
        assert np.abs(out_R[..., :3] - R).max() <= 8 * EPS32, kind
        # Schlick: 16 eps32, but from the dense side cos_t = sqrt(k) amplifies k's rounding
        # (and (1 - cos)^5 by up to 5): 16 eps32 (1 + 5 / sqrt(k)) there
        amplified = np.where(eta > 1, 5 / np.sqrt(np.maximum(np.abs(k), EPS32)), 0)
        assert (np.abs(out_R[..., 3] - F) <= 16 * EPS32 * (1 + amplified)).all(), kind
        # refraction: the flag agrees but within float32 rounding of k = 0; T within
        # 16 eps32 (1 + 1 / sqrt(k)) (sqrt amplifies k's rounding near the critical angle)
        gpu_refracted = out_T[..., 3] == 1
        near_critical = np.abs(k) <= 16 * EPS32
        assert not ((gpu_refracted != refracted) & ~near_critical).any(), kind
        both = gpu_refracted == refracted
        error = np.abs(out_T[..., :3] - T).max(-1)
        allowed = 16 * EPS32 * (1 + 1 / np.sqrt(np.maximum(np.abs(k), EPS32)))
        assert (error[both] <= allowed[both]).all(), (kind, error[both].max())
