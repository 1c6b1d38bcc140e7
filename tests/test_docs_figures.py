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


README_BLOCK = re.compile(r"<!-- results: (\S+) -->\n(.*?)<!-- /results -->", re.S)


def test_each_readme_block_is_its_results_file():
    """The README (read on GitHub, which includes no file) holds a results file's .md between
    `<!-- results: NAME -->` and `<!-- /results -->`, copied in by the benchmark
    (benchmarks/common.py fill_readme_block): the two must be equal."""
    blocks = README_BLOCK.findall((ROOT / "README.md").read_text())
    assert blocks
    assert [name for name, text in blocks if text != (RESULTS / f"{name}.md").read_text()] == []


def test_every_results_file_a_page_includes_exists():
    included = []
    for page in (ROOT / "docs").rglob("*.md"):
        for target in re.findall(r"```\{include\} (\S+)", page.read_text()):
            included.append((page, (page.parent / target).resolve()))
    assert any("benchmarks/results" in str(target) for _, target in included)
    assert [f"{page.name}: {target}" for page, target in included if not target.exists()] == []


# ------------------------------------------------------------------ figures typed by hand
# A measured figure: a time, a memory size, frames per second or a speed ratio, alone or as a
# range ("3.2 ms", "1–2.4 ms", "3.2×", "25 to 40 times a Bayer pass"). Sizes in pixels, counts
# and parameters ("16 samples", "320×240") are not measured and not matched.
NUMBER = r"(?<![\w.,])(?:\d{1,3}(?:,\d{3})+|\d+)(?:\.\d+)?"
FIGURE = re.compile(
    rf"{NUMBER}(?:\s?(?:–|-|to)\s?{NUMBER})?"
    r"(?:×(?![\d(])|x(?=[\s,.;:)])|\s?(?:ms|µs|s|min|minutes?|seconds?|hours?|KiB|MiB|GiB|KB|MB|GB|fps)\b"
    r"|\stimes (?:faster|slower|as (?:fast|long|slow|much|many)|the|a|an|more|less|its|their)\b)")

# Figures in prose that are not measurements: limits and constants the code sets (each
# named where it is defined), not a machine's speed. Every entry must still be on its page.
NOT_MEASURED = {
    ("docs/bad-input.md", "1 GiB"): "the fuzz runaway guard's memory limit (tests/test_fuzz.py)",
    ("docs/bad-input.md", "8 MiB"): "MAX_SCENE_BYTES, the largest scene file (renderer/core/user_files.py)",
    ("docs/bad-input.md", "64 KiB"): "a limit set in renderer/core/user_files.py",
    ("docs/bad-input.md", "3 GiB"): "the size of a fuzz case's mesh file",
    ("docs/bad-input.md", "192 MiB"): "memory.PROCESS_BYTES",
    ("docs/memory.md", "192 MiB"): "memory.PROCESS_BYTES",
    ("docs/memory.md", "1 KiB"): "memory.MESH_BUILD_BYTES_PER_TRIANGLE",
    ("docs/scene-format.md", "8 MiB"): "MAX_SCENE_BYTES",
    ("docs/scene-format.md", "4 GiB"): "a limit of the scene reader",
    ("docs/scene-format.md", "2.1 GiB"): "a limit of the scene reader",
    ("docs/conventions.md", "256 MiB"): "MAX_SHADOW_TEXELS' memory",
    ("docs/conventions.md", "4 times the"): "DECISION_MARGIN = 2^-12 against the rounding it covers (reference/raytrace/pipeline.py)",
    ("docs/error-against-run-time.md", "30 minutes"): "the bound set for the default report (issue 31); benchmarks/bench_report.py measures it",
}


def prose(markdown: str) -> str:
    """What a page states in its own words: without code blocks, code spans (commands, output
    shown), HTML comments, included files and the README's copies of them (a results file's
    fragment is measured). Lines keep their numbers."""
    def blank(match):
        return "\n" * match.group(0).count("\n")
    markdown = re.sub(r"^```.*?^```", blank, markdown, flags=re.S | re.M)
    markdown = README_BLOCK.sub(blank, markdown)
    markdown = re.sub(r"<!--.*?-->", blank, markdown, flags=re.S)
    return re.sub(r"`[^`\n]*`", "", markdown)


def typed_figures(markdown: str) -> list[tuple[int, str]]:
    """(line, figure) of each measured figure a page types in its prose (FIGURE)."""
    text = prose(markdown)
    return [(text.count("\n", 0, m.start()) + 1, " ".join(m.group(0).split()))
            for m in FIGURE.finditer(text)]


def docs_pages() -> dict[str, str]:
    """The README and the manual's pages, but docs/report/: those are the reports'
    own output (report.md beside its results.csv), not typed."""
    from test_readme import manual
    return {name: text for name, text in manual().items() if not name.startswith("docs/report/")}


def test_no_page_types_a_measured_figure():
    found = [f"{name}:{line}: {figure}" for name, text in docs_pages().items()
             for line, figure in typed_figures(text) if (name, figure) not in NOT_MEASURED]
    assert found == [], ("figures typed by hand; quote them from a results file "
                         "(benchmarks/common.py write_results, included with ```{include}):\n" + "\n".join(found))


def test_every_figure_said_not_measured_is_still_on_its_page():
    pages = docs_pages()
    assert [key for key in NOT_MEASURED
            if key[1] not in [figure for _, figure in typed_figures(pages.get(key[0], ""))]] == []


def test_the_check_sees_a_typed_figure():
    page = ("The sphere takes 12.4 ms a frame, 3.2× faster; Floyd–Steinberg costs 25 to 40 "
            "times a Bayer pass, and the run 1–2.4 s and 630 MiB.\n"
            "At 320×240 with 16 samples, `renderer render --size 32x24` prints `wrote x (3 ms)`.\n"
            "```{include} ../benchmarks/results/memory.md\n```\n<!-- 5 ms -->\n"
            "```sh\ntime renderer report  # 29 s\n```\n"
            "<!-- results: knot -->\n| the frame | 7.5 ms |\n<!-- /results -->\n")
    assert typed_figures(page) == [(1, "12.4 ms"), (1, "3.2×"), (1, "25 to 40 times a"),
                                   (1, "1–2.4 s"), (1, "630 MiB")]
