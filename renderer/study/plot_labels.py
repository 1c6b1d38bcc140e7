"""Labels on a plot that neither leave their axes nor cover each other, and the check that a
figure keeps to that (tests/test_plot_labels.py): the report's points and the chromaticity
diagram's marks are named beside them, and a label cut off at the edge or printed over
another is no label (issue 31).

    place_labels(axes, [(text, (x, y)), ...], fontsize=7)
    labels_outside_or_overlapping(figure)   # [] for a figure that keeps to it
"""

from __future__ import annotations

# Where a label may sit beside its point, in points, in order of preference: right and up,
# then the other corners and sides, then further out.
OFFSETS = [(5, 3, "left", "bottom"), (5, -3, "left", "top"), (-5, 3, "right", "bottom"),
           (-5, -3, "right", "top"), (0, 7, "center", "bottom"), (0, -7, "center", "top"),
           (12, 10, "left", "bottom"), (-12, 10, "right", "bottom"), (12, -10, "left", "top"),
           (-12, -10, "right", "top"), (0, 16, "center", "bottom"), (0, -16, "center", "top")]


def _inside(box, outer) -> bool:
    return (box.x0 >= outer.x0 - 0.5 and box.x1 <= outer.x1 + 0.5
            and box.y0 >= outer.y0 - 0.5 and box.y1 <= outer.y1 + 0.5)


# Behind each label, so that it reads over a histogram's dark bins or a line.
BACKING = {"boxstyle": "round,pad=0.15", "facecolor": "white", "alpha": 0.75, "linewidth": 0}


def place_labels(axes, labels, *, fontsize: float = 7, color=None) -> list:
    """Annotate each (text, (x, y)) of `labels` at the first of OFFSETS where it lies inside
    `axes` and over no label placed before; where none does, at the first inside the axes,
    else the first. Call after the axes' limits and scales are set. The annotations."""
    renderer = axes.figure.canvas.get_renderer()
    frame = axes.get_window_extent(renderer)
    placed, made = [], []

    def annotated(text, xy, offset):
        dx, dy, ha, va = offset
        note = axes.annotate(text, xy, xytext=(dx, dy), textcoords="offset points",
                             fontsize=fontsize, ha=ha, va=va, color=color, bbox=BACKING)
        return note, note.get_window_extent(renderer)

    for text, xy in labels:
        fallback = None
        for offset in OFFSETS:
            note, box = annotated(text, xy, offset)
            if _inside(box, frame) and not any(box.overlaps(other) for other in placed):
                break
            if fallback is None and _inside(box, frame):
                fallback = offset
            note.remove()
        else:
            note, box = annotated(text, xy, fallback or OFFSETS[0])
        placed.append(box)
        made.append(note)
    return made


def labels_outside_or_overlapping(figure) -> list[str]:
    """What breaks the rule in `figure` (drawn): each annotation outside its axes, each two
    annotations of one axes that overlap, each legend outside the figure."""
    figure.canvas.draw()
    renderer = figure.canvas.get_renderer()
    problems = []
    whole = figure.bbox
    for axes in figure.axes:
        frame = axes.get_window_extent(renderer)
        boxes = []
        for note in axes.texts:
            box = note.get_window_extent(renderer)
            if not _inside(box, frame):
                problems.append(f"{note.get_text()!r} leaves its axes")
            for other_text, other in boxes:
                if box.overlaps(other):
                    problems.append(f"{note.get_text()!r} covers {other_text!r}")
            boxes.append((note.get_text(), box))
        legend = axes.get_legend()
        if legend is not None and not _inside(legend.get_window_extent(renderer), whole):
            problems.append("a legend leaves the figure")
    return problems
