"""Names users have: the public ones stay."""

import importlib.metadata


def test_public_names():
    import reference
    from reference.pipeline import render
    from renderer.gpu import GpuRenderer
    from renderer.gpu.pipeline import GpuRenderer as same
    from renderer.methods import open_renderer
    assert callable(open_renderer)
    from renderer.viewer import Viewer
    from renderer.viewer.viewer import Viewer as same_viewer
    assert GpuRenderer is same and Viewer is same_viewer and reference.render is render
    plugins = [e.value for e in importlib.metadata.entry_points(group="pytest11")
               if e.name == "checked_renderer_goldens"]
    assert plugins == ["renderer.checks.pytest_plugin"]



def test_the_old_flat_module_names_are_gone():
    """renderer.scene and the like (before the subpackages) import no more: no alias hook."""
    import importlib.util
    assert importlib.util.find_spec("renderer.scene") is None
    assert importlib.util.find_spec("renderer.core.scene") is not None
