"""`renderer colour`'s files, written all or none (renderer/core/imageio.py `outputs`):

    chromaticity.png   the CIE 1931 xy diagram: spectral locus, sRGB gamut, D65, the pixels
                       (a 2D histogram), a scene's materials (k_d) and lights marked
    luminance.png      the histogram of the pixels' CIE Y
    munsell.md         each object's k_d as Munsell hue, value and chroma (renderer/study/
                       munsell.py), or an image's mean colour
    colour.json        the figures: pixel counts, luminance statistics, chromaticity
                       percentiles, the materials and lights, the matrix and white point used

Only counted pixels (alpha > 0) are measured; a chromaticity only where there is light
(renderer/study/colour_source.py).
"""

from __future__ import annotations

from dataclasses import asdict
from pathlib import Path

import numpy as np

from reference.output.colour import chromaticity, rgb_to_xyz
from renderer.core.colour import D65_XY, RGB_TO_XYZ
from renderer.core.imageio import outputs
from renderer.core.jsonio import json_text
from renderer.core.output_settings import Transfer
from renderer.core.quantise import encode
from renderer.study.colour_plots import Mark, chromaticity_png, luminance_png
from renderer.study.colour_source import ColourSource
from renderer.study.munsell import munsell_of

COLOUR_FILES = ("chromaticity.png", "luminance.png", "munsell.md", "colour.json")
PERCENTILES = (1, 5, 50, 95, 99)


def _rounded(values, places: int = 6) -> list:
    return [round(float(v), places) for v in np.ravel(values)]


def _display(rgb) -> tuple:
    """A marker's face colour: the linear colour scaled to a largest channel of at most 1,
    sRGB-encoded (so a light of intensity 3 shows its hue)."""
    rgb = np.maximum(np.asarray(rgb, np.float64), 0.0)
    return tuple(encode(rgb / max(1.0, rgb.max()), Transfer("srgb")).tolist())


def colour_entry(rgb) -> dict:
    """A colour's linear RGB, XYZ and chromaticity x, y as JSON numbers."""
    xyz = rgb_to_xyz(rgb)
    return {"rgb": _rounded(rgb), "xyz": _rounded(xyz), "xy": _rounded(chromaticity(xyz)[:2])}


def materials(scene) -> list[dict]:
    """Each object's k_d (and whether a texture modulates it) with its Munsell notation."""
    rows = []
    for obj in scene.objects:
        kd = obj.material.kd
        textured = obj.material.texture is not None and "kd" in obj.material.texture.modulate
        rows.append({"object": obj.name, **colour_entry(kd), "textured": textured,
                     "munsell": asdict(munsell_of(kd))})
    return rows


def lights(scene) -> list[dict]:
    """The colour of each light (its intensity's RGB) and of the ambient term."""
    named = [("ambient", scene.ambient)]
    named += [(f"directional {i}", light.intensity) for i, light in enumerate(scene.directional_lights)]
    named += [(f"point {i}", light.intensity) for i, light in enumerate(scene.point_lights)]
    return [{"light": name, **colour_entry(rgb), "dark": not sum(rgb) > 0} for name, rgb in named]


def summary(source: ColourSource) -> dict:
    """colour.json's figures for `source` (module docstring)."""
    covered, lit = source.covered, source.lit
    luminance = source.xyz[..., 1][covered].astype(np.float64)
    xy = source.chromaticity[lit][:, :2].astype(np.float64)
    stats = {}
    if luminance.size:
        stats = {"mean": float(luminance.mean()), "min": float(luminance.min()),
                 "max": float(luminance.max())} | {
            f"p{p:02d}": float(v) for p, v in zip(PERCENTILES, np.percentile(luminance, PERCENTILES))}
    mean_rgb = source.linear[..., :3][covered].astype(np.float64).mean(axis=0) if covered.any() else np.zeros(3)
    return {
        **source.details,
        "white_point": {"name": "D65", "xy": list(D65_XY)},
        "rgb_to_xyz": [_rounded(row, 10) for row in RGB_TO_XYZ],
        "pixels": {"total": int(covered.size), "counted": int(covered.sum()), "lit": int(lit.sum())},
        "luminance": {key: round(value, 6) for key, value in stats.items()},
        "chromaticity_percentiles": {axis: _rounded(np.percentile(xy[:, i], PERCENTILES))
                                     for i, axis in enumerate("xy")} if len(xy) else {},
        "percentiles": list(PERCENTILES),
        "mean_colour": colour_entry(mean_rgb) | {"munsell": asdict(munsell_of(mean_rgb))},
        "materials": materials(source.scene) if source.scene is not None else [],
        "lights": lights(source.scene) if source.scene is not None else [],
    }


def _cell(value) -> str:
    return "" if value is None else str(value)


def munsell_markdown(source: ColourSource, figures: dict) -> str:
    """munsell.md: a table of each object's k_d (an image: its mean colour) in Munsell terms."""
    lines = [f"# Munsell notation: {source.name}", "",
             "Munsell hue, value and chroma by colour-science's inversion of the Munsell "
             "renotation (xyY_to_munsell_colour), after adapting from D65 (our white) to the "
             "renotation's illuminant C (von Kries, Bradford). Colours outside the renotation "
             "data are said in words.", ""]
    if source.scene is not None:
        rows = [(entry["object"] + (" (textured: k_d times the texel)" if entry["textured"] else ""),
                 entry) for entry in figures["materials"]]
        lines.append("Each object's diffuse colour k_d (linear RGB), as a surface colour.")
    else:
        rows = [("mean colour", figures["mean_colour"])]
        lines.append("An image has no materials: the row is the mean linear colour of its "
                     f"{figures['pixels']['counted']} counted pixels.")
    lines += ["", "| what | linear RGB | x, y | Y | Munsell | hue | value | chroma | note |",
              "|---|---|---|---|---|---|---|---|---|"]
    for label, entry in rows:
        munsell = entry["munsell"]
        rgb = ", ".join(f"{v:.3f}" for v in entry["rgb"])
        xy = ", ".join(f"{v:.4f}" for v in entry["xy"])
        lines.append(f"| {label} | {rgb} | {xy} | {entry['xyz'][1]:.4f} | "
                     f"{_cell(munsell['notation'])} | {_cell(munsell['hue'])} | "
                     f"{munsell['value']:.1f} | {_cell(munsell['chroma'])} | {munsell['note']} |")
    return "\n".join(lines) + "\n"


def marks(figures: dict) -> list[Mark]:
    """The diagram's marks: every object's k_d and every light with some light."""
    found = [Mark(m["object"], tuple(m["xy"]), "material", _display(m["rgb"]))
             for m in figures["materials"]]
    return found + [Mark(m["light"], tuple(m["xy"]), "light", _display(m["rgb"]))
                    for m in figures["lights"] if not m["dark"]]


def write_colour_report(source: ColourSource, out: Path) -> list[Path]:
    """Every file of COLOUR_FILES in `out`, or none; the paths written."""
    figures = summary(source)
    what = f"{source.name} ({source.details['kind']}, {source.details['backend']})"
    xy = source.chromaticity[source.lit][:, :2]
    luminance = source.xyz[..., 1][source.covered]
    with outputs(*(out / name for name in COLOUR_FILES)) as written:
        written.bytes(out / "chromaticity.png", chromaticity_png(
            xy, marks(figures), f"CIE 1931 chromaticity of {what}: {len(xy)} pixels"))
        written.bytes(out / "luminance.png", luminance_png(
            luminance, f"Luminance Y of {what}: {len(luminance)} pixels"))
        written.text(out / "munsell.md", munsell_markdown(source, figures))
        written.text(out / "colour.json", json_text(figures))
    return [out / name for name in COLOUR_FILES]
