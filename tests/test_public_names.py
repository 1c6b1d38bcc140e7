"""Names users have: the public ones stay, and the old flat module names still import for one
release (renderer/_moved.py), as the very modules at their new homes, with a warning."""

import importlib
import importlib.metadata
import importlib.util
import sys

import pytest

from renderer._moved import MOVED


def test_public_names():
    import reference
    from reference.pipeline import render
    from renderer.gpu import GpuRenderer
    from renderer.gpu.pipeline import GpuRenderer as same
    from renderer.viewer import Viewer
    from renderer.viewer.viewer import Viewer as same_viewer
    assert GpuRenderer is same and Viewer is same_viewer and reference.render is render
    plugins = [e.value for e in importlib.metadata.entry_points(group="pytest11")
               if e.name == "checked_renderer_goldens"]
    assert plugins == ["renderer.checks.pytest_plugin"]


@pytest.mark.parametrize("old", sorted(MOVED))
def test_an_old_name_is_the_moved_module_with_a_warning(old):
    sys.modules.pop(f"renderer.{old}", None)          # an earlier test may have imported it
    with pytest.warns(DeprecationWarning) as caught:
        module = importlib.import_module(f"renderer.{old}")
    assert module is importlib.import_module(MOVED[old])
    assert [str(w.message) for w in caught] == [
        f"renderer.{old} moved to {MOVED[old]}; the old name will be removed in release 0.2"]


def test_every_module_that_moved_has_its_old_name():
    """The 33 flat modules of renderer/ that went into core, gpu, checks, study and viewer
    (gpu.py is renderer/gpu/pipeline.py behind the package renderer.gpu)."""
    assert len(MOVED) == 33
    for new in MOVED.values():
        assert importlib.util.find_spec(new) is not None, new
