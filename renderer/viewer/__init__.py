"""The interactive window viewer (`renderer view`): the glfw window, the frame loop, controls,
orbit camera, presentation (double and triple buffering), the background reference view, the
overlay and a virtual X display for tests. Imports core, gpu, checks and the reference; only the
command line imports it.

    from renderer.viewer import Viewer
"""

__all__ = ["Viewer"]


def __getattr__(name: str):
    # Lazy, so that importing one of the viewer's modules (the reference view's worker
    # process imports reference_view) does not import glfw and the whole frame loop.
    if name == "Viewer":
        from renderer.viewer.viewer import Viewer
        return Viewer
    raise AttributeError(f"module 'renderer.viewer' has no attribute {name!r}")
