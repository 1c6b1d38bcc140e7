"""What a golden suite is for, shown on this project's own: in a copy of the repository, a
16x16 block painted into one golden fails that golden's tests and no other, writes the
images and the results page, and `pytest --update-goldens` restores the golden.

To keep it to seconds, the copy holds what the golden suite reads (the pytest settings,
tests/conftest.py, tests/test_goldens.py and tests/goldens/; the renderer is imported from
this checkout), and each run holds the goldens of two scenes: the painted golden's scene in
every mode, so its neighbours must keep passing, and another scene in all of its modes."""

import os
import shutil
import subprocess
import sys
import xml.etree.ElementTree as ElementTree
from pathlib import Path

import numpy as np
import pytest
from PIL import Image

from renderer.checks.goldens import read_golden

pytestmark = pytest.mark.slow          # four pytest runs in subprocesses

REPO = Path(__file__).resolve().parents[1]
GOLDEN = "sphere-phong"
# Every test that holds this golden: the GPU on both contexts, and the reference.
ITS_TESTS = {f"test_gpu_matches_golden[{GOLDEN}-egl]", f"test_gpu_matches_golden[{GOLDEN}-osmesa]",
             f"test_golden_matches_reference[{GOLDEN}]"}
# The goldens each run holds (pytest -k): every mode of the painted golden's scene and of one
# other scene. Some of the others, which must pass beside the painted one:
SELECTED = "sphere or hierarchy"
OTHERS = ("sphere-flat", "sphere-gouraud", "hierarchy-as-authored", "hierarchy-phong")
OTHER_TESTS = {f"test_{check}[{golden}{context}]" for golden in OTHERS
               for check, context in (("gpu_matches_golden", "-egl"), ("gpu_matches_golden", "-osmesa"),
                                      ("golden_matches_reference", ""))}
# What the golden suite reads besides the renderer (imported from this checkout).
SUITE_FILES = ("pyproject.toml", "tests/conftest.py", "tests/test_goldens.py", "tests/goldens")


def copy_of_repository(target: Path) -> Path:
    for name in SUITE_FILES:
        source, copy = REPO / name, target / name
        copy.parent.mkdir(parents=True, exist_ok=True)
        if source.is_dir():
            shutil.copytree(source, copy)
        else:
            shutil.copy2(source, copy)
    return target


def run_golden_suite(repo: Path, *options: str):
    """(exit status, names of failed tests, names of tests run, output) of the SELECTED
    goldens' tests of tests/test_goldens.py in `repo`, all of them (--all: the OSMesa and
    other-mode checks are in the full run only)."""
    report = repo / "report.xml"
    env = dict(os.environ, PYTHONPATH=os.pathsep.join(
        filter(None, (str(REPO), os.environ.get("PYTHONPATH")))))
    result = subprocess.run([sys.executable, "-m", "pytest", "tests/test_goldens.py", "-q",
                             "-k", SELECTED, "--all", "-p", "no:cacheprovider", f"--junitxml={report}",
                             *options],
                            cwd=repo, env=env, capture_output=True, text=True)
    cases = list(ElementTree.parse(report).iter("testcase"))
    failed = {case.get("name") for case in cases
              if case.find("failure") is not None or case.find("error") is not None}
    ran = {case.get("name") for case in cases if case.find("skipped") is None}
    return result.returncode, failed, ran, result.stdout + result.stderr


def test_a_painted_block_fails_only_its_golden_and_update_restores_it(tmp_path):
    repo = copy_of_repository(tmp_path / "repo")
    # Start from goldens that hold: the repository's own may be under edit (they are checked
    # by tests/test_goldens.py itself), and this test is about the mechanism.
    status, failed, _, output = run_golden_suite(repo, "--update-goldens")
    assert status == 0 and not failed, output
    png = repo / "tests" / "goldens" / f"{GOLDEN}.png"
    original = read_golden(png)
    painted = original.copy()
    painted[120:136, 120:136] = (255, 0, 255, 255)
    Image.fromarray(painted).save(png)

    status, failed, ran, output = run_golden_suite(repo)
    assert status == 1, output
    assert failed == ITS_TESTS, output
    assert OTHER_TESTS <= ran, output                        # and they held the others
    assert "256 pixels fail" in output                       # the count, in the message
    results = repo / "golden-results"
    assert "golden-results/index.html" in output
    page = (results / "index.html").read_text()
    for folder in (GOLDEN, f"{GOLDEN}-2"):                   # one per failing GPU comparison
        for image in ("expected", "actual", "diff", "flip"):
            assert (results / folder / f"{image}.png").is_file()
            assert f'src="{folder}/{image}.png"' in page

    status, failed, _, output = run_golden_suite(repo, "--update-goldens")
    assert status == 0 and not failed, output
    np.testing.assert_array_equal(read_golden(png), original)
    status, failed, _, output = run_golden_suite(repo)
    assert status == 0 and not failed, output
