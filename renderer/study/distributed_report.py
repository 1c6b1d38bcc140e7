"""The distributed effects' knobs of `renderer report --method raytrace` (issue 16): how the
error of soft shadows, depth of field, motion blur and glossy reflection falls with the samples
spent on them, by pattern, against run time (renderer/study/ray_report.py runs them; the
conventions: docs/conventions.md, "Distributed sampling").

    knob            scenes                              settings
    light_samples   some point light has an area        N = LIGHT_CARRIER_SAMPLES pixel samples,
                                                        M = 1, 4, 16, 64 light samples per hit
                                                        and light, by pattern
    lens            the camera has an aperture          N = 1, 4, 16, 64 pixel samples (each
    time            the shutter is open and something   carries one lens point, one time, one
                    moves                               glossy direction per hit), by pattern
    glossy          a reflecting material has a finite
                    gloss exponent

A scene's lens, time and glossy knobs trace the same frames as its antialiasing knob would (a
pixel sample carries one point of every dimension), so such a scene gets them instead of
antialiasing: the rows say which dimension their samples were spent on. A scene with area
lights keeps antialiasing (N pixel samples carrying one light sample each) beside
light_samples (M per hit at a fixed N): the two ways of buying a penumbra.
"""

from __future__ import annotations

import math

from renderer.core.light_areas import uses_area_lights
from renderer.core.motion import moves
from renderer.core.sampling import PATTERNS
from renderer.study.report_output import convergence_slopes, spread
from renderer.study.report_settings import DISTRIBUTED_KNOBS, EFFECT_KNOBS

LIGHT_CARRIER_SAMPLES = 4            # pixel samples under the light_samples knob (a 2 x 2 grid)

# The textbook rates of RMSE in the samples spent on a dimension (Mitchell, "Consequences of
# Stratified Sampling in Graphics", SIGGRAPH 1996): random N^-0.5 whatever the integrand;
# jittered N^-(1/2 + 1/(2d)) where the integrand has edges in d dimensions, N^-(1/2 + 1/d)
# where it is smooth. Each dimension is stratified by itself and shuffled against the others
# (Cook 1984), not stratified jointly, so over the pixel's 2 dimensions and the effect's,
# jittered keeps only what each dimension's own strata give.
EFFECT_TEXTBOOK = {
    "light_samples": ("random N^-0.5; jittered N^-0.75",
                      "visibility over the light's 2D area has an edge (the blocker's silhouette)"),
    "lens": ("random N^-0.5; jittered between N^-0.5 and N^-0.75",
             "4 dimensions (pixel, lens) stratified 2 by 2 and shuffled, not jointly"),
    "time": ("random N^-0.5; jittered up to N^-1 in time alone",
             "a moving edge is a step in the 1D time, whose N strata only one straddles; the "
             "pixel's 2D edge adds its N^-0.75"),
    "glossy": ("random N^-0.5; jittered about N^-0.75",
               "the lobe's 2D directions see the reflected objects' edges"),
}


def scene_effects(scene) -> set[str]:
    """The distributed knobs that apply to `scene`: what it uses with a non-degenerate value."""
    effects = set()
    if uses_area_lights(scene):
        effects.add("light_samples")
    camera = scene.camera
    if camera.has_lens:
        effects.add("lens")
    if camera.shutter[0] < camera.shutter[1] and moves(scene):    # an open shutter, a motion
        effects.add("time")
    if any(obj.material.is_glossy for obj in scene.objects):
        effects.add("glossy")
    return effects


def distributed_settings(setting_type, sweep, depth: int) -> list:
    """The distributed knobs' settings (module docstring), each on both backends, as
    `setting_type` (ray_report.RaySetting) rows."""
    out = []
    for pattern in PATTERNS:
        for knob in EFFECT_KNOBS:
            for n in sweep.sample_counts:
                if pattern != "regular" or math.isqrt(n) ** 2 == n:
                    out += [setting_type(knob, f"{pattern} {n}", backend, pattern, n, depth)
                            for backend in ("gpu", "reference")]
        for m in sweep.light_counts:
            out += [setting_type("light_samples", f"{pattern} {LIGHT_CARRIER_SAMPLES}x{m}", backend,
                                 pattern, LIGHT_CARRIER_SAMPLES, depth, light_samples=m)
                    for backend in ("gpu", "reference")]
    return out


def settings_for_scene(plan: list, scene) -> list:
    """The settings `scene` gets: each distributed knob where the scene uses its effect; the
    antialiasing settings only where no lens, time or glossy knob traces them instead."""
    effects = scene_effects(scene)
    instead = bool(effects & set(EFFECT_KNOBS))
    return [s for s in plan if (s.knob in DISTRIBUTED_KNOBS and s.knob in effects)
            or (s.knob not in DISTRIBUTED_KNOBS and not (instead and s.knob == "antialiasing"))]


def slope_x(knob: str) -> str:
    """The column a knob's convergence is measured in: the light samples per hit for
    light_samples, the samples per pixel for the others."""
    return "light_samples" if knob == "light_samples" else "samples"


def distributed_sections(rows: list[dict]) -> list[str]:
    """report.md's section on the distributed knobs present in `rows`: per knob and pattern,
    the slope of log RMSE in log samples (and in log time) beside the textbook rate."""
    knobs = [k for k in DISTRIBUTED_KNOBS if any(r["knob"] == k for r in rows)]
    if not knobs:
        return []
    lines = ["", "## Distributed effects: convergence by dimension", "",
             "Each knob spends samples on one distributed dimension (docs/conventions.md, "
             "\"Distributed sampling\"): `light_samples` M shadow rays per area light and hit at "
             f"{LIGHT_CARRIER_SAMPLES} pixel samples (x: M); `lens`, `time`, `glossy` N pixel "
             "samples, each carrying one lens point, one time and one glossy direction per hit "
             "(x: N). Slopes of log RMSE against log x and against log time, least squares over "
             "the scenes with that effect, each with its own intercept.", "",
             "| knob | pattern | backend | slope in x | per scene | slope in time | points | "
             "textbook | why |", "| --- | --- | --- | ---: | --- | ---: | ---: | --- | --- |"]
    for knob in knobs:
        knob_rows = [r for r in rows if r["knob"] == knob]
        patterns = list(dict.fromkeys(r["pattern"] for r in knob_rows))
        in_x = convergence_slopes(knob_rows, patterns, x=slope_x(knob), knob=knob)
        in_time = convergence_slopes(knob_rows, patterns, x="median_ms", knob=knob)
        rate, why = EFFECT_TEXTBOOK[knob]
        for (pattern, backend), fit in in_x.items():
            timed = in_time.get((pattern, backend))
            lines.append(f"| {knob} | {pattern} | {backend} | {fit.slope:.2f} | {spread(fit)} | "
                         f"{f'{timed.slope:.2f}' if timed else ''} | {fit.points} | {rate} | {why} |")
    return lines
