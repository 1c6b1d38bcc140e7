"""One way to make a renderer (renderer/methods): every method on every backend opens through
open_renderer, answers the Renderer protocol (renderer/gpu/base.py) and is asked, not branched
on. Outside renderer/gpu, renderer/methods and reference/, nothing constructs GpuRenderer or
RayTracer or calls the reference's entry points (reference.render, reference.pipeline.render,
reference.raytrace.pipeline.render): a test reads the tree."""

import ast
from pathlib import Path

import numpy as np
import pytest

from renderer.core import memory

from renderer.core.frame import Frame
from renderer.core.raster_options import RasterOptions
from renderer.core.ray_options import RayOptions
from renderer.errors import OptionError
from renderer.gpu.base import Renderer
from renderer.methods import METHODS, BACKENDS, method_options, open_renderer
from renderer.methods.registry import Method

ROOT = Path(__file__).resolve().parents[1]
# Where renderers are made: the GPU's classes, the registrations, the twin itself.
MAKERS = ("renderer/gpu", "renderer/methods", "reference")
SEARCHED = ("renderer", "benchmarks", "tools")
CLASSES = {"GpuRenderer", "RayTracer"}
# Files that may, and why.
EXEMPT = {"benchmarks/ab_raytrace.py": "its worker runs inside exported older revisions of the tree, "
                                       "which have no renderer/methods: it falls back to the classes"}
ENTRY_MODULES = {"reference", "reference.pipeline", "reference.raytrace.pipeline"}


def direct_makers(tree: ast.AST) -> list[tuple[int, str]]:
    """(line, what) for each construction of a GPU renderer class and each use of a
    reference entry point (an attribute `reference.render`, or `render` imported from one)."""
    found = []
    for node in ast.walk(tree):
        if isinstance(node, ast.Call):
            name = node.func.id if isinstance(node.func, ast.Name) else \
                node.func.attr if isinstance(node.func, ast.Attribute) else None
            if name in CLASSES:
                found.append((node.lineno, f"{name}(...)"))
            if (isinstance(node.func, ast.Attribute) and node.func.attr == "render"
                    and ast.unparse(node.func.value) in ENTRY_MODULES):
                found.append((node.lineno, f"{ast.unparse(node.func)}(...)"))
        if isinstance(node, ast.ImportFrom) and node.module in ENTRY_MODULES:
            if any(alias.name == "render" for alias in node.names):
                found.append((node.lineno, f"from {node.module} import render"))
    return found


def makers_outside(root: Path) -> list[str]:
    problems = []
    for folder in SEARCHED:
        for path in sorted((root / folder).rglob("*.py")):
            relative = path.relative_to(root).as_posix()
            if relative.startswith(MAKERS) or relative in EXEMPT:
                continue
            for line, what in direct_makers(ast.parse(path.read_text(), filename=relative)):
                problems.append(f"{relative}:{line}: {what}")
    return problems


def test_only_the_factory_makes_renderers():
    assert makers_outside(ROOT) == []


def test_the_check_sees_a_direct_construction_and_a_reference_call(tmp_path):
    (tmp_path / "renderer/study").mkdir(parents=True)
    (tmp_path / "renderer/study/x.py").write_text(
        "import reference\nfrom renderer.gpu.pipeline import GpuRenderer\n"
        "def f(s):\n    GpuRenderer(s, 8, 8)\n    return reference.render(s, 8, 8)\n")
    (tmp_path / "benchmarks").mkdir()
    (tmp_path / "benchmarks/b.py").write_text("from reference.raytrace.pipeline import render\n")
    (tmp_path / "tools").mkdir()
    assert makers_outside(tmp_path) == ["renderer/study/x.py:4: GpuRenderer(...)",
                                        "renderer/study/x.py:5: reference.render(...)",
                                        "benchmarks/b.py:1: from reference.raytrace.pipeline import render"]


# ------------------------------------------------------------------ the protocol, each way round

@pytest.mark.parametrize("backend", BACKENDS)
@pytest.mark.parametrize("method", list(METHODS))
def test_every_method_on_every_backend_is_a_renderer(method, backend, sphere_scene):
    """Linear colour and depth come back when asked the same way; update() and resize() keep
    the renderer usable; release() twice is harmless."""
    with open_renderer(sphere_scene, (16, 12), method=method, backend=backend) as renderer:
        assert isinstance(renderer, Renderer)
        frame = renderer.render(linear=True, depth=True)
        assert isinstance(frame, Frame) and frame.rgba8.shape == (12, 16, 4)
        assert frame.linear.shape == (12, 16, 4) and frame.depth.shape == (12, 16)
        assert frame.rgba8[6, 8, 3] == 255                    # the sphere covers the centre
        renderer.update(sphere_scene)
        renderer.resize(8, 6)
        assert renderer.render(depth=True).depth.shape == (6, 8)
        assert renderer.gl_info
    renderer.release()


def test_a_frame_is_rendered_into_the_arrays_of_the_one_before(sphere_scene):
    for method in METHODS:
        with open_renderer(sphere_scene, (16, 12), method=method) as renderer:
            first = renderer.render(linear=True)
            again = renderer.render(first, linear=True)
            assert again.linear is first.linear and np.array_equal(again.rgba8, first.rgba8)


def test_options_of_another_method_are_refused_by_name():
    with pytest.raises(OptionError) as refused:
        method_options("raster", {"samples": 4})
    assert (refused.value.fields, refused.value.reason) == (("samples",), "is for method raytrace, not raster")
    with pytest.raises(OptionError, match="unknown method 'photon_map'; one of raster, raytrace, radiosity, pathtrace"):
        method_options("photon_map")
    with pytest.raises(TypeError, match="method raytrace takes RayOptions, not RasterOptions"):
        open_renderer(None, (8, 8), method="raytrace", options=RasterOptions())
    assert method_options("raytrace", {"samples": 4}) == RayOptions(samples=4)


def test_a_new_method_is_one_registration(monkeypatch, sphere_scene):
    """A method added to METHODS is opened, checked and described through the same calls,
    with nothing else changed."""
    opened = []

    def open_either(scene, width, height, options, *where):
        opened.append((scene.name, width, height, options))
        return open_renderer(scene, (width, height), backend="reference")

    fake = Method("flat", "flat colour", RasterOptions, open_either, open_either,
                  lambda size, backends, options: memory.raster_need(size, backends))
    monkeypatch.setitem(METHODS, "flat", fake)
    with open_renderer(sphere_scene, (8, 6), method="flat", options=RasterOptions(specialise=False)) as r:
        assert r.render().rgba8.shape == (6, 8, 4)
    assert opened == [("sphere", 8, 6, RasterOptions(specialise=False))]
    assert method_options("flat", {"prune_shadows": False}) == RasterOptions(prune_shadows=False)
    METHODS["flat"].check_memory(sphere_scene, (8, 6), ["gpu"], RasterOptions())


@pytest.fixture
def sphere_scene():
    from renderer.core.builtin import resolve_scene
    from renderer.core.scene_file import load_scene
    return load_scene(resolve_scene("sphere"))
