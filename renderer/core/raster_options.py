"""The rasteriser's options (renderer/gpu/pipeline.py's GpuRenderer): what a benchmark or a
check may change of how a frame is drawn, never what it shows."""

from __future__ import annotations

import dataclasses
from dataclasses import dataclass


@dataclass(frozen=True)
class RasterOptions:
    """`specialise` False draws with the all-features build of every program (a benchmark's
    baseline; the image is the same); `prune_shadows` False draws every caster into every
    shadow map (renderer/core/shadows.py, plan_shadows(prune=False))."""
    specialise: bool = True
    prune_shadows: bool = True

    def scene_for(self, scene):
        """The scene as these options draw it: as it is (the rasteriser's camera is a pinhole;
        RayOptions.scene_for sets a lens)."""
        return scene

    def replace(self, **changes) -> "RasterOptions":
        return dataclasses.replace(self, **changes)

    def as_dict(self) -> dict:
        return dataclasses.asdict(self)
