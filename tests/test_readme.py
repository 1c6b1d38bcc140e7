"""The README as a user reads it. Its Python example runs as written, from any folder (not
only the repository root): it loads a built-in scene by name. Its shell examples, copied into
a checkout: every file or folder a command writes lands under out/ (which git ignores) or a
temporary folder, never loose in the repository root (the first command's default output
is out/sphere.png).
Its timings: a section that gives one says where and when it was measured and the command
that reproduces it, since absolute times on the shared machine vary 2 to 3× with load."""

import re
import shlex
import subprocess
import sys
from pathlib import Path

import pytest

ROOT = Path(__file__).resolve().parents[1]
README = ROOT / "README.md"
OUTPUT_OPTIONS = {"-o", "--out", "--depth", "--alpha", "--screenshot", "--stats", "--goldens-results"}


def shell_lines(markdown: str) -> list[str]:
    blocks = re.findall(r"^```sh\n(.*?)^```", markdown, flags=re.S | re.M)
    return [line.split("#")[0].strip() for block in blocks for line in block.splitlines()
            if line.split("#")[0].strip()]


def outputs_outside_out(lines: list[str]) -> list[str]:
    """'line: path' for each output option whose path is not under out/ or /tmp."""
    found = []
    for line in lines:
        words = shlex.split(line)
        for option, value in zip(words, words[1:]):
            if option in OUTPUT_OPTIONS and not value.startswith(("out/", "/tmp/")):
                found.append(f"{line}: {value}")
    return found


def manual() -> dict[str, str]:
    """The README and every page of the manual (docs/), by path: what a user reads."""
    pages = [ROOT / "README.md", *sorted((ROOT / "docs").rglob("*.md"))]
    return {page.relative_to(ROOT).as_posix(): page.read_text() for page in pages
            if "gallery" not in page.relative_to(ROOT).parts}


def test_readme_examples_write_under_out():
    lines = [line for text in manual().values() for line in shell_lines(text)]
    assert any("renderer report" in line for line in lines)          # the examples were found
    assert outputs_outside_out(lines) == []


def test_git_ignores_what_the_examples_write():
    ignored = (ROOT / ".gitignore").read_text().split()
    assert {"/out/", "/golden-results/"} <= set(ignored)


def test_the_check_sees_a_loose_output():
    assert outputs_outside_out(["renderer render sphere -o gp.png --depth out/d.npy",
                                "renderer compare sphere --out cmp/"]) == [
        "renderer render sphere -o gp.png --depth out/d.npy: gp.png",
        "renderer compare sphere --out cmp/: cmp/"]


# What the example leaves behind, checked after it has run.
CHECKS = """
assert scene.name == "sphere", scene.name
assert frame.rgba8.shape == (480, 640, 4) and expected.rgba8.shape == (480, 640, 4)
assert traced.rgba8.shape == (480, 640, 4) and traced.samples.max() == 4
assert (frame.rgba8[..., 3] == 255).mean() > 0.05 and (expected.rgba8[..., 3] == 255).mean() > 0.05
print("README example ran")
"""


def using_it_python_block() -> str:
    """The one ```python block of the README's "Using it" section."""
    section = re.search(r"^## Using it\n(.*?)^## ", README.read_text(encoding="utf-8"), re.S | re.M)
    assert section, "README.md has no '## Using it' section"
    blocks = re.findall(r"^```python\n(.*?)^```", section[1], re.S | re.M)
    assert len(blocks) == 1, f"expected one python block in 'Using it', found {len(blocks)}"
    return blocks[0]


def test_the_using_it_example_loads_a_builtin_scene_by_name():
    assert 'load_scene("sphere")' in using_it_python_block()


@pytest.mark.slow
def test_the_using_it_example_runs_from_another_folder(tmp_path):
    result = subprocess.run([sys.executable, "-c", using_it_python_block() + CHECKS],
                            cwd=tmp_path, capture_output=True, text=True, timeout=120)
    assert result.returncode == 0, result.stderr
    assert result.stdout.strip().splitlines()[-1] == "README example ran"
    assert list(tmp_path.iterdir()) == []                    # it writes nothing
