"""The wheel is the product: built from the repository, installed by pip into a fresh virtual
environment, it carries glsl/ and assets/ and, from an empty folder outside the repository,
renders every method on both backends, compares, measures colour, runs a tiny batch and the
README's Python example (issue 31: a wheel once lacked reference.shadow, and the test that
only rendered on the GPU never saw it).

The fresh environment gets the wheel from pip (its files, its `renderer` script, its entry
points) and nothing else of the project; its third-party dependencies come from the test's own
environment through a .pth line, which appends them after its own site-packages (so the
wheel's packages, not the checkout's, are the ones imported: the test checks), and saves
downloading them. install.sh's pip install of the whole dependency list is CI's own set-up."""

import shutil
import subprocess
import sys
import sysconfig
import zipfile
from pathlib import Path

import pytest

REPO = Path(__file__).resolve().parents[1]

# Builds a wheel (in the checkout's build/) and a virtual environment, once: with xdist, the
# module's tests run in one worker (two builds at once collide in build/).
pytestmark = [pytest.mark.slow, pytest.mark.xdist_group("wheel")]


@pytest.fixture(scope="session")
def installed(tmp_path_factory):
    """(the fresh environment's python, an empty folder outside the repository, the wheel's
    file names). Built once per session from a copy of the tracked files: setuptools builds in
    the source's build/, and a second build there (the fixture made again after other
    modules' tests) failed on the first's leftovers."""
    root = tmp_path_factory.mktemp("wheel")
    source = root / "source"
    tracked = subprocess.run(["git", "ls-files"], cwd=REPO, capture_output=True, text=True,
                             check=True).stdout.split("\n")
    for name in filter(None, tracked):
        if (REPO / name).is_file():
            (source / name).parent.mkdir(parents=True, exist_ok=True)
            shutil.copy2(REPO / name, source / name)
    build = subprocess.run([sys.executable, "-m", "pip", "wheel", "-q", "--no-deps",
                            "-w", str(root / "dist"), str(source)], capture_output=True, text=True)
    assert build.returncode == 0, build.stderr
    wheel = next((root / "dist").glob("*.whl"))
    subprocess.run([sys.executable, "-m", "venv", "--without-pip", str(root / "venv")], check=True)
    python = root / "venv" / "bin" / "python"
    install = subprocess.run([sys.executable, "-m", "pip", "--python", str(python), "install", "-q",
                              "--no-deps", "--no-index", str(wheel)], capture_output=True, text=True)
    assert install.returncode == 0, install.stderr
    site = subprocess.run([str(python), "-c", "import sysconfig; print(sysconfig.get_paths()['purelib'])"],
                          capture_output=True, text=True, check=True).stdout.strip()
    (Path(site) / "test-dependencies.pth").write_text(sysconfig.get_paths()["purelib"] + "\n")
    empty = root / "empty"
    empty.mkdir()
    return python, empty, set(zipfile.ZipFile(wheel).namelist())


def run(installed, *args, script: bool = True):
    """`renderer ARGS` (the installed script) or `python ARGS` in the empty folder."""
    python, empty, _ = installed
    command = [str(python.parent / "renderer"), *args] if script else [str(python), *args]
    result = subprocess.run(command, capture_output=True, text=True, cwd=empty, timeout=300,
                            env={"PATH": f"{python.parent}:/usr/bin:/bin", "HOME": str(empty)})
    assert result.returncode == 0, f"{args}: {result.stderr}"
    return result


def test_the_wheel_carries_every_package_shader_and_asset(installed):
    names = installed[2]
    for glsl in (REPO / "glsl").rglob("*.*"):             # every folder, .vert and .frag too
        assert f"renderer/glsl/{glsl.relative_to(REPO / 'glsl').as_posix()}" in names
    for asset in (REPO / "assets").rglob("*.*"):
        assert f"renderer/assets/{asset.relative_to(REPO / 'assets').as_posix()}" in names
    for top in ("renderer", "reference"):
        for module in (REPO / top).rglob("*.py"):
            assert module.relative_to(REPO).as_posix() in names, module


def test_the_installed_packages_are_the_wheels(installed):
    found = run(installed, "-c", "import renderer, reference; print(renderer.__file__, reference.__file__)",
                script=False).stdout
    assert str(REPO) not in found and "site-packages" in found


@pytest.mark.parametrize("method", ["raster", "raytrace"])
@pytest.mark.parametrize("backend", ["gpu", "reference"])
def test_every_method_renders_on_both_backends_from_the_wheel(installed, method, backend):
    out = f"out/{method}-{backend}.png"
    run(installed, "render", "shadow_plane", "--size", "16x12", "--method", method, "--backend",
        backend, "-o", out)
    assert (installed[1] / out).exists()


def test_compare_colour_and_a_tiny_batch_from_the_wheel(installed):
    empty = installed[1]
    run(installed, "compare", "sphere", "--size", "16x12", "--out", "out/compare")
    assert {p.name for p in (empty / "out" / "compare").iterdir()} >= {"gpu.png", "reference.png", "diff.png"}
    run(installed, "colour", "sphere", "--size", "16x12", "--out", "out/colour")
    assert any((empty / "out" / "colour").iterdir())
    (empty / "job.toml").write_text('name = "tiny"\n[[settings]]\nname = "small"\nsize = [16, 12]\n'
                                    '[[scenes]]\nscene = "sphere"\n')
    run(installed, "batch", "job.toml", "--out", "out/batch", "--workers", "1")
    assert (empty / "out" / "batch" / "manifest.jsonl").exists()


def test_the_readme_python_example_runs_from_the_wheel(installed):
    from test_readme import using_it_python_block
    result = run(installed, "-c", using_it_python_block() + "\nprint('ran', frame.rgba8.shape, traced.rgba8.shape)",
                 script=False)
    assert result.stdout.strip().splitlines()[-1] == "ran (480, 640, 4) (480, 640, 4)"
