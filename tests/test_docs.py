"""The manual: a short README that points into it, and docs/ built by Sphinx with warnings as
errors (a broken reference, a page in no table of contents, an example that fails), its
gallery drawn by examples/ with the current code (issue 31)."""

import re
import shutil
import subprocess
import sys
from pathlib import Path

import pytest

ROOT = Path(__file__).resolve().parents[1]
README_MOST_LINES = 400


def test_the_readme_is_short_and_starts_with_the_two_commands():
    readme = (ROOT / "README.md").read_text()
    assert readme.count("\n") < README_MOST_LINES
    first = readme.index("<!-- render-command -->")
    assert first < readme.index("<!-- test-command -->") < readme.index("\n## ")


def test_every_page_the_readme_names_exists():
    named = set(re.findall(r"\b(docs/[\w./-]+\.md|docs/[\w/-]+/)", (ROOT / "README.md").read_text()))
    assert named and [name for name in sorted(named) if not (ROOT / name).exists()] == []


def test_every_example_is_a_gallery_script():
    """sphinx-gallery runs the scripts named plot_*.py: an example named otherwise would sit
    in examples/ unrun and undrawn."""
    scripts = sorted(p.name for p in (ROOT / "examples").glob("*.py"))
    assert scripts and all(name.startswith("plot_") for name in scripts)


@pytest.mark.slow
def test_the_manual_builds_without_a_warning_and_draws_its_gallery(tmp_path):
    for part in ("docs", "examples"):          # a copy: the gallery is written beside its pages
        shutil.copytree(ROOT / part, tmp_path / part,
                        ignore=shutil.ignore_patterns("gallery", "_build", "sg_execution_times.rst"))
    shutil.copy(ROOT / "README.md", tmp_path)   # docs/using.md includes its tour
    shutil.copytree(ROOT / "benchmarks" / "results", tmp_path / "benchmarks" / "results")   # and figures
    out = tmp_path / "html"
    result = subprocess.run([sys.executable, "-m", "sphinx", "-W", "--keep-going", "-q", "-b", "html",
                             str(tmp_path / "docs"), str(out)], capture_output=True, text=True,
                            timeout=600, env={"PATH": "/usr/bin:/bin", "MPLBACKEND": "Agg",
                                              "PYTHONPATH": str(ROOT)})
    assert result.returncode == 0, result.stderr
    for script in (ROOT / "examples").glob("plot_*.py"):
        assert (out / "gallery" / f"{script.stem}.html").exists(), script.name
        assert list((out / "_images").glob(f"sphx_glr_{script.stem}_001.png")), script.name
    assert (out / "index.html").exists() and (out / "layout.html").exists()
