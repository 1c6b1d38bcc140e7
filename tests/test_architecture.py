"""The layout as a rule: imports point down, and there is no import cycle.

    errors      imports nothing of the project
    core        errors
    reference   core, errors                     (only the core modules of REFERENCE_SHARES)
    gpu         core, errors
    methods     core, gpu, reference, errors     (one call opens every method on every backend)
    cluster     core, gpu, reference, methods, errors   (where work runs: in-process or Ray)
    checks      core, gpu, reference, methods, errors
    study       core, gpu, checks, reference, methods, cluster, errors
    batch       core, gpu, checks, reference, methods, cluster, errors
    viewer      core, gpu, checks, reference, methods, errors
    cli         anything (only the command line imports the viewer)

The graph is read from the source (every import statement, function-level ones included) of
renderer/ and reference/, so an import hidden inside a function counts too.

The twin is not independent of core. Whatever it imports from there the GPU path reads too, so a
mistake in such a module is the same on both sides, and no comparison of the GPU with the twin
can see it. REFERENCE_SHARES lists each core module the reference imports. For each one it says
why the module must be shared, or which check that does not share it catches its mistakes.
The list stays exact: an import missing from it fails a test, and so does an entry the reference
no longer imports. reference/__init__.py and the README name the same modules.
"""

import ast
import re
from pathlib import Path

import pytest

ROOT = Path(__file__).resolve().parents[1]
PACKAGES = ("renderer", "reference")

# group -> the groups it may import (itself included). The root package (renderer/__init__.py:
# __version__) is imported by every import of a submodule anyway.
ALLOWED = {
    "renderer": {"renderer"},                    # renderer/__init__.py
    "errors": {"errors"},
    "core": {"core", "errors"},
    "reference": {"reference", "core", "errors"},
    "gpu": {"gpu", "core", "errors"},
    "methods": {"methods", "core", "gpu", "reference", "errors"},
    "cluster": {"cluster", "core", "gpu", "reference", "methods", "errors"},
    "checks": {"checks", "core", "gpu", "reference", "methods", "errors"},
    "study": {"study", "core", "gpu", "checks", "reference", "methods", "cluster", "errors"},
    "batch": {"batch", "core", "gpu", "checks", "reference", "methods", "cluster", "errors"},
    "viewer": {"viewer", "core", "gpu", "checks", "reference", "methods", "errors"},
    "cli": {"cli", "core", "gpu", "checks", "study", "viewer", "reference", "methods", "cluster",
            "batch", "errors"},
}
ALLOWED = {group: allowed | {"renderer"} for group, allowed in ALLOWED.items()}

# The modules of renderer/core that reference/** may import. For each: why it must be shared,
# or which check, sharing nothing with it, catches its mistakes (the module docstring above).
REFERENCE_SHARES = {
    # containers and settings: no image rule of their own
    "frame": "Frame, what both pipelines hand back",
    "output_settings": "the output stage's knobs (transfer, bits, dither, half-tone) as the user gave them",
    "memory": "REFERENCE_TILE_PIXELS, the reference's band size, also used by the memory estimates; "
              "tests/test_reference_tiles.py: bands equal one pass bit for bit",
    # data and rules the twin must reproduce bit for bit, each checked by hand or against others
    "gl_rules": "GL's fixed-function rules; by hand in tests/test_gl_rules.py, llvmpipe held to them "
                "in tests/test_rasterizer.py, test_extremes.py and test_reference_stages.py",
    "uniforms": "the GLSL's light, material and UV values from the scene; names and types against the "
                "GLSL in tests/test_glsl_contract.py, the lighting from them by hand in tests/test_lighting.py",
    "colour": "the CIE matrices; against colour-science in tests/test_colour.py",
    "quantise": "the quantisation tables; against the transfer curves in tests/test_quantise_rule.py",
    "blue_noise": "the dither mask; its defining properties in tests/test_output_dither.py",
    "error_kernels": "the kernels and their wavefront order; against the classic push algorithm and "
                     "every dependency in tests/test_output_diffusion.py",
    "halftone_screen": "the screens' geometry and threshold arrays; the dot by hand, its area law and "
                       "nesting in tests/test_output_halftone.py",
    "sampling": "DEFAULT_SEED (and, through ray_sampling, the pattern tables); each pattern by hand "
                "in tests/test_sampling.py",
    "ray_sampling": "the ray tracer's sampling rule and constants; by hand in tests/test_raytrace_sampling.py, "
                    "the distributed points by chi-square in tests/test_sampler_statistics.py",
    "ray_depth": "RAY_WEIGHT_CUTOFF (trace.glsl's TRACE_WEIGHT_CUTOFF); its bound in "
                 "tests/test_raytrace_precision.py",
    "path_options": "the path tracer's sample dimensions and Russian roulette's start (pathtrace.glsl's "
                    "constants, held equal in tests/test_pathtrace.py); the diffuse bounce by chi-square in "
                    "tests/test_sampler_statistics.py, the paths against the furnace's closed form in "
                    "tests/test_pathtrace.py",
    "light_areas": "the area-light uniform and its shape codes; the axes by hand and the twin against "
                   "closed forms in tests/test_raytrace_area_lights.py",
    # computations with a check that does not share them
    "shadows": "the shadow plan (layers, light views, cube faces); against ray-cast truth that does "
               "not read it, renderer/checks/shadow_truth.py (tests/test_shadow_truth.py)",
    "shadow_settings": "the filters' taps and the slope cap of the shadow lookup; against ray-cast "
                       "truth, renderer/checks/shadow_truth.py",
    "facets": "the shadow lookup's facet normals and creases; against ray-cast truth, "
              "renderer/checks/shadow_truth.py",
    "visibility": "frustum culling; the culled frame against the unculled all-features build "
                  "in tests/test_specialisation.py",
    "drawn": "an analytic plane's polygon in the view; its depth against rays cast at the infinite "
             "plane, renderer/checks/depth_truth.py (tests/test_depth_truth.py)",
    "camera_rays": "the ray tracer's primary rays from P V; the rasteriser, which does not read them, "
                   "against the ray tracer in tests/test_raytrace_trace.py and renderer/checks/methods.py",
    "hemicube": "radiosity's hemicube faces, their matrices and delta form factors; by hand and against "
                "Howell's closed forms (renderer/checks/form_factor_closed_forms.py) in tests/test_hemicube.py",
    "raytrace_scene": "the ray tracer's scene and BVH; the BVH against brute force in tests/test_raytrace_bvh.py, "
                      "the rasteriser against the ray tracer in tests/test_raytrace_trace.py",
    "tessellation": "a tessellated sphere's patches and the levels' settings and draw bound; the levels' rule "
                    "by the sagitta it bounds (tests/test_tessellation_stages.py), the bound by the "
                    "tessellator's twin and the sphere against the ray tracer's exact one "
                    "(tests/test_tessellation_raster.py)",
}


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
    if len(parts) == 1:
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
    assert importers == {"renderer.cli.view"}


def test_the_reference_imports_only_core(graph):
    outside = {target for module, targets in graph.items() if group_of(module) == "reference"
               for target in targets if group_of(target) not in ("reference", "core")}
    assert outside == set()


def reference_core_imports(graph) -> dict[str, list[str]]:
    """Each core module the reference imports (its name in renderer/core) -> the importers."""
    found: dict[str, list[str]] = {}
    for module, targets in graph.items():
        if group_of(module) == "reference":
            for target in targets:
                if group_of(target) == "core":
                    found.setdefault(target.removeprefix("renderer.core."), []).append(module)
    return found


def test_the_reference_imports_only_the_core_modules_it_declares(graph):
    undeclared = {name: importers for name, importers in reference_core_imports(graph).items()
                  if name not in REFERENCE_SHARES}
    assert undeclared == {}, ("add each to REFERENCE_SHARES, saying why the twin must share it "
                              "or which check that does not share it catches its mistakes")


def test_every_declared_core_module_is_still_imported_by_the_reference(graph):
    """The list stays minimal: an entry the reference no longer imports is dropped."""
    assert set(REFERENCE_SHARES) - set(reference_core_imports(graph)) == set()


def named_core_modules(text: str) -> set[str]:
    """The renderer/core modules that `text` names as `name.py` (in backticks)."""
    core = {path.stem for path in (ROOT / "renderer/core").glob("*.py")}
    return {name for name in re.findall(r"`(\w+)\.py`", text) if name in core}


def shares_list(text: str) -> str:
    """The bulleted list of `text` (from its first "- " line to its end), spaces normalised."""
    return " ".join(text[text.index("\n- ") + 1:].split())


def test_the_reference_and_the_readme_name_the_declared_modules():
    """reference/__init__.py's docstring ends with the same list as docs/layout.md's block
    between the twin-shares markers. The list names exactly the modules of REFERENCE_SHARES, in backticks."""
    docstring = ast.get_docstring(ast.parse((ROOT / "reference/__init__.py").read_text()))
    layout = (ROOT / "docs" / "layout.md").read_text(encoding="utf-8")
    block = re.search(r"<!-- twin-shares -->(.*?)<!-- /twin-shares -->", layout, re.S)
    assert block, "docs/layout.md has no <!-- twin-shares --> ... <!-- /twin-shares --> block"
    assert named_core_modules(docstring) == set(REFERENCE_SHARES)
    assert shares_list(block.group(1)) == shares_list(docstring)


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
