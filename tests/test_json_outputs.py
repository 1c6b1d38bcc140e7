"""Every JSON the project prints or writes is standard JSON (RFC 8259): no NaN, no Infinity.

Python's json module writes `NaN` and `Infinity` unless told not to, and strict parsers
(jq, JavaScript's JSON.parse) refuse them. Each output below is parsed strictly; the one
helper that writes JSON (renderer/core/jsonio.py) refuses a non-finite number outright, and
no other module calls json.dump or json.dumps.
"""

import ast
import json
import math
from pathlib import Path

import numpy as np
import pytest

from renderer.core.jsonio import finite_or_none, to_json, write_json

ROOT = Path(__file__).resolve().parents[1]
SIZE = (32, 24)


def strict_loads(text: str):
    """json.loads that refuses NaN, Infinity and -Infinity (which json.loads accepts)."""
    def refuse(constant):
        raise ValueError(f"not standard JSON: {constant}")
    return json.loads(text, parse_constant=refuse)


def test_strict_loads_refuses_what_python_writes_by_default():
    with pytest.raises(ValueError, match="Infinity"):
        strict_loads(json.dumps({"psnr": math.inf}))
    with pytest.raises(ValueError, match="NaN"):
        strict_loads(json.dumps([math.nan]))


@pytest.mark.parametrize("value", [math.inf, -math.inf, math.nan, np.float64("nan")])
def test_the_helper_refuses_a_non_finite_number_anywhere(value, tmp_path):
    with pytest.raises(ValueError):
        to_json({"a": [1, {"b": value}]})
    with pytest.raises(ValueError):
        write_json(tmp_path / "x.json", {"a": value})
    assert list(tmp_path.iterdir()) == []                      # nothing half-written


def test_finite_or_none():
    assert finite_or_none(1.5) == 1.5 and finite_or_none(0.0) == 0.0
    assert finite_or_none(math.inf) is None and finite_or_none(math.nan) is None
    assert finite_or_none(None) is None


def test_no_module_writes_json_but_the_helper():
    """json.dump / json.dumps appear only in renderer/core/jsonio.py."""
    found = []
    for path in sorted([*ROOT.glob("renderer/**/*.py"), *ROOT.glob("reference/**/*.py")]):
        for node in ast.walk(ast.parse(path.read_text())):
            if (isinstance(node, ast.Attribute) and node.attr in ("dump", "dumps")
                    and isinstance(node.value, ast.Name) and node.value.id == "json"):
                found.append(f"{path.relative_to(ROOT)}:{node.lineno}")
    assert {place.split(":")[0] for place in found} == {"renderer/core/jsonio.py"}


# -- each output ------------------------------------------------------------------------------

def test_compare_prints_null_psnr_for_identical_images(tmp_path, capsys, gpu_stand_in, reference_frames):
    """The GPU's frame replaced by the reference's own: identical, so PSNR is infinite."""
    from renderer import cli
    gpu_stand_in(reference_frames("sphere", *SIZE))
    status = cli.main(["compare", "sphere", "--size", "32x24", "--out", str(tmp_path)])
    figures = strict_loads(capsys.readouterr().out)
    assert status == 0
    assert figures["psnr"] is None and figures["rmse"] == 0.0 and figures["max_abs"] == 0


def test_compare_prints_psnr_as_a_number_otherwise(tmp_path, capsys, gpu_stand_in, reference_frames):
    from dataclasses import replace
    from renderer import cli
    frame = reference_frames("sphere", *SIZE)
    gpu = replace(frame, rgba8=frame.rgba8.copy())
    gpu.rgba8[0, 0, :3] ^= 0xFF
    gpu_stand_in(gpu)
    cli.main(["compare", "sphere", "--size", "32x24", "--out", str(tmp_path)])
    figures = strict_loads(capsys.readouterr().out)
    assert figures["psnr"] == pytest.approx(20 * math.log10(255 / figures["rmse"]))


def test_view_stats_json_is_strict(tmp_path, capsys, monkeypatch):
    """`view --frames N --stats OUT.json` with frames that took no measurable time (fps would
    be infinite): fps is null. The window is replaced by a stand-in."""
    import renderer.viewer.viewer as viewer_module
    from renderer import cli
    from renderer.viewer.viewer import FrameStats

    class FakeViewer:
        figures = {"rmse": 0.0, "max_abs": 0, "mismatched": 0, "mismatched_fraction": 0.0,
                   "reference_ms": 5.0}
        samples = None                          # rasterising
        radiosity_line = None

        def __init__(self, *args, **kwargs):
            pass

        def __enter__(self):
            return self

        def __exit__(self, *exc):
            return False

        def run(self, frames, orbit, screenshot):
            return FrameStats(frames=3, frame_ms=[0.0, 0.0], draw_ms=[0.0, 0.0], latency_ms=None)

    monkeypatch.setattr(viewer_module, "Viewer", FakeViewer)
    stats = tmp_path / "stats.json"
    assert cli.main(["view", "sphere", "--frames", "3", "--stats", str(stats)]) == 0
    document = strict_loads(stats.read_text())
    assert document["fps"] is None and document["frames"] == 3
    assert document["reference"] == FakeViewer.figures
    assert "no fps" in capsys.readouterr().out


def test_extremes_json_is_strict(tmp_path, gl_contexts):
    """A case where nothing is drawn (PSNR infinite) and a refused one: extremes.json keeps
    its documented spelling of non-finite figures as strings, and is strict JSON."""
    from renderer.study.extremes import extreme_scenes, measure_extremes, write_report
    empty = tmp_path / "empty.toml"
    empty.write_text('[camera]\neye = [0, 0, 5]\nlook = [0, 0, 10]\n'
                     '[[objects]]\nmesh = { primitive = "cube" }\n')
    scenes = {"nan_mesh": extreme_scenes()["nan_mesh"], "empty": empty}
    cases = measure_extremes(scenes, (16, 12), {"osmesa": gl_contexts["osmesa"]})
    json_path, _ = write_report(tmp_path / "out", cases, (16, 12))
    document = strict_loads(json_path.read_text())
    assert document["cases"][1]["worst_truth"]["psnr"] == "inf"
    assert "refused" in document["cases"][0]


def test_golden_sidecar_and_figures_json_are_strict(tmp_path):
    from renderer.checks.golden_report import ResultsFolder
    from renderer.checks.goldens import check_golden
    image = np.zeros((8, 8, 4), np.uint8)
    image[2:6, 2:6] = 255
    check_golden(tmp_path / "goldens", "square", image, update=True)
    sidecar = strict_loads((tmp_path / "goldens" / "square.json").read_text())
    assert sidecar["name"] == "square" and sidecar["size"] == [8, 8]
    changed = image.copy()
    changed[0, 0] = 255
    outcome = check_golden(tmp_path / "goldens", "square", changed)
    assert outcome.status == "failed"
    results = ResultsFolder(tmp_path / "results")
    entry = results.add("test_square", outcome)
    figures = strict_loads((tmp_path / "results" / entry.folder / "figures.json").read_text())
    assert figures["pixels_differing"] == 1 and figures["status"] == "failed"
