"""The old flat module names (renderer.scene, renderer.compare, ...), kept working for one
release after the modules moved into subpackages: `import renderer.scene` gives the very
module renderer.core.scene, with a DeprecationWarning naming the new home."""

from __future__ import annotations

import importlib
import importlib.abc
import importlib.util
import sys
import warnings

MOVED = {
    **{name: "renderer.core." + name for name in (
        "scene", "transforms", "frame", "visibility", "primitives", "meshio", "scene_file",
        "builtin", "resources", "imageio", "sampling")},
    **{name: "renderer.gpu." + name for name in ("context", "osmesa", "shaders")},
    **{name: "renderer.checks." + name for name in (
        "compare", "perceptual", "policies", "goldens", "golden_report", "pytest_plugin")},
    **{name: "renderer.study." + name for name in (
        "report", "report_output", "supersample", "ground_truth", "tessellation", "extremes")},
    **{name: "renderer.viewer." + name for name in (
        "window", "presenter", "controls", "orbit", "overlay", "reference_view",
        "virtual_display")},
}


class _Alias(importlib.abc.MetaPathFinder, importlib.abc.Loader):
    """Finds renderer.OLD and loads it as the module at its new name."""

    def find_spec(self, fullname, path=None, target=None):
        package, _, name = fullname.rpartition(".")
        if package == "renderer" and name in MOVED:
            return importlib.util.spec_from_loader(fullname, self)
        return None

    def create_module(self, spec):
        return None

    def exec_module(self, module) -> None:
        new = MOVED[module.__name__.rpartition(".")[2]]
        warnings.warn(f"{module.__name__} moved to {new}; the old name will be removed in release 0.2",
                      DeprecationWarning, stacklevel=2)
        # The import system hands back whatever sys.modules holds under the name once this
        # returns: the module at its new name, so both names share one module object.
        sys.modules[module.__name__] = importlib.import_module(new)


def install() -> None:
    if not any(isinstance(finder, _Alias) for finder in sys.meta_path):
        sys.meta_path.append(_Alias())
