"""The shadow knobs of `renderer report` (issue 15): the rasteriser's shadow maps at a series of
settings, each setting's error against ray-cast truth against its frame time.

    knob                  settings                              the others
    shadows-resolution    SHADOW_RESOLUTIONS texels a side      as the scene has them (the
    shadows-filter        FILTERS (hard, pcf2x2, 3x3, 5x5)      built-in scenes: automatic
    shadows-bias          BIAS_RULES (named_bias)               resolution, pcf2x2, auto bias)

A setting is applied to every light with shadows on (dataclasses.replace on its Shadow), to a
scene with shadow maps (renderer/core/shadows.py has_shadow_maps), drawn as authored, one
sample at each pixel's centre. Its time is a frame's (both passes), on each backend
(report.py times it like the other knobs); its error is shadows_vs_truth's at the report's size
(renderer/checks/shadow_truth.py: the reference's lookup, which the GPU's equals within the
pipeline tolerance, against the ray tracer's shadow rays), the same figures for both backends.
A setting whose maps exceed MAX_SHADOW_TEXELS at that size (a point light's six faces at 4096)
is left out. The cheapest setting per scene is the fastest reaching each of SHADOW_TARGETS.
"""

from __future__ import annotations

from dataclasses import replace

from renderer.core.shadow_settings import named_bias
from renderer.core.shadows import has_shadow_maps, shadow_layout
from renderer.errors import SceneError
from renderer.checks.shadow_truth import MAX_REACH_TEXELS, shadows_vs_truth
from renderer.study.report_settings import SHADOW_COLUMNS, SHADOW_TARGETS

FAMILY = "shadows"
KNOBS = {"resolution": f"{FAMILY}-resolution", "filter": f"{FAMILY}-filter", "bias": f"{FAMILY}-bias"}
HEADLINE = "wrong_outside_band_fraction"            # the plots' error
LINEAR_BELOW = 1e-4                                 # the plots' y axis is linear below, log above
BACKENDS = ("gpu", "reference")


def shadow_variants(resolutions, filters, biases) -> list[tuple[str, str, tuple]]:
    """(knob, setting, variant) of each shadow setting; variant = ("shadow", field, value)."""
    return ([(KNOBS["resolution"], str(r), ("shadow", "resolution", r)) for r in resolutions]
            + [(KNOBS["filter"], f, ("shadow", "filter", f)) for f in filters]
            + [(KNOBS["bias"], b, ("shadow", "bias", b)) for b in biases])


def with_shadow_setting(scene, field: str, value):
    """`scene` with `field` ("resolution", "filter" or "bias", a BIAS_RULES name) of every
    enabled light's Shadow set to `value`."""
    def changed(light):
        if not light.shadow.enabled:
            return light
        if field == "bias":
            return replace(light, shadow=replace(light.shadow, bias=named_bias(value, light.shadow.filter)))
        return replace(light, shadow=replace(light.shadow, **{field: value}))
    return replace(scene, directional_lights=[changed(light) for light in scene.directional_lights],
                   point_lights=[changed(light) for light in scene.point_lights])


def fits(scene, variant: tuple, width: int, height: int) -> bool:
    """Whether `scene` has shadow maps and the setting's maps stay within MAX_SHADOW_TEXELS."""
    if not has_shadow_maps(scene):
        return False
    try:
        shadow_layout(with_shadow_setting(scene, *variant[1:]), width, height)
    except SceneError:
        return False
    return True


def shadow_errors(scene, width: int, height: int) -> dict:
    """SHADOW_COLUMNS of `scene` at width x height: fractions of all pixels; peter-panning's
    largest distance in texels, MAX_REACH_TEXELS + 1 where some pixel is farther."""
    figures = shadows_vs_truth(scene, width, height).as_dict()
    reach = figures["peter_panning"]
    beyond = reach[f"beyond_{MAX_REACH_TEXELS}_texels"] > 0
    return dict(zip(SHADOW_COLUMNS, (
        figures["wrong_outside_band_fraction"],
        (figures["wrong_outside_band_pixels"] + figures["wrong_in_band_pixels"]) / figures["pixels"],
        figures["acne_pixels"],
        MAX_REACH_TEXELS + 1 if beyond else reach["max_texels"])))


def plot_axis(knob: str) -> dict:
    """plot_png's error axis for `knob`: the shadow knobs' HEADLINE (linear near 0, where a
    good setting lies), else the default (RMSE)."""
    if not knob.startswith(f"{FAMILY}-"):
        return {}
    return {"error": HEADLINE, "label": "pixels wrong outside the 1-texel band (fraction of all)",
            "linear_below": LINEAR_BELOW}


def is_shadow_row(row: dict) -> bool:
    return row["knob"].startswith(f"{FAMILY}-")


def cheapest_shadow(rows: list[dict], scene: str, backend: str, target) -> dict | None:
    """The fastest shadow row of `scene` on `backend` that meets `target` (a ShadowTarget), or None."""
    good = [r for r in rows if r["scene"] == scene and r["backend"] == backend
            and is_shadow_row(r) and target.met(r)]
    return min(good, key=lambda r: r["median_ms"]) if good else None


def method_bullet() -> str:
    return ("- **shadows-resolution, shadows-filter, shadows-bias** (scenes with shadow maps): each "
            "setting applied to every light with shadows on, the others as the scene has them "
            "(the built-in scenes: automatic resolution, pcf2x2, the automatic bias); the scene "
            "drawn as authored, one sample at each pixel's centre, and timed per frame (light "
            "views and the lit pass). Their error is the shadow maps' against ray-cast truth "
            "(`renderer compare --shadows-vs-truth`; docs/conventions.md, \"Shadows\"): "
            "`wrong_outside_band_fraction` (the plots' error), `wrong_fraction` (inside the "
            "1-texel band too), `acne_pixels`, `peter_panning_max_texels` "
            f"({MAX_REACH_TEXELS + 1}: farther than {MAX_REACH_TEXELS}). These figures come from "
            "the reference's lookup, so both backends' rows carry the same error (the GPU's "
            "lookup equals it within the pipeline tolerance); their image errors are left empty. "
            "A setting whose maps would exceed the texel budget at this size is left out.")


def shadow_sections(rows: list[dict], scenes: list[str]) -> list[str]:
    """The markdown naming, per scene, the cheapest shadow setting reaching each SHADOW_TARGETS."""
    scenes = [s for s in scenes if any(is_shadow_row(r) and r["scene"] == s for r in rows)]
    if not scenes:
        return []
    lines = []
    for target in SHADOW_TARGETS:
        lines += ["", f"## Cheapest shadow setting: {target.text()}", "",
                  "The fastest shadow setting (median time per frame) that meets the target, "
                  "against ray-cast truth.", "",
                  "| scene | GPU | ms | wrong outside the band | wrong in all | reference | ms |",
                  "| --- | --- | ---: | ---: | ---: | --- | ---: |"]
        for scene in scenes:
            gpu, ref = (cheapest_shadow(rows, scene, b, target) for b in BACKENDS)
            cells = [scene]
            cells += (["none reaches it", "", "", ""] if gpu is None else
                      [f"{gpu['knob'].split('-')[1]}: {gpu['setting']}", f"{gpu['median_ms']:.3g}",
                       f"{gpu['wrong_outside_band_fraction']:.3%}", f"{gpu['wrong_fraction']:.3%}"])
            cells += (["none reaches it", ""] if ref is None else
                      [f"{ref['knob'].split('-')[1]}: {ref['setting']}", f"{ref['median_ms']:.3g}"])
            lines.append("| " + " | ".join(cells) + " |")
    return lines
