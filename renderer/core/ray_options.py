"""The ray tracer's options, checked once (docs/conventions.md, "Sample positions", "Depth",
"Depth of field"): every range and every rule of two options together lives in RayOptions'
constructor, which raises the one OptionError (renderer/errors.py) naming the fields. The
command line (renderer/cli) and the job file (renderer/batch/job_file.py) only map their
spellings onto the fields (`--spp` and `samples`) and put their own name in front of the
same reason; the GPU tracer and the reference take a RayOptions and check nothing again.

    options = RayOptions(samples=16, pattern="jittered", max_depth=2)
    options.sampling                     # the frame's RaySampling (renderer/core/ray_sampling.py)
    options.scene_for(scene)             # the scene with the lens overrides applied
"""

from __future__ import annotations

import dataclasses
from dataclasses import dataclass, fields
from typing import ClassVar

from renderer.core.ray_depth import DEFAULT_MAX_DEPTH, MAX_DEPTH_LIMIT
from renderer.core.ray_sampling import RaySampling, ray_sampling
from renderer.core.sampling import DEFAULT_SEED
from renderer.errors import OptionError, SceneError

# The lens overrides: a camera's keys (scene files' [camera]) that the ray tracer's options
# may set for one render (`--aperture`, `--focus-distance`).
LENS_FIELDS = ("aperture", "focus_distance")


@dataclass(frozen=True)
class RayOptions:
    """How the ray tracer samples and recurses (module docstring). `shadows` False traces no
    shadow ray (a comparison's step); `specialise` False compiles every feature in (a
    benchmark's baseline; the image is the same). `aperture` and `focus_distance`, when not
    None, replace the camera's own for this render (scene_for)."""
    samples: int = 1
    pattern: str = "regular"
    adaptive_threshold: float | None = None
    max_depth: int = DEFAULT_MAX_DEPTH
    seed: int = DEFAULT_SEED
    light_samples: int = 1
    aperture: float | None = None
    focus_distance: float | None = None
    shadows: bool = True
    specialise: bool = True
    # The fields a batch job's [[settings]] gives (renderer/batch/job_file.py): a setting's
    # identity (the seed is each item's own).
    SETTING_FIELDS: ClassVar[tuple[str, ...]] = ("samples", "pattern", "max_depth",
                                                 "adaptive_threshold", "light_samples")
    METHOD: ClassVar[str] = "raytrace"          # what a physical scene is drawn as (scene_for)
    DEPTH_LIMIT: ClassVar[int] = MAX_DEPTH_LIMIT  # max_depth's most (the path tracer's: deeper)

    def __post_init__(self):
        if isinstance(self.max_depth, bool) or not isinstance(self.max_depth, int) \
                or not 0 <= self.max_depth <= self.DEPTH_LIMIT:
            raise OptionError("max_depth", f"must be between 0 and {self.DEPTH_LIMIT}, got {self.max_depth}")
        object.__setattr__(self, "_sampling", ray_sampling(
            self.pattern, self.samples, self.seed, self.adaptive_threshold, self.light_samples))
        self._check_lens()

    def _check_lens(self) -> None:
        """The lens keys' own ranges, by the scene file's rule for them (a parallel camera's
        aperture is the scene's part of that rule: scene_for)."""
        if self.lens:
            from renderer.core.scene import Camera
            self._with_lens(Camera(), "options")

    def _with_lens(self, camera, source: str):
        from renderer.core.scene_file import with_lens
        try:
            return with_lens(camera, self.lens, source=source)
        except SceneError as error:
            raise OptionError(error.key, error.reason) from None

    @property
    def sampling(self) -> RaySampling:
        """The frame's sampling rule (made, and so checked, by the constructor)."""
        return self._sampling

    @property
    def lens(self) -> dict:
        """The lens overrides given: {"aperture": ..., "focus_distance": ...}, those not None."""
        return {key: getattr(self, key) for key in LENS_FIELDS if getattr(self, key) is not None}

    def scene_for(self, scene):
        """`scene` as this method draws it (a physical one in its units: renderer/core/
        physical.py) with the lens overrides on its camera, checked as the scene file's [camera]
        keys are (renderer/core/scene_file.py, with_lens: an aperture on a parallel camera,
        a focus distance whose inverse float32 cannot hold): OptionError naming the field."""
        from renderer.core.physical import for_method
        scene = for_method(scene, self.METHOD)
        if not self.lens:
            return scene
        return dataclasses.replace(scene, camera=self._with_lens(scene.camera, scene.source or scene.name))

    def replace(self, **changes) -> "RayOptions":
        """A copy with `changes` (checked again)."""
        return dataclasses.replace(self, **changes)

    def as_dict(self) -> dict:
        """The fields by name (a manifest's record, a report's row)."""
        return {f.name: getattr(self, f.name) for f in fields(self)}

