"""The layout as a rule: imports point down, and there is no import cycle.

    errors      imports nothing of the project
    core        errors
    reference   core, errors                     (the twin shares the scene model and matrices only)
    gpu         core, errors
    cluster     core, gpu, reference, errors     (where work runs: in-process or Ray)
    checks      core, gpu, reference, errors
    study       core, gpu, checks, reference, cluster, errors
    batch       core, gpu, checks, reference, cluster, errors
    viewer      core, gpu, checks, reference, errors
    cli         anything (only the command line imports the viewer)

The graph is read from the source (every import statement, function-level ones included) of
renderer/ and reference/, so an import hidden inside a function counts too.
"""

import ast
from pathlib import Path

import pytest

ROOT = Path(__file__).resolve().parents[1]
PACKAGES = ("renderer", "reference")

# group -> the groups it may import (itself included). The root package (renderer/__init__.py:
# __version__, and the old names' aliases) is imported by every import of a submodule anyway.
ALLOWED = {
    "renderer": {"renderer"},                    # renderer/__init__.py and _moved.py
    "errors": {"errors"},
    "core": {"core", "errors"},
    "reference": {"reference", "core", "errors"},
    "gpu": {"gpu", "core", "errors"},
    "cluster": {"cluster", "core", "gpu", "reference", "errors"},
    "checks": {"checks", "core", "gpu", "reference", "errors"},
    "study": {"study", "core", "gpu", "checks", "reference", "cluster", "errors"},
    "batch": {"batch", "core", "gpu", "checks", "reference", "cluster", "errors"},
    "viewer": {"viewer", "core", "gpu", "checks", "reference", "errors"},
    "cli": {"cli", "core", "gpu", "checks", "study", "viewer", "reference", "cluster", "batch",
            "errors"},
}
ALLOWED = {group: allowed | {"renderer"} for group, allowed in ALLOWED.items()}


def module_name(path: Path, root: Path) -> str:
    parts = list(path.relative_to(root).with_suffix("").parts)
    if parts[-1] == "__init__":
        parts.pop()
    return ".".join(parts)


def group_of(module: str) -> str:
    """renderer.core.scene -> core; renderer.cli / renderer.__main__ -> cli; reference.x -> reference."""
    parts = module.split(".")
    if parts[0] == "reference":
        return "reference"
    if len(parts) == 1 or parts[1] == "_moved":
        return "renderer"
    if parts[1] in ("cli", "__main__"):
        return "cli"
    return parts[1]


def imported_modules(tree: ast.AST, module: str, is_package: bool, known: set[str]):
    """(imported project module, line) for every import statement in the tree."""
    package = module if is_package else module.rpartition(".")[0]
    for node in ast.walk(tree):
        if isinstance(node, ast.Import):
            names = [alias.name for alias in node.names]
        elif isinstance(node, ast.ImportFrom):
            base = node.module or ""
            if node.level:                                   # relative: from .x import y
                anchor = package.split(".")
                anchor = anchor[:len(anchor) - node.level + 1]
                base = ".".join(anchor + ([base] if base else []))
            # `from a.b import c` imports the module a.b.c when there is one, else a.b
            names = [f"{base}.{alias.name}" if f"{base}.{alias.name}" in known else base
                     for alias in node.names]
        else:
            continue
        for name in names:
            # `import a.b.c` runs a.b.c; only project modules matter here
            while name and name not in known:
                name = name.rpartition(".")[0]
            if name and name != module:
                yield name, node.lineno


def import_graph(root: Path, packages=PACKAGES) -> dict[str, dict[str, int]]:
    """module -> {imported module: line} over the packages' source files under `root`."""
    files = {module_name(path, root): path for package in packages
             for path in sorted((root / package).rglob("*.py"))}
    known = set(files)
    graph = {}
    for module, path in files.items():
        tree = ast.parse(path.read_text(), filename=str(path))
        graph[module] = dict(imported_modules(tree, module, path.name == "__init__.py", known))
    return graph


def upward_imports(graph) -> list[str]:
    return [f"{module} (line {line}) imports {target}: {group_of(module)} may import only "
            f"{', '.join(sorted(ALLOWED[group_of(module)]))}"
            for module, targets in graph.items() for target, line in targets.items()
            if group_of(target) not in ALLOWED[group_of(module)]]


def cycles(graph) -> list[list[str]]:
    """Every strongly connected component of more than one module (Tarjan)."""
    index, low, on_stack, stack, found = {}, {}, set(), [], []

    def visit(v):
        index[v] = low[v] = len(index)
        stack.append(v)
        on_stack.add(v)
        for w in graph.get(v, ()):
            if w not in index:
                visit(w)
                low[v] = min(low[v], low[w])
            elif w in on_stack:
                low[v] = min(low[v], index[w])
        if low[v] == index[v]:
            component = []
            while True:
                w = stack.pop()
                on_stack.discard(w)
                component.append(w)
                if w == v:
                    break
            if len(component) > 1:
                found.append(sorted(component))

    for v in sorted(graph):
        if v not in index:
            visit(v)
    return found


@pytest.fixture(scope="module")
def graph():
    return import_graph(ROOT)


def test_every_module_is_in_a_known_group(graph):
    assert {group_of(module) for module in graph} <= set(ALLOWED)
    assert {"renderer.core.scene", "renderer.gpu.pipeline", "renderer.checks.compare",
            "renderer.study.report", "renderer.viewer.viewer", "reference.pipeline"} <= set(graph)


def test_imports_point_down(graph):
    assert upward_imports(graph) == []


def test_there_is_no_import_cycle(graph):
    assert cycles(graph) == []


def test_only_the_command_line_imports_the_viewer(graph):
    importers = {module for module, targets in graph.items()
                 if any(group_of(t) == "viewer" for t in targets) and group_of(module) != "viewer"}
    assert importers == {"renderer.cli"}


def test_the_reference_imports_only_core(graph):
    outside = {target for module, targets in graph.items() if group_of(module) == "reference"
               for target in targets if group_of(target) not in ("reference", "core")}
    assert outside == set()


def test_the_checker_sees_an_upward_import_and_a_cycle(tmp_path):
    """The rules above can fail: a core module importing the GPU path, and two study modules
    importing each other (inside a function, as report.py and report_output.py once did)."""
    for package in ("renderer", "renderer/core", "renderer/gpu", "renderer/study", "reference"):
        (tmp_path / package).mkdir(parents=True, exist_ok=True)
        (tmp_path / package / "__init__.py").write_text("")
    (tmp_path / "renderer/gpu/pipeline.py").write_text("X = 1\n")
    (tmp_path / "renderer/core/scene.py").write_text("from renderer.gpu.pipeline import X\n")
    (tmp_path / "renderer/study/a.py").write_text("def f():\n    from renderer.study import b\n")
    (tmp_path / "renderer/study/b.py").write_text("from renderer.study.a import f\n")
    fake = import_graph(tmp_path)
    assert upward_imports(fake) == ["renderer.core.scene (line 1) imports renderer.gpu.pipeline: "
                                    "core may import only core, errors, renderer"]
    assert cycles(fake) == [["renderer.study.a", "renderer.study.b"]]
