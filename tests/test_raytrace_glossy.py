"""Glossy reflection (docs/conventions.md, "Glossy reflection"; glsl/raytrace/trace.glsl's
glossy_direction, reference/raytrace/glossy.py's glossy_reflection): the reflected ray drawn
from the Phong lobe about the mirror direction, absorbed below the surface, gloss = inf the
mirror exactly. Hand-checked cases first (the lobe's mean cosine, the half of a lobe that lies
under a surface, a glossy floor's reflection of a white sky), then the limit (gloss = inf
draws the mirror tracer's image bit for bit, on the GPU with every feature compiled in and in
the twin, which runs the lobe's code), then the GPU against the twin under PIPELINE_TOLERANCE:
small frames in the default run, the built-in scene `glossy` at 320x240 in the full run.
The lobe's density itself is held by tests/test_sampler_statistics.py."""

import dataclasses
import math

import numpy as np
import pytest

from reference.raytrace import glossy as twin_glossy
from reference.raytrace.pipeline import render as reference_raytrace
from reference.raytrace.glossy import glossy_reflection
from renderer.checks.compare import compare_frames
from renderer.checks.tolerance import PIPELINE_TOLERANCE
from renderer.core.scene_file import load_scene, scene_from_dict

F32 = np.float32
EPS32 = float(np.finfo(F32).eps)


def grid_points(side: int) -> np.ndarray:
    """(side^2, 2) float32 centres of a side x side grid of the unit square: a quadrature rule
    for averages over the lobe (exact for what is linear in u within a cell)."""
    c = (np.arange(side, dtype=np.float64) + 0.5) / side
    return np.stack(np.meshgrid(c, c), -1).reshape(-1, 2).astype(F32)


def unit(v) -> np.ndarray:
    v = np.asarray(v, np.float64)
    return (v / np.linalg.norm(v)).astype(F32)


def assert_within_tolerance(frame, reference):
    result = compare_frames(frame.rgba8, reference.rgba8, frame.depth, reference.depth,
                            PIPELINE_TOLERANCE.threshold, PIPELINE_TOLERANCE.deviation)
    assert PIPELINE_TOLERANCE.passes(result), (PIPELINE_TOLERANCE.failures(result), result.as_dict())


def with_gloss(scene, gloss):
    """The scene with every material's gloss set to `gloss` (None: unset)."""
    objects = [dataclasses.replace(o, material=dataclasses.replace(o.material, gloss=gloss))
               for o in scene.objects]
    return dataclasses.replace(scene, objects=objects)


# --------------------------------------------------------------------------- by hand

@pytest.mark.parametrize("gloss", [0.0, 1.0, 10.0, 1000.0, 1e6])
def test_the_lobe_about_the_mirror_direction_has_the_closed_form_mean_cosine(gloss):
    """Over the lobe (e + 1)/(2 pi) cos^e alpha about R, E[cos alpha] = the integral of
    (e + 1) cos^(e+1) alpha sin alpha over [0, pi/2] = (e + 1)/(e + 2): 1/2 for the uniform
    hemisphere (e = 0), 2/3, 11/12, 1001/1002. cos alpha = (1 - u0)^(1/(e+1)) depends on u0
    alone: the midpoint rule over 2^16 cells of u0 (its error below 2e-7: the integrand's
    derivative is infinite at u0 = 1), u1 spread by the golden ratio. Every direction is unit
    within 4 eps32 and, with Ng = R, none is absorbed."""
    R = unit([1.0, 2.0, 3.0])
    n = 1 << 16
    k = np.arange(n, dtype=np.float64)
    u = np.stack([(k + 0.5) / n, (k * 0.6180339887498949) % 1.0], -1).astype(F32)
    D, kept = glossy_reflection(np.tile(R, (n, 1)), np.tile(R, (n, 1)), np.full(n, gloss), u)
    assert D.dtype == F32 and kept.all()
    assert np.abs(np.linalg.norm(D.astype(np.float64), axis=1) - 1).max() <= 4 * EPS32
    mean_cosine = (D.astype(np.float64) @ R.astype(np.float64)).mean()
    assert mean_cosine == pytest.approx((gloss + 1) / (gloss + 2), abs=1e-6)


def test_a_sample_below_the_surface_is_absorbed_and_a_mirror_never_is():
    """R lying in the surface (R.Ng = 0): a lobe sample's height above the surface is
    sin alpha cos(phi - phi_R), so the samples whose phi is within 90 degrees of the surface's
    side are kept: exactly half of a grid of u1 (none lies on the boundary). Kept is D.Ng > 0,
    sample by sample. The mirror (gloss inf) keeps R itself, bit for bit, even where R does not
    leave the surface."""
    Ng = unit([0.0, 1.0, 0.0])
    R = unit([1.0, 0.0, 0.0])
    u = grid_points(64)
    n = len(u)
    for gloss in (1.0, 50.0):
        D, kept = glossy_reflection(np.tile(R, (n, 1)), np.tile(Ng, (n, 1)), np.full(n, gloss), u)
        assert kept.sum() == n // 2
        assert np.array_equal(kept, D @ Ng > 0)
    D, kept = glossy_reflection(np.tile(R, (n, 1)), np.tile(Ng, (n, 1)), np.full(n, np.inf), u)
    assert kept.all() and np.array_equal(D, np.tile(R, (n, 1)))


SKY = 0.8


def floor_under_the_sky(gloss):
    """A mirror floor (k_r = 1, no local colour, no lights) under a uniform sky (the
    background SKY), seen by a parallel camera at 45 degrees: every camera ray meets it at the
    same angle, so R is 45 degrees from the floor's normal in every pixel."""
    return scene_from_dict({
        "background": [SKY] * 3, "ambient": [0, 0, 0],
        "camera": {"eye": [0, 5, 5], "look": [0, 0, 0], "projection": "parallel", "height": 4.0},
        "materials": {"floor": {"ka": 0, "kd": 0, "kr": 1, "gloss": gloss}},
        "objects": [{"name": "floor", "shape": {"type": "plane", "normal": [0, 1, 0]},
                     "material": "floor"}]})


def test_a_rough_floor_reflects_the_sky_but_where_its_lobe_dips_under_it(gl_contexts):
    """gloss 0 (the uniform hemisphere about R) with R at gamma = 45 degrees from Ng: the part
    of the hemisphere under the floor is the lune between the two great circles, 2 gamma of its
    2 pi steradians, so a pixel's expected colour is SKY (1 - gamma/pi) = 0.6; each kept ray
    sees the sky. Averaged over 48 x 36 pixels of 4 jittered samples (6,912 rays, stratified
    per pixel: the binomial spread of the mean is below 0.0042, 0.015 is 3.5 of it). The mirror
    (gloss inf) reflects all of the sky."""
    from renderer.gpu.raytracer import RayTracer
    expected = SKY * (1 - (math.pi / 4) / math.pi)
    scene = floor_under_the_sky(0.0)
    twin = reference_raytrace(scene, 48, 36, samples=4, pattern="jittered")
    with RayTracer(scene, 48, 36, context=gl_contexts["egl"], samples=4, pattern="jittered") as tracer:
        gpu = tracer.render()
    for frame in (twin, gpu):
        assert (frame.rgba8[..., 3] == 255).all()
        assert frame.linear[..., :3].mean() == pytest.approx(expected, abs=0.015)
    assert np.array_equal(twin.rgba8, gpu.rgba8)
    mirror = reference_raytrace(floor_under_the_sky(math.inf), 48, 36, samples=4, pattern="jittered")
    assert np.allclose(mirror.linear[..., :3], SKY)


# --------------------------------------------------------------------------- the limit

def test_gloss_inf_is_the_mirror_bit_for_bit(gl_contexts, monkeypatch):
    """The built-in glossy scene with every gloss set to inf against the same scene with gloss
    unset (the plain tracer: no GLOSSY define, no lobe code in the twin): identical rgba8 and
    linear, on the GPU with every feature compiled in (specialise=False, GLOSSY on) and in the
    twin, whose lobe code runs (counted) wherever a material sets gloss."""
    from renderer.gpu.raytracer import RayTracer
    glossy = load_scene("glossy")
    infinite, plain = with_gloss(glossy, math.inf), with_gloss(glossy, None)
    options = dict(samples=4, pattern="jittered")
    ctx = gl_contexts["egl"]
    with RayTracer(plain, 48, 36, context=ctx, **options) as tracer:
        assert not tracer.defines["GLOSSY"]
        expected = tracer.render()
    with RayTracer(infinite, 48, 36, context=ctx, **options) as tracer:
        assert not tracer.defines["GLOSSY"]              # no finite gloss: nothing to draw
    with RayTracer(infinite, 48, 36, context=ctx, specialise=False, **options) as tracer:
        assert tracer.defines["GLOSSY"]
        every = tracer.render()
    assert np.array_equal(every.rgba8, expected.rgba8)
    assert np.array_equal(every.linear, expected.linear)

    calls = []
    monkeypatch.setattr(twin_glossy, "glossy_reflection",
                        lambda *a: calls.append(len(a[0])) or glossy_reflection(*a))
    twin_plain = reference_raytrace(plain, 48, 36, **options)
    assert not calls
    twin_infinite = reference_raytrace(infinite, 48, 36, **options)
    assert sum(calls) > 1000
    assert np.array_equal(twin_infinite.rgba8, twin_plain.rgba8)
    assert np.array_equal(twin_infinite.linear, twin_plain.linear)


# --------------------------------------------------------------------------- GPU against twin

def extreme_exponents():
    """The glossy scene with exponent 1 on the floor and the rough sphere and 1e6 on the
    others (issue 16's extremes)."""
    scene = load_scene("glossy")
    objects = [dataclasses.replace(o, material=dataclasses.replace(
        o.material, gloss=1.0 if o.name in ("floor", "rough") else 1e6)) for o in scene.objects]
    return dataclasses.replace(scene, objects=objects)


@pytest.mark.parametrize("case", ["glossy", "exponents 1 and 1e6"])
def test_gpu_glossy_reflection_matches_the_twin_small(case, gl_contexts):
    """The default run's check: 48x36, 4 jittered samples, EGL."""
    from renderer.gpu.raytracer import RayTracer
    scene = load_scene("glossy") if case == "glossy" else extreme_exponents()
    with RayTracer(scene, 48, 36, context=gl_contexts["egl"], samples=4, pattern="jittered") as tracer:
        assert tracer.defines["GLOSSY"]
        frame = tracer.render()
    reference = reference_raytrace(scene, 48, 36, samples=4, pattern="jittered")
    assert np.isfinite(frame.linear).all() and np.isfinite(reference.linear).all()
    assert_within_tolerance(frame, reference)


@pytest.mark.slow
@pytest.mark.parametrize("context_kind", ("egl", "osmesa"))
@pytest.mark.parametrize("samples", (4, 16))
def test_gpu_glossy_reflection_matches_the_twin(samples, context_kind, gl_contexts, traced_references):
    """Issue 16's rule on the built-in scene glossy: 320x240, 4 and 16 jittered samples, EGL
    and OSMesa (each reference frame traced once: conftest's traced_references). The regular
    pattern at 1 and 4 samples: tests/test_raytrace_scenes.py."""
    from renderer.gpu.raytracer import RayTracer
    with RayTracer(traced_references.scene("glossy"), 320, 240, context=gl_contexts[context_kind],
                   samples=samples, pattern="jittered") as tracer:
        frame = tracer.render()
    assert frame.gl_info["context"] == context_kind
    assert_within_tolerance(frame, traced_references.frame("glossy", 320, 240, samples=samples,
                                                           pattern="jittered"))
