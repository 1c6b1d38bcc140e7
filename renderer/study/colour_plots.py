"""The figures of `renderer colour`: the CIE 1931 chromaticity diagram of an image's pixels
(with a scene's materials and lights marked) and the histogram of their luminance.

The spectral locus is the chromaticity of each wavelength's colour-matching functions,
colour-science's CIE 1931 2-degree observer (`colour.MSDS_CMFS`, 360 to 830 nm in 1 nm steps),
closed by the line of purples; nothing is copied by hand. The pixels are a 2D histogram
(counts on a log scale), so that a million pixels draw as fast as a hundred and none hides
another.
"""

from __future__ import annotations

import io
from typing import NamedTuple

import colour
import numpy as np

from renderer.core.colour import D65_XY, SRGB_PRIMARIES_XY
from renderer.study.munsell import OBSERVER

LOCUS_LABELS_NM = (460, 480, 490, 500, 510, 520, 540, 560, 580, 600, 620, 700)
HISTOGRAM_BINS = 160                     # per axis of each panel of the diagram
DIAGRAM_RANGE = ((0.0, 0.8), (0.0, 0.9))
LUMINANCE_BINS = 64


class Mark(NamedTuple):
    """A colour marked on the diagram: its label, chromaticity x, y, kind ("material" or
    "light") and a display colour for the marker (sRGB-encoded RGB in [0, 1])."""
    label: str
    xy: tuple
    kind: str
    display: tuple


def spectral_locus() -> tuple[np.ndarray, np.ndarray]:
    """(wavelengths (N,) nm, their chromaticities (N, 2)) of the CIE 1931 2-degree observer."""
    cmfs = colour.MSDS_CMFS[OBSERVER]
    return np.asarray(cmfs.wavelengths), colour.XYZ_to_xy(cmfs.values)


def _figure(size):
    from matplotlib.backends.backend_agg import FigureCanvasAgg
    from matplotlib.figure import Figure
    figure = Figure(figsize=size, dpi=100)
    FigureCanvasAgg(figure)
    return figure


def _png(figure) -> bytes:
    buffer = io.BytesIO()
    figure.savefig(buffer, format="png", metadata={"Software": None})
    return buffer.getvalue()


def zoom_range(xy: np.ndarray, marks: list[Mark], margin: float = 0.02,
               least: float = 0.06) -> tuple:
    """((x0, x1), (y0, y1)): a square around the pixels (their 0.5 to 99.5 percentiles), the
    marks and D65, with a margin, at least `least` wide, moved inside the diagram."""
    points = [np.array([D65_XY])] + ([np.percentile(xy, (0.5, 99.5), axis=0)] if len(xy) else [])
    points += [np.array([m.xy for m in marks])] if marks else []
    points = np.vstack(points)
    low, high = points.min(axis=0), points.max(axis=0)
    half = max(float(np.max(high - low)) / 2 + margin, least / 2)
    ranges = []
    for axis, (start, end) in enumerate(DIAGRAM_RANGE):
        centre = float(np.clip((low[axis] + high[axis]) / 2, start + half, end - half))
        ranges.append((max(start, centre - half), min(end, centre + half)))
    return tuple(ranges)


def _labels(marks: list[Mark]) -> list[tuple[str, tuple]]:
    """(label, xy) per place: marks at the same chromaticity (to 3 decimals) share one label."""
    places: dict = {}
    for mark in marks:
        places.setdefault(tuple(np.round(mark.xy, 3)), []).append(mark)
    return [(", ".join(m.label for m in group), group[0].xy) for group in places.values()]


def _draw(axes, xy: np.ndarray, marks: list[Mark], extent, labelled: bool):
    """One panel: locus, sRGB triangle, the pixels' histogram over `extent`, D65, the marks,
    the wavelengths along the locus unless `labelled` (the zoomed panel names its marks
    instead: _name_marks). The histogram's artist (None without pixels)."""
    from matplotlib.colors import LogNorm
    wavelengths, locus = spectral_locus()
    closed = np.vstack([locus, locus[:1]])
    axes.plot(closed[:, 0], closed[:, 1], color="black", linewidth=1,
              label="spectral locus (CIE 1931 2\N{DEGREE SIGN})")
    triangle = np.array(SRGB_PRIMARIES_XY + SRGB_PRIMARIES_XY[:1])
    axes.plot(triangle[:, 0], triangle[:, 1], color="0.3", linestyle="--", linewidth=1,
              label="sRGB gamut")
    counts = None
    if len(xy):
        counts = axes.hist2d(xy[:, 0], xy[:, 1], bins=HISTOGRAM_BINS, range=extent,
                             norm=LogNorm(), cmap="viridis", cmin=1)[3]
    axes.plot(*D65_XY, marker="+", color="black", markersize=10, linestyle="none", label="D65")
    for kind, marker in (("material", "o"), ("light", "*")):
        chosen = [m for m in marks if m.kind == kind]
        for mark in chosen:
            axes.plot(*mark.xy, marker=marker, markersize=11 if kind == "light" else 7,
                      markerfacecolor=mark.display, markeredgecolor="black", linestyle="none")
        if chosen:
            axes.plot([], [], marker=marker, color="white", markeredgecolor="black",
                      linestyle="none", label=f"{kind}s")
    axes.set_xlim(*extent[0])
    axes.set_ylim(*extent[1])
    axes.set_aspect("equal")
    axes.set_xlabel("x")
    axes.set_ylabel("y")
    axes.grid(True, linewidth=0.3)
    if not labelled:                         # inside the panel: 500 and 510 lie near x = 0
        from renderer.study.plot_labels import place_labels
        axes.figure.canvas.draw()
        place_labels(axes, [(f"{nm}", tuple(locus[np.searchsorted(wavelengths, nm)]))
                            for nm in LOCUS_LABELS_NM], fontsize=6)
    return counts


def _name_marks(axes, marks: list[Mark]) -> None:
    """The marks' names beside them, inside the panel and apart (plot_labels): near D65 the
    lights and materials crowd, and a name at a fixed offset ran off the panel's edge."""
    from renderer.study.plot_labels import place_labels
    axes.figure.canvas.draw()                # the panel's final place (aspect, colour bar)
    place_labels(axes, _labels(marks), fontsize=7)


def chromaticity_png(xy: np.ndarray, marks: list[Mark], title: str) -> bytes:
    """PNG bytes of chromaticity_figure."""
    return _png(chromaticity_figure(xy, marks, title))


def chromaticity_figure(xy: np.ndarray, marks: list[Mark], title: str):
    """On the left the whole diagram (the locus, the sRGB triangle, D65, a 2D histogram of the
    pixels' xy (N, 2), the marks), on the right the same zoomed in on the pixels and marks
    (zoom_range), the marks named."""
    figure = _figure((12.0, 5.8))
    whole, zoomed = figure.subplots(1, 2, gridspec_kw={"left": 0.05, "right": 0.97, "top": 0.9,
                                                        "bottom": 0.09, "wspace": 0.12})
    _draw(whole, xy, marks, DIAGRAM_RANGE, labelled=False)
    whole.legend(fontsize=7, loc="upper right")
    whole.set_title("the whole diagram", fontsize=9)
    counts = _draw(zoomed, xy, marks, zoom_range(xy, marks), labelled=True)
    zoomed.set_title("zoomed in on the pixels and marks", fontsize=9)
    if counts is not None:
        figure.colorbar(counts, ax=zoomed, shrink=0.8, label="pixels per bin")
    figure.suptitle(title, fontsize=10)
    _name_marks(zoomed, marks)
    return figure


def luminance_png(luminance: np.ndarray, title: str) -> bytes:
    """PNG bytes: the histogram of the pixels' Y (linear, 0 .. max(1, the largest)), pixel
    counts on a log scale, with the mean marked."""
    figure = _figure((6.4, 4.0))
    axes = figure.add_subplot()
    top = max(1.0, float(luminance.max())) if len(luminance) else 1.0
    axes.hist(luminance, bins=LUMINANCE_BINS, range=(0.0, top), color="0.4",
              log=bool(len(luminance)))           # no pixels: nothing to put on a log scale
    if len(luminance):
        mean = float(luminance.mean())
        axes.axvline(mean, color="C3", linewidth=1, label=f"mean Y = {mean:.4f}")
        axes.legend(fontsize=7)
    axes.set_xlabel("luminance Y (linear; 1 = white)")
    axes.set_ylabel("pixels")
    axes.set_title(title, fontsize=9)
    axes.grid(True, linewidth=0.3)
    return _png(figure)
