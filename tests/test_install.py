"""install.sh, as a new user runs it: on a fresh copy it says what it is doing while pip runs
(a line per phase, no pip or setuptools chatter), and run again it sees that nothing changed
and says nothing; a changed pyproject.toml installs again."""

import re
import shutil
import subprocess
from pathlib import Path

import pytest

pytestmark = pytest.mark.slow           # a virtual environment and a pip install (about 30 s)

REPO = Path(__file__).resolve().parents[1]


def fresh_copy(target: Path) -> Path:
    files = subprocess.run(["git", "ls-files"], cwd=REPO, capture_output=True, text=True,
                           check=True).stdout.split()
    for name in files:
        if (REPO / name).is_file():
            (target / name).parent.mkdir(parents=True, exist_ok=True)
            shutil.copy2(REPO / name, target / name)
    return target


def install(repo: Path) -> subprocess.CompletedProcess:
    return subprocess.run(["bash", "install.sh"], cwd=repo, capture_output=True, text=True,
                          timeout=600)


def test_install_is_quiet_and_a_second_run_does_nothing(tmp_path):
    repo = fresh_copy(tmp_path / "repo")
    first = install(repo)
    assert first.returncode == 0, first.stdout + first.stderr
    said = (first.stdout + first.stderr).splitlines()
    assert said[0] == "install.sh: installing the package and its dependencies into .venv (pip)", said
    assert re.fullmatch(r"install\.sh: pip: \d+ packages looked at; installing those missing", said[1]), said
    assert re.fullmatch(r"install\.sh: pip: done in \d+ s", said[2]) and len(said) == 3, said
    assert subprocess.run([repo / ".venv/bin/renderer", "scenes"], capture_output=True).returncode == 0

    stamp = (repo / ".venv/.install-stamp").stat().st_mtime_ns
    again = install(repo)
    assert again.returncode == 0 and again.stdout + again.stderr == ""       # pip did not run
    assert (repo / ".venv/.install-stamp").stat().st_mtime_ns == stamp

    with (repo / "pyproject.toml").open("a") as f:
        f.write("\n# changed\n")
    changed = install(repo)
    assert changed.returncode == 0
    assert "installing the package" in changed.stdout
