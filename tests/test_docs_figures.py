"""Figures that cannot go stale (issue 31): a page of the manual quotes a benchmark's figures
by including the markdown the benchmark made from its own results file, never by a figure
typed by hand. benchmarks/results/NAME.json holds what was measured, with the machine, its
load, the date and the commit (benchmarks/common.py write_results); NAME.md is the
benchmark's `markdown` of it. Here each .md is made again from its .json and must be equal,
and every results file a page includes exists."""

import importlib.util
import json
import re
from pathlib import Path

import pytest

ROOT = Path(__file__).resolve().parents[1]
RESULTS = ROOT / "benchmarks" / "results"
KEYS = {"machine", "cpus", "load", "date", "commit", "command", "figures"}


def results() -> list[Path]:
    return sorted(RESULTS.glob("*.json"))


def benchmark_module(command: str):
    """The benchmark script a results document names in its command, imported."""
    script = next(word for word in command.split() if word.startswith("benchmarks/") and word.endswith(".py"))
    import sys
    sys.path.insert(0, str(ROOT / "benchmarks"))              # its `from common import ...`
    try:
        spec = importlib.util.spec_from_file_location(Path(script).stem, ROOT / script)
        module = importlib.util.module_from_spec(spec)
        spec.loader.exec_module(module)
        return module
    finally:
        sys.path.remove(str(ROOT / "benchmarks"))


def test_there_are_results_files():
    assert results()


@pytest.mark.parametrize("path", results(), ids=lambda path: path.stem)
def test_each_page_fragment_is_made_from_its_results_file(path):
    document = json.loads(path.read_text())
    assert KEYS <= set(document), path.name
    assert re.fullmatch(r"[0-9a-f]{7,40}( \+ uncommitted changes)?", document["commit"])
    made = benchmark_module(document["command"]).markdown(document)
    assert path.with_suffix(".md").read_text() == made, f"{path.with_suffix('.md').name} was edited by hand"


def test_every_results_file_a_page_includes_exists():
    included = []
    for page in (ROOT / "docs").rglob("*.md"):
        for target in re.findall(r"```\{include\} (\S+)", page.read_text()):
            included.append((page, (page.parent / target).resolve()))
    assert any("benchmarks/results" in str(target) for _, target in included)
    assert [f"{page.name}: {target}" for page, target in included if not target.exists()] == []
