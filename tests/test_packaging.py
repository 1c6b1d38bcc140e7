"""pyproject.toml's package list names every package of renderer/ and reference/: a package
left out is missing from the wheel, and whatever imports it there fails (issue 31: a wheel
without reference.shadow could not draw with --backend reference). tests/test_wheel.py
builds the wheel and renders from it (slow)."""

import tomllib
from pathlib import Path

ROOT = Path(__file__).resolve().parents[1]


def source_packages(root: Path) -> set[str]:
    return {".".join(init.parent.relative_to(root).parts)
            for top in ("renderer", "reference") for init in (root / top).rglob("__init__.py")}


def test_the_wheel_lists_every_package():
    listed = set(tomllib.loads((ROOT / "pyproject.toml").read_text())["tool"]["setuptools"]["packages"])
    mapped = {name for name in listed if name.startswith(("renderer.glsl", "renderer.assets"))}
    assert listed - mapped == source_packages(ROOT)


def test_the_check_sees_a_package_left_out(tmp_path):
    for package in ("renderer", "renderer/methods", "reference", "reference/shadow"):
        (tmp_path / package).mkdir(parents=True)
        (tmp_path / package / "__init__.py").write_text("")
    assert source_packages(tmp_path) == {"renderer", "renderer.methods", "reference", "reference.shadow"}
