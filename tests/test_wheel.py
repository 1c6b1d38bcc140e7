"""A wheel built from the repository carries glsl/ and assets/ and renders from anywhere."""

import subprocess
import sys
import zipfile
from pathlib import Path

import pytest

REPO = Path(__file__).resolve().parents[1]

pytestmark = pytest.mark.slow          # builds a wheel


def test_wheel_carries_shaders_and_assets_and_renders_from_another_folder(tmp_path):
    build = subprocess.run([sys.executable, "-m", "pip", "wheel", "-q", "--no-deps", "-w",
                            str(tmp_path / "dist"), str(REPO)], capture_output=True, text=True)
    assert build.returncode == 0, build.stderr
    wheel = next((tmp_path / "dist").glob("*.whl"))
    names = set(zipfile.ZipFile(wheel).namelist())
    for glsl in (REPO / "glsl").rglob("*.*"):             # every folder, .vert and .frag too
        assert f"renderer/glsl/{glsl.relative_to(REPO / 'glsl').as_posix()}" in names
    assert "reference/raytrace/random.py" in names
    for asset in (REPO / "assets").rglob("*.*"):
        assert f"renderer/assets/{asset.relative_to(REPO / 'assets').as_posix()}" in names
    # Unpacked on its own (the dependencies come from this environment), run from elsewhere.
    site = tmp_path / "site"
    zipfile.ZipFile(wheel).extractall(site)
    elsewhere = tmp_path / "elsewhere"
    elsewhere.mkdir()
    result = subprocess.run([sys.executable, "-P", "-m", "renderer", "render", "mesh_file", "--size", "40x30"],
                            capture_output=True, text=True, cwd=elsewhere,
                            env={"PYTHONPATH": str(site), "PATH": "/usr/bin:/bin"})
    assert result.returncode == 0, result.stderr
    assert str(site) in subprocess.run(
        [sys.executable, "-P", "-c", "import renderer; print(renderer.__file__)"],
        capture_output=True, text=True, env={"PYTHONPATH": str(site)}).stdout
    assert (elsewhere / "mesh_file.png").exists()
    # Every method on every backend from the wheel (a package left out of it failed here once).
    for method in ("raster", "raytrace"):
        for backend in ("gpu", "reference"):
            out = elsewhere / f"{method}-{backend}.png"
            result = subprocess.run([sys.executable, "-P", "-m", "renderer", "render", "shadow_plane", "--size",
                                     "16x12", "--method", method, "--backend", backend, "-o", str(out)],
                                    capture_output=True, text=True, cwd=elsewhere,
                                    env={"PYTHONPATH": str(site), "PATH": "/usr/bin:/bin"})
            assert result.returncode == 0 and out.exists(), result.stderr
