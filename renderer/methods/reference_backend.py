"""The NumPy twin behind the Renderer protocol (renderer/gpu/base.py): no GL and nothing to
free; each render() computes the frame afresh from the scene. `precision` ("float32" or
"float64") may change between frames: a check's float64 truth of the same scene reuses what
the renderer built (the ray tracer's BVH)."""

from __future__ import annotations

import numpy as np

from renderer.core.frame import Frame, image_size
from renderer.core.scene import Scene


class ReferenceRenderer:
    """The lifetime and scene handling the reference's renderers share."""

    default_precision = "float64"

    def __init__(self, scene: Scene, width: int, height: int, options, precision: str | None = None):
        self.scene = scene
        self.width, self.height = image_size(width, height)
        self.options = options
        self.precision = precision or self.default_precision

    @property
    def dtype(self) -> np.dtype:
        return np.dtype(self.precision)

    def render(self, out: Frame | None = None, *, linear: bool = False, depth: bool = True,
               progress=None, **extra) -> Frame:
        """The twin's frame (`progress(rows done, rows)` told as the method can, and when it
        is done); `out` is taken for the protocol's sake and not reused: the twin's arrays are
        its own, made afresh each frame."""
        frame = self._frame(linear=linear, depth=depth, progress=progress, **extra)
        if progress is not None:
            progress(self.height, self.height)
        return frame

    def _frame(self, *, linear: bool, depth: bool, progress=None, **extra) -> Frame:
        raise NotImplementedError

    def update(self, scene: Scene | None = None) -> None:
        """The next frame draws `scene` (or the scene changed in place): nothing is cached
        that a change could leave stale but what _scene_changed() drops."""
        if scene is not None:
            self.scene = scene
        self._scene_changed()

    def _scene_changed(self) -> None:
        pass

    def resize(self, width: int, height: int) -> None:
        self.width, self.height = image_size(width, height)

    def release(self) -> None:
        pass

    @property
    def gl_info(self) -> dict:
        return {"backend": "reference", "precision": self.precision}

    def __enter__(self):
        return self

    def __exit__(self, *exc) -> None:
        self.release()

    def __repr__(self) -> str:
        return f"<{type(self).__name__} {self.scene.name!r} {self.width}x{self.height} {self.precision}>"
