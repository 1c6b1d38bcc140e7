"""Every command the README and the manual show runs as written (issue 31: commands that
called a bare `renderer`, used files that did not exist, or wrote one output twice).

A ```sh block runs line by line, in a folder laid out like a checkout after install.sh
(`.venv`, `assets/`, `examples/` there), at a small size: `--size` is set to 32x24 for the
commands that take one. A block after `<!-- illustration: why -->` is shown, not run (a window
until Esc, a report of minutes, a cluster of machines), and says which test covers it; the
README's two set-up commands are CI's own (.ci/run, tests/test_install.py)."""

import os
import re
import shlex
import subprocess
import sys
from pathlib import Path

import pytest

from test_readme import OUTPUT_OPTIONS, manual

ROOT = Path(__file__).resolve().parents[1]
SMALL = "32x24"
SIZED = {"render", "compare", "view", "extremes"}      # and colour of a scene
SETUP = ("./install.sh",)
BLOCK = re.compile(r"(?:^<!-- (illustration: [^\n]*?) -->\n)?^```sh\n(.*?)^```", re.S | re.M)


def commands(texts: dict[str, str] | None = None) -> list[tuple[str, str, str | None]]:
    """(page, command line, why it is not run or None), in reading order, of `texts` (page
    name -> Markdown; the manual's pages when None)."""
    found = []
    for name, text in (manual() if texts is None else texts).items():
        for illustration, block in BLOCK.findall(text):
            for line in block.splitlines():
                command = line.split("  #")[0].split(" # ")[0].strip()
                if command and not command.startswith("#"):
                    skip = illustration or ("CI's set-up (.ci/run, tests/test_install.py)"
                                            if command.startswith(SETUP) else None)
                    found.append((name, command, skip))
    return found


def small(command: str) -> str:
    """The command at SMALL where it takes --size (a colour of an image takes none)."""
    words = shlex.split(command)
    renderer = next((i for i, w in enumerate(words) if w.endswith("bin/renderer")), None)
    if renderer is None or len(words) <= renderer + 1:
        return command
    sub = words[renderer + 1]
    takes = sub in SIZED or (sub == "colour" and not words[renderer + 2].endswith((".png", ".exr", ".npy")))
    if not takes:
        return command
    if "--size" in words:
        words[words.index("--size") + 1] = SMALL
    else:
        words[renderer + 2:renderer + 2] = ["--size", SMALL]
    return shlex.join(words)


def test_the_manual_shows_commands_and_runs_most():
    found = commands()
    assert len(found) > 30 and sum(skip is None for _, _, skip in found) > 25


def shipping_problems(found) -> list[str]:
    problems = []
    for page, command, skip in found:
        words = shlex.split(command)
        if re.search(r"(?:^|\s)renderer\s", command) and not re.search(r"\.venv/bin/renderer\s", command):
            problems.append(f"{page}: a bare renderer: {command}")
        for word in words:
            if word.endswith(".toml") and not (ROOT / word).exists():
                problems.append(f"{page}: no such file {word}: {command}")
    return problems


def test_every_command_runs_the_installed_renderer_on_files_that_ship():
    """`.venv/bin/renderer` (install.sh does not put a bare `renderer` on the PATH) and input
    files that exist in the repository."""
    assert shipping_problems(commands()) == []


def test_the_checks_see_a_bare_renderer_a_missing_file_and_a_shown_block():
    page = ("```sh\nrenderer render sphere -o out/a.png\n.venv/bin/renderer render my_scene.toml\n```\n"
            "<!-- illustration: a window -->\n```sh\n.venv/bin/renderer view sphere  # until Esc\n```\n")
    found = commands({"p.md": page})
    assert [skip for _, _, skip in found] == [None, None, "illustration: a window"]
    assert shipping_problems(found) == ["p.md: a bare renderer: renderer render sphere -o out/a.png",
                                        "p.md: no such file my_scene.toml: .venv/bin/renderer render my_scene.toml"]
    assert small(".venv/bin/renderer render x --size 640x480") == ".venv/bin/renderer render x --size 32x24"
    assert small(".venv/bin/renderer colour out/a.png --out o") == ".venv/bin/renderer colour out/a.png --out o"


def outputs(command: str) -> list[str]:
    words = shlex.split(command)
    return [value for option, value in zip(words, words[1:]) if option in OUTPUT_OPTIONS]


def test_no_command_writes_over_another_commands_output():
    """The same line twice is a resume (batch); any other two commands name different files."""
    written: dict[str, str] = {}
    clashes = []
    for page, command, _ in commands():
        for path in outputs(command):
            key = path.rstrip("/")
            if key in written and written[key] != command:
                clashes.append(f"{path}: {written[key]!r} and {command!r}")
            written.setdefault(key, command)
    assert clashes == []


@pytest.fixture(scope="module")
def checkout(tmp_path_factory):
    """A folder laid out like the repository after install.sh, without its outputs."""
    folder = tmp_path_factory.mktemp("checkout")
    (folder / ".venv").symlink_to(Path(sys.prefix))
    for part in ("assets", "examples"):
        (folder / part).symlink_to(ROOT / part)
    return folder


RUN = {}
for _page, _command, _skip in commands():
    if _skip is None:
        RUN.setdefault(_page, []).append(_command)


@pytest.mark.slow
@pytest.mark.parametrize("page", sorted(RUN))
def test_each_pages_commands_run_as_written_in_order(checkout, page):
    """A page's commands in the order it shows them (a later one may read an earlier one's
    output: colour of out/bn.png after the render that wrote it)."""
    env = os.environ | {"PYTHONWARNINGS": "ignore"}
    for command in RUN[page]:
        result = subprocess.run(["bash", "-c", small(command)], cwd=checkout, capture_output=True,
                                text=True, timeout=300, env=env)
        assert result.returncode == 0, f"{page}: {small(command)}\n{result.stderr[-2000:]}"
        for path in outputs(command):
            assert (checkout / path).exists(), f"{page}: {command} did not write {path}"
