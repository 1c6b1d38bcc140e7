"""This project's golden images: every built-in scene in each shading mode, at 256x256.

Each golden is held two ways. The GPU's frame is held against it on EGL and on OSMesa (the
`golden` fixture from renderer/checks/pytest_plugin.py, default policy "threshold"). The golden is
held against the NumPy reference under the rule of tests/test_gpu_vs_reference.py, so a
golden can never drift from the reference unnoticed, not even by `--update-goldens`.

Goldens are tests/goldens/SCENE-MODE.png (+ .json): MODE is flat, gouraud or phong (every
material drawn that way) and, for scenes whose materials mix modes, "as-authored" (the scene
as its file has it).
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

SIZE = (256, 256)
GOLDENS = Path(__file__).parent / "goldens"
AS_AUTHORED = "as-authored"


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


# Defined first so that under --update-goldens the goldens are written before the reference
# checks below read them.
@pytest.mark.parametrize("context_kind", ("egl", "osmesa"))
@pytest.mark.parametrize("name, mode", VARIANTS, ids=IDS)
def test_gpu_matches_golden(name, mode, context_kind, gl_contexts, golden):
    frame = golden.check_scene(scene_variant(name, mode), f"{name}-{mode}", size=SIZE,
                               context=gl_contexts[context_kind])
    # Something was drawn: a golden of background only would hold nothing.
    assert (frame.rgba8[..., 3] == 255).mean() > 0.02
    # On the GL implementation that made the golden (this machine's llvmpipe; EGL and OSMesa
    # draw the same bits), the golden is exact: a change of even one level in one pixel is
    # caught when it is introduced, not left to pile up under the policy's tolerance.
    sidecar = json.loads((GOLDENS / f"{name}-{mode}.json").read_text())
    made_here = (sidecar["gl_renderer"], sidecar["gl_version"]) == \
        (frame.gl_info.get("GL_RENDERER"), frame.gl_info.get("GL_VERSION"))
    if made_here:
        expected = read_golden(GOLDENS / f"{name}-{mode}.png")
        differing = int((expected != frame.rgba8).any(axis=2).sum())
        assert differing == 0, (f"{name}-{mode}: {differing} pixels differ from the golden on the "
                                f"GL implementation that made it; if intended: pytest "
                                f"--update-goldens=all, review, commit")


@pytest.mark.parametrize("name, mode", VARIANTS, ids=IDS)
def test_golden_matches_reference(name, mode, reference_frames):
    png = GOLDENS / f"{name}-{mode}.png"
    if not png.exists():
        pytest.fail(f"{png} is missing; make it with pytest --update-goldens", pytrace=False)
    expected = reference_frames(name, *SIZE, shading=None if mode == AS_AUTHORED else mode,
                                depth=False)
    result = compare_frames(read_golden(png), expected.rgba8, reference_tie=expected.rgba8_tie)
    failures = PIPELINE_TOLERANCE.failures(result)
    if failures:
        pytest.fail(f"{png.name} drifted from the NumPy reference: {'; '.join(failures)}; largest "
                    f"channel difference {result.max_abs}", pytrace=False)


def test_every_golden_belongs_to_a_scene_and_mode():
    """No golden is left behind by a removed scene, and each has its sidecar."""
    on_disk = {path.stem for path in GOLDENS.glob("*.png")}
    assert on_disk == set(IDS)
    assert {path.stem for path in GOLDENS.glob("*.json")} == on_disk


@pytest.mark.parametrize("name, mode", VARIANTS, ids=IDS)
def test_sidecar_describes_its_golden(name, mode):
    sidecar = json.loads((GOLDENS / f"{name}-{mode}.json").read_text())
    assert sidecar["name"] == f"{name}-{mode}"
    assert sidecar["scene"] == name
    assert sidecar["size"] == list(SIZE)
    assert sidecar["policy"] == {"name": "threshold", "threshold": 2, "deviation": 1, "max_failing_pixels": 0}
    assert sidecar["gl_renderer"] and sidecar["gl_version"] and sidecar["renderer_version"]
