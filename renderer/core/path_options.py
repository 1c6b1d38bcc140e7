"""The path tracer's options (issue 33; renderer/methods/pathtrace.py, docs/pathtrace.md): the
ray tracer's (renderer/core/ray_options.py: samples, pattern, seed, light samples, the lens),
with the defaults a Monte Carlo estimate wants, and the constants both twins read.

    options = PathOptions(samples=64)          # jittered, up to 32 bounces
    options.sampling                           # the frame's RaySampling, as the ray tracer's

`max_depth` is the most bounces a path takes (the camera ray's hit is bounce 0); Russian
roulette ends most paths long before it (ROULETTE_DEPTH). The rest is RayOptions' rules.
"""

from __future__ import annotations

from dataclasses import dataclass
from typing import ClassVar

from renderer.core.ray_options import RayOptions
from renderer.errors import OptionError

DEFAULT_PATH_SAMPLES = 16
DEFAULT_PATH_PATTERN = "jittered"       # stratified and unbiased: regular's cell centres are not
DEFAULT_PATH_DEPTH = 32
# The deepest path asked for: a closed room of reflectance rho loses rho^(D + 2) of its light to
# the cut-off (0.99^1026 = 3e-5), while Russian roulette ends nearly every path long before. A
# pass traces one sample, so llvmpipe's 65535 loop iterations an invocation (renderer/gpu/
# pathtracer.py) bound a path's bounces times its BVH steps: about 60 steps a bounce here.
PATH_DEPTH_LIMIT = 1024
# Russian roulette (Arvo and Kirk 1990) from this bounce on: a path goes on with probability
# q = min(1, the largest channel of its weight) and its weight is divided by q, so that the
# estimate stays unbiased while a dim path ends early. The GLSL's ROULETTE_DEPTH (a #define).
ROULETTE_DEPTH = 3
# The distributed dimensions a path's bounce draws at slot 1 + bounce (renderer/core/
# ray_sampling.py): above every point light's LIGHT_DIMENSION + i (fewer than 1023 point lights
# fit the lights' uniforms), so that a bounce's numbers are its own. glsl/raytrace/pathtrace.glsl
# holds the same values (tests/test_pathtrace.py checks them).
EMITTER_CHOICE_DIMENSION = 1024       # 1D: which emitting triangle next-event estimation samples
EMITTER_POINT_DIMENSION = 1025        # 2D: the point on it
LOBE_DIMENSION = 1026                 # 1D: diffuse, reflected or transmitted
BOUNCE_DIMENSION = 1027               # 2D: the diffuse direction (cosine-weighted)
ROULETTE_DIMENSION = 1028             # 1D: whether the path goes on


@dataclass(frozen=True)
class PathOptions(RayOptions):
    """RayOptions with the path tracer's defaults (module docstring); every pattern but
    adaptive, whose per-pixel decision the GPU's passes of one sample do not make."""
    samples: int = DEFAULT_PATH_SAMPLES
    pattern: str = DEFAULT_PATH_PATTERN
    max_depth: int = DEFAULT_PATH_DEPTH
    METHOD: ClassVar[str] = "pathtrace"          # a physical scene in exitance units (scene_for)

    DEPTH_LIMIT: ClassVar[int] = PATH_DEPTH_LIMIT

    def __post_init__(self):
        super().__post_init__()
        if self.pattern == "adaptive":
            raise OptionError("pattern", "the path tracer takes every pattern but adaptive")
