"""The README's shell examples, as a user copies them into a checkout: every file or folder a
command writes lands under out/ (which git ignores) or a temporary folder, never loose in the
repository root; the first command's default output (sphere.png) is ignored too."""

import re
import shlex
from pathlib import Path

ROOT = Path(__file__).resolve().parents[1]
OUTPUT_OPTIONS = {"-o", "--out", "--depth", "--screenshot", "--stats", "--goldens-results"}


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


def test_readme_examples_write_under_out():
    lines = shell_lines((ROOT / "README.md").read_text())
    assert any("renderer report" in line for line in lines)          # the examples were found
    assert outputs_outside_out(lines) == []


def test_git_ignores_what_the_examples_write():
    ignored = (ROOT / ".gitignore").read_text().split()
    assert {"/out/", "/sphere.png", "/golden-results/"} <= set(ignored)


def test_the_check_sees_a_loose_output():
    assert outputs_outside_out(["renderer render sphere -o gp.png --depth out/d.npy",
                                "renderer compare sphere --out cmp/"]) == [
        "renderer render sphere -o gp.png --depth out/d.npy: gp.png",
        "renderer compare sphere --out cmp/: cmp/"]
