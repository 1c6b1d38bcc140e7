"""Plots whose labels stay inside their axes and apart (renderer/study/plot_labels.py): the
report's error-against-time plots (their legend beside the axes, where it covers no point)
and the chromaticity diagram (its marks named beside them). Issue 31: the ray-tracing report's
legend covered its data; the diagram's names overlapped near D65 and ran off the right edge."""

from matplotlib.backends.backend_agg import FigureCanvasAgg
from matplotlib.figure import Figure

from renderer.study.colour_plots import D65_XY, Mark, chromaticity_figure
from renderer.study.plot_labels import labels_outside_or_overlapping, place_labels
from renderer.study.report_output import plot_figure


def crowded_marks() -> list[Mark]:
    """Lights and materials crowded near D65, one light at the far right (the case that ran off
    the edge), one far below."""
    near = [Mark(f"material {i}", (D65_XY[0] + 0.004 * i, D65_XY[1] + 0.003 * (i % 3)), "material",
                 (0.8, 0.8, 0.8)) for i in range(6)]
    return near + [Mark("directional 0", (0.513, 0.347), "light", (0.8, 0.1, 0.1)),
                   Mark("directional 1", (0.199, 0.165), "light", (0.1, 0.2, 0.9)),
                   Mark("ambient", D65_XY, "light", (0.5, 0.5, 0.5))]


def test_the_chromaticity_diagram_names_crowded_marks_inside_and_apart():
    import numpy as np
    pixels = np.random.default_rng(1).normal(D65_XY, 0.03, (2000, 2))
    figure = chromaticity_figure(pixels, crowded_marks(), "crowded")
    assert labels_outside_or_overlapping(figure) == []
    names = {text.get_text() for axes in figure.axes for text in axes.texts}
    assert {"directional 0", "directional 1"} <= names


def report_rows() -> list[dict]:
    rows = []
    for pattern, scale in (("regular", 1.0), ("random", 1.4), ("jittered", 1.1), ("poisson", 1.2)):
        for backend, slower in (("gpu", 1.0), ("reference", 30.0)):
            for samples in (1, 4, 16):
                rows.append({"knob": "antialiasing", "pattern": pattern, "backend": backend,
                             "setting": f"{pattern} {samples}", "samples": samples,
                             "median_ms": 0.4 * samples * slower, "rmse": 0.05 * scale / samples ** 0.5})
    return rows


def test_the_report_plot_keeps_its_legend_off_the_points_and_its_names_inside():
    figure = plot_figure(report_rows(), "classic: antialiasing")
    assert labels_outside_or_overlapping(figure) == []
    axes = figure.axes[0]
    figure.canvas.draw()
    legend = axes.get_legend().get_window_extent()
    assert legend.x0 >= axes.get_window_extent().x1                # beside the axes, not on them
    assert axes.texts                                              # the front's points are named


def test_the_check_sees_a_label_off_the_edge_and_two_on_one_another():
    figure = Figure(figsize=(3, 2))
    FigureCanvasAgg(figure)
    axes = figure.add_subplot()
    axes.set_xlim(0, 1)
    axes.set_ylim(0, 1)
    axes.annotate("off the edge", (0.98, 0.5), xytext=(6, 0), textcoords="offset points")
    axes.annotate("first", (0.3, 0.3))
    axes.annotate("second", (0.3, 0.3))
    assert labels_outside_or_overlapping(figure) == ["'off the edge' leaves its axes",
                                                     "'second' covers 'first'"]
    for text in list(axes.texts):
        text.remove()
    place_labels(axes, [("off the edge", (0.98, 0.5)), ("first", (0.3, 0.3)), ("second", (0.3, 0.3))])
    assert labels_outside_or_overlapping(figure) == []
