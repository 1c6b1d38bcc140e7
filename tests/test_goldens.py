"""This project's golden images: every built-in scene in each shading mode, at 256x256, and
each scene made for the ray tracer ray traced, and each made for radiosity solved and drawn,
at 160x120, and each made for radiosity path traced (its check) at 160x120.

Each golden is held two ways. The GPU's frame is held against it on EGL and on OSMesa (the
`golden` fixture from renderer/checks/pytest_plugin.py, default policy "threshold"). The golden is
held against the NumPy reference under the rule of tests/test_gpu_vs_reference.py, so a
golden can never drift from the reference unnoticed, not even by `--update-goldens`.

Goldens are tests/goldens/SCENE-MODE.png (+ .json): MODE is flat, gouraud or phong (every
material drawn that way) and, for scenes whose materials mix modes, "as-authored" (the scene
as its file has it); "raytrace" for the GPU ray tracer (renderer/gpu/raytracer.py, 1 sample
per pixel, max depth 4; the distributed effects' scenes with TRACE_OPTIONS, samples that show
their effect), held the same two ways, against the NumPy ray tracer (reference/raytrace/).
"""

import functools
import json
from pathlib import Path

import pytest

from renderer.core.builtin import builtin_scenes
from renderer.checks.compare import compare_frames
from renderer.checks.goldens import read_golden
from renderer.checks.tolerance import PIPELINE_TOLERANCE
from renderer.core.scene import SHADING_MODES
from renderer.core.scene_file import load_scene

from conftest import RADIOSITY_SCENES, RAYTRACE_SCENES, SHADOW_SCENES, raster_scene_params

SIZE = (256, 256)
RAYTRACE_SIZE = (160, 120)
GOLDENS = Path(__file__).parent / "goldens"
AS_AUTHORED = "as-authored"
RAYTRACE = "raytrace"
RADIOSITY = "radiosity"
RADIOSITY_SIZE = (160, 120)


@functools.lru_cache(maxsize=None)
def scene_variant(name, mode):
    scene = load_scene(builtin_scenes()[name])
    return scene if mode == AS_AUTHORED else scene.with_shading(mode)


def variants():
    """(scene, mode) of every golden: each shading mode, plus as-authored where modes mix."""
    out = []
    for name in sorted(builtin_scenes()):
        modes = list(SHADING_MODES)
        if len(scene_variant(name, AS_AUTHORED).shading_modes()) > 1:
            modes.append(AS_AUTHORED)
        out += [(name, mode) for mode in modes]
    return out


VARIANTS = variants()
IDS = [f"{name}-{mode}" for name, mode in VARIANTS]
RENDERED = raster_scene_params(VARIANTS, IDS)       # the ray-tracing scenes' in the full run
# The default run holds each scene's Phong golden (and its as-authored one, where modes mix)
# to the GPU's image, and the Phong one to the reference but for two kinds of scene: the
# shadow scenes, which it holds GPU against reference directly (at 320x240:
# tests/test_gpu_vs_reference.py), and those whose Phong image draws nothing the others' lack
# (NOT_REFERENCE_CHECKED_BY_DEFAULT: sphere's Phong sphere under a directional and a point
# light is coloured_lights' too; gouraud_vs_phong and flat_shading are made for the modes that
# tests/test_shadow_shading.py holds to the reference in the default run, on scenes made for
# it; hierarchy, which tests/test_supersample.py holds GPU against reference in the default
# run, every shading variant and both kinds of shadow map; open_mesh_inside, whose one- and
# two-sided lighting tests/test_shadow_shading.py holds GPU against reference in each mode;
# mesh_file, whose meshes are renderer.core's loaders' triangles, the same for both paths, read
# by hand in tests/test_meshio.py). The full run (--all) holds every golden, every mode, both
# ways.
DEFAULT_MODES = ("phong", AS_AUTHORED)
NOT_REFERENCE_CHECKED_BY_DEFAULT = SHADOW_SCENES | {"sphere", "gouraud_vs_phong", "flat_shading",
                                                    "hierarchy", "open_mesh_inside", "mesh_file"}
GPU_CHECKED = [pytest.param(*p.values, id=p.id, marks=[*p.marks, *(
    [] if p.values[1] in DEFAULT_MODES else [pytest.mark.slow])]) for p in RENDERED]
REFERENCE_CHECKED = [pytest.param(*p.values, id=p.id, marks=[*p.marks, *(
    [] if p.values[1] == "phong" and p.values[0] not in NOT_REFERENCE_CHECKED_BY_DEFAULT
    else [pytest.mark.slow])]) for p in RENDERED]
TRACED = sorted(RAYTRACE_SCENES)
TRACED_IDS = [f"{name}-{RAYTRACE}" for name in TRACED]
# Every ray-traced golden is held to the GPU's frame in the default run (EGL); to the NumPy
# ray tracer only classic's and cornell_box's (mirror, glass, hard shadows, a closed room),
# the others in the full run: the default run holds each of these scenes GPU against the NumPy
# ray tracer at 64x48 (tests/test_raytrace_scenes.py) and each effect's samples on its own
# (tests/test_raytrace_distributed.py, _area_lights, _lens, _motion, _glossy).
TRACED_AGAINST_REFERENCE_BY_DEFAULT = ("classic", "cornell_box")
TRACED_REFERENCE_CHECKED = [pytest.param(name, id=f"{name}-{RAYTRACE}", marks=(
    [] if name in TRACED_AGAINST_REFERENCE_BY_DEFAULT else [pytest.mark.slow])) for name in TRACED]
# One regular sample is a pinhole, a still, a mirror and a point light: the effects' scenes are
# traced with 4 jittered samples (soft_shadows: and 4 points per area light and hit).
EFFECT_SAMPLES = {"samples": 4, "pattern": "jittered"}
TRACE_OPTIONS = {"soft_shadows": {**EFFECT_SAMPLES, "light_samples": 4},
                 "depth_of_field": EFFECT_SAMPLES, "motion_blur": EFFECT_SAMPLES, "glossy": EFFECT_SAMPLES}


def assert_exact_where_made(name, frame):
    """On the GL implementation that made the golden (this machine's llvmpipe; EGL and OSMesa
    draw the same bits), the golden is exact: a change of even one level in one pixel is
    caught when it is introduced, not left to pile up under the policy's tolerance."""
    sidecar = json.loads((GOLDENS / f"{name}.json").read_text())
    made_here = (sidecar["gl_renderer"], sidecar["gl_version"]) == \
        (frame.gl_info.get("GL_RENDERER"), frame.gl_info.get("GL_VERSION"))
    if made_here:
        expected = read_golden(GOLDENS / f"{name}.png")
        differing = int((expected != frame.rgba8).any(axis=2).sum())
        assert differing == 0, (f"{name}: {differing} pixels differ from the golden on the GL "
                                f"implementation that made it; if intended: pytest "
                                f"--update-goldens=all, review, commit")


def assert_matches_reference(png, expected_rgba8, reference_tie=None):
    result = compare_frames(read_golden(png), expected_rgba8, reference_tie=reference_tie)
    failures = PIPELINE_TOLERANCE.failures(result)
    if failures:
        pytest.fail(f"{png.name} drifted from the NumPy reference: {'; '.join(failures)}; largest "
                    f"channel difference {result.max_abs}", pytrace=False)


def golden_png(name):
    png = GOLDENS / f"{name}.png"
    if not png.exists():
        pytest.fail(f"{png} is missing; make it with pytest --update-goldens", pytrace=False)
    return png


# Defined first so that under --update-goldens the goldens are written before the reference
# checks below read them (one process even under -n: the plugin turns pytest-xdist off).
# OSMesa in the full run: the same llvmpipe as EGL, drawing the same bits.
@pytest.mark.parametrize("context_kind", ("egl", pytest.param("osmesa", marks=pytest.mark.slow)))
@pytest.mark.parametrize("name, mode", GPU_CHECKED)
def test_gpu_matches_golden(name, mode, context_kind, gl_contexts, golden):
    frame = golden.check_scene(scene_variant(name, mode), f"{name}-{mode}", size=SIZE,
                               context=gl_contexts[context_kind])
    # Something was drawn: a golden of background only would hold nothing.
    assert (frame.rgba8[..., 3] == 255).mean() > 0.02
    assert_exact_where_made(f"{name}-{mode}", frame)


@pytest.mark.parametrize("name, mode", REFERENCE_CHECKED)
def test_golden_matches_reference(name, mode, reference_frames):
    png = golden_png(f"{name}-{mode}")
    expected = reference_frames(name, *SIZE, shading=None if mode == AS_AUTHORED else mode,
                                depth=False)
    assert_matches_reference(png, expected.rgba8, expected.rgba8_tie)


# OSMesa in the full run: the same llvmpipe as EGL (the same bits), and each tracer costs the
# scene's BVH again (mesh_shadow's: about 0.4 s).
@pytest.mark.parametrize("context_kind", ("egl", pytest.param("osmesa", marks=pytest.mark.slow)))
@pytest.mark.parametrize("name", TRACED, ids=TRACED_IDS)
def test_ray_tracer_matches_golden(name, context_kind, gl_contexts, golden):
    frame = golden.check_scene(scene_variant(name, AS_AUTHORED), f"{name}-{RAYTRACE}",
                               size=RAYTRACE_SIZE, context=gl_contexts[context_kind],
                               method=RAYTRACE, **TRACE_OPTIONS.get(name, {}))
    assert (frame.rgba8[..., 3] == 255).mean() > 0.5
    assert_exact_where_made(f"{name}-{RAYTRACE}", frame)


@pytest.mark.parametrize("name", TRACED_REFERENCE_CHECKED)
def test_ray_traced_golden_matches_reference(name, traced_references):
    png = golden_png(f"{name}-{RAYTRACE}")
    assert_matches_reference(png, traced_references.frame(name, *RAYTRACE_SIZE,
                                                          **TRACE_OPTIONS.get(name, {})).rgba8)


# Radiosity's goldens (its default options: the scene's diagonal / 12 elements, hemicubes of
# 64, Gauss-Seidel), each held to the GPU's frame on EGL (OSMesa in the full run) and to the
# twin (reference/radiosity/) in the full run; the default run holds the GPU against the twin
# on smaller settings (tests/test_radiosity_method.py).
RADIATED = sorted(RADIOSITY_SCENES)
RADIATED_IDS = [f"{name}-{RADIOSITY}" for name in RADIATED]


@pytest.mark.parametrize("context_kind", ("egl", pytest.param("osmesa", marks=pytest.mark.slow)))
@pytest.mark.parametrize("name", RADIATED, ids=RADIATED_IDS)
def test_radiosity_matches_golden(name, context_kind, gl_contexts, golden):
    assert_method_matches_golden(golden, name, RADIOSITY, gl_contexts[context_kind])


def assert_method_matches_golden(golden, name, method, ctx, **options):
    """SCENE-METHOD's golden held to the GPU's frame at RADIOSITY_SIZE (the scene drawing
    something), exactly where the golden was made."""
    frame = golden.check_scene(scene_variant(name, AS_AUTHORED), f"{name}-{method}", size=RADIOSITY_SIZE,
                               context=ctx, method=method, **options)
    assert (frame.rgba8[..., 3] == 255).mean() > 0.02
    assert_exact_where_made(f"{name}-{method}", frame)


@pytest.mark.slow
@pytest.mark.parametrize("name", RADIATED, ids=RADIATED_IDS)
def test_radiosity_golden_matches_reference(name):
    from renderer.methods import open_renderer
    with open_renderer(scene_variant(name, AS_AUTHORED), RADIOSITY_SIZE, method=RADIOSITY,
                       backend="reference") as twin:
        expected = twin.render()
    assert_matches_reference(golden_png(f"{name}-{RADIOSITY}"), expected.rgba8, expected.rgba8_tie)


# The path tracer's goldens (issue 33): each radiosity scene path traced with 16 jittered paths a
# pixel (PATH_OPTIONS: its defaults), held to the GPU's frame on EGL (OSMesa in the full run) and
# to the twin in the full run; the default run holds the GPU against the twin at 40 x 30
# (tests/test_pathtrace.py). The noise is part of the image: the same seed, the same bits.
PATHTRACE = "pathtrace"
PATH_OPTIONS = {"samples": 16}
PATH_TRACED = sorted(RADIOSITY_SCENES)
PATH_TRACED_IDS = [f"{name}-{PATHTRACE}" for name in PATH_TRACED]


@pytest.mark.parametrize("context_kind", ("egl", pytest.param("osmesa", marks=pytest.mark.slow)))
@pytest.mark.parametrize("name", PATH_TRACED, ids=PATH_TRACED_IDS)
def test_path_tracer_matches_golden(name, context_kind, gl_contexts, golden):
    assert_method_matches_golden(golden, name, PATHTRACE, gl_contexts[context_kind], **PATH_OPTIONS)


@pytest.mark.slow
@pytest.mark.parametrize("name", PATH_TRACED, ids=PATH_TRACED_IDS)
def test_path_traced_golden_matches_reference(name):
    from renderer.core.path_options import PathOptions
    from renderer.methods import open_renderer
    with open_renderer(scene_variant(name, AS_AUTHORED), RADIOSITY_SIZE, method=PATHTRACE,
                       backend="reference", options=PathOptions(**PATH_OPTIONS)) as twin:
        expected = twin.render()
    assert_matches_reference(golden_png(f"{name}-{PATHTRACE}"), expected.rgba8, expected.rgba8_tie)


def test_every_golden_belongs_to_a_scene_and_mode():
    """No golden is left behind by a removed scene, and each has its sidecar."""
    on_disk = {path.stem for path in GOLDENS.glob("*.png")}
    assert on_disk == set(IDS) | set(TRACED_IDS) | set(RADIATED_IDS) | set(PATH_TRACED_IDS)
    assert {path.stem for path in GOLDENS.glob("*.json")} == on_disk


@pytest.mark.parametrize("name, mode, size",
                         [(name, mode, SIZE) for name, mode in VARIANTS]
                         + [(name, RAYTRACE, RAYTRACE_SIZE) for name in TRACED]
                         + [(name, RADIOSITY, RADIOSITY_SIZE) for name in RADIATED]
                         + [(name, PATHTRACE, RADIOSITY_SIZE) for name in PATH_TRACED],
                         ids=IDS + TRACED_IDS + RADIATED_IDS + PATH_TRACED_IDS)
def test_sidecar_describes_its_golden(name, mode, size):
    sidecar = json.loads((GOLDENS / f"{name}-{mode}.json").read_text())
    assert sidecar["name"] == f"{name}-{mode}"
    assert sidecar["scene"] == name
    assert sidecar["size"] == list(size)
    assert sidecar["policy"] == {"name": "threshold", "threshold": 2, "deviation": 1, "max_failing_pixels": 0}
    assert sidecar["gl_renderer"] and sidecar["gl_version"] and sidecar["renderer_version"]
