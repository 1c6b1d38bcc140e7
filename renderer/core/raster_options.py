"""The rasteriser's options (renderer/gpu/pipeline.py's GpuRenderer): what a benchmark or a
check may change of how a frame is drawn, never what it shows."""

from __future__ import annotations

import dataclasses
from dataclasses import dataclass
from typing import ClassVar

from renderer.core.scene import SHADING_MODES
from renderer.errors import OptionError


@dataclass(frozen=True)
class RasterOptions:
    """`shading` ("flat", "gouraud", "phong") replaces every material's shading, None keeps
    the scene's (scene_for); `specialise` False draws with the all-features build of every
    program (a benchmark's baseline; the image is the same); `prune_shadows` False draws every
    caster into every shadow map (renderer/core/shadows.py, plan_shadows(prune=False))."""
    shading: str | None = None
    specialise: bool = True
    prune_shadows: bool = True
    # The fields a batch job's [[settings]] gives (renderer/batch/job_file.py): a setting's identity.
    SETTING_FIELDS: ClassVar[tuple[str, ...]] = ("shading",)

    def __post_init__(self):
        if self.shading is not None and self.shading not in SHADING_MODES:
            raise OptionError("shading", f"unknown shading {self.shading!r}; one of {', '.join(SHADING_MODES)}")

    def scene_for(self, scene):
        """The scene as these options draw it: a physical scene in the lighting equation's
        terms (renderer/core/physical.py), every material in `shading` where given (the
        rasteriser's camera is a pinhole; RayOptions.scene_for sets a lens)."""
        from renderer.core.physical import for_method
        scene = for_method(scene, "raster")
        return scene if self.shading is None else scene.with_shading(self.shading)

    def replace(self, **changes) -> "RasterOptions":
        return dataclasses.replace(self, **changes)

    def as_dict(self) -> dict:
        return dataclasses.asdict(self)
