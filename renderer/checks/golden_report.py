"""The results folder of a golden-test run, for a person to review.

Every failing comparison (and, under --update-goldens, every golden whose pixels changed)
gets a folder with expected.png (the golden), actual.png (the frame), diff.png (the
amplified difference, failing pixels in magenta: renderer.checks.compare.heat_map), flip.png (the
ꟻLIP error map) and figures.json; index.html shows them side by side with their figures.
The page is rewritten after each entry, so it is there even if the run is interrupted.

The folder is the plugin's own: a marker file says so, and a run empties it before its
first entry so that nothing stale is shown. A non-empty folder without the marker is
refused rather than emptied.

Under pytest-xdist one run is several processes sharing the folder. A worker's folder
(`worker=True`) writes its entries' images and figures, each in a folder of its own claimed
with an atomic mkdir, but never empties the folder nor writes the page: the controller
empties it once before the workers start (`empty`), takes each worker's entries as plain
data (`Entry.as_dict`, `collect`) and writes the one page.
"""

from __future__ import annotations

import html
import shutil
from dataclasses import asdict, dataclass, field
from pathlib import Path

from renderer.checks.compare import channel_difference, heat_map, position_deviation_mismatch
from renderer.errors import show_number
from renderer.checks.goldens import GoldenError, Outcome
from renderer.core.imageio import write_png, write_text
from renderer.core.jsonio import write_json
from renderer.checks.perceptual import flip_error

MARKER = ".golden-results"
INDEX = "index.html"


def figures_of(outcome: Outcome, mean_flip: float) -> dict:
    """Every figure a reviewer wants, whatever the policy measured (expected and actual must
    have the same size; `mean_flip` is their mean ꟻLIP error)."""
    expected, actual = outcome.expected, outcome.actual
    threshold, deviation = outcome.policy.marking()
    difference = channel_difference(actual, expected).max(axis=-1)
    return {
        "size": [int(actual.shape[1]), int(actual.shape[0])],
        "pixels_differing": int((difference > 0).sum()),
        "pixels_failing": int(position_deviation_mismatch(actual, expected, threshold, deviation).sum()),
        "failing_rule": f"no match within ±{deviation} px at {threshold}/255",
        "max_channel_difference": int(difference.max()),
        "mean_flip": mean_flip,
        "policy": outcome.policy.describe(),
        "verdict": outcome.verdict.summary if outcome.verdict else None,
    }


@dataclass
class Entry:
    """One comparison on the page, as plain data (a worker sends it to the controller)."""
    test: str                 # the pytest node id (or whatever named the comparison)
    name: str                 # the golden's
    status: str               # the Outcome's
    folder: str               # relative to the results folder
    compared: bool            # whether there was a golden of the frame's size (and so its images)
    notes: list[str] = field(default_factory=list)
    figures: dict = field(default_factory=dict)

    def as_dict(self) -> dict:
        return asdict(self)


class ResultsFolder:
    def __init__(self, root: Path, *, worker: bool = False):
        self.root = Path(root)
        self.worker = worker      # a pytest-xdist worker's: never empties, never writes the page
        self.entries: list[Entry] = []
        self._prepared = False
        self._emptied = False

    @property
    def index(self) -> Path:
        return self.root / INDEX

    def empty(self) -> None:
        """Empty the folder of an earlier run if it is ours (once per run), keeping the marker;
        anything else is left for `prepare` to refuse when an entry is written."""
        if not self._emptied and self.root.is_dir() and (self.root / MARKER).exists():
            for child in self.root.iterdir():
                if child.name != MARKER:
                    shutil.rmtree(child) if child.is_dir() and not child.is_symlink() else child.unlink()
        self._emptied = True

    def prepare(self) -> None:
        """Make the folder ready for entries (once per run): empty it of an earlier run
        (not in a worker), or refuse a folder not ours."""
        if self._prepared:
            return
        if self.root.exists():
            if not self.root.is_dir():
                raise GoldenError("is not a folder", file=str(self.root), key="--goldens-results")
            # Non-empty first, then no marker: another process of this run writes the marker
            # before anything else, so the folder it has begun is never taken for a stranger's.
            if any(self.root.iterdir()) and not (self.root / MARKER).exists():
                raise GoldenError("exists, is not empty and was not made by the golden plugin (it has no "
                                  f"{MARKER} marker); name a new or empty folder", file=str(self.root),
                                  key="--goldens-results")
            if not self.worker:
                self.empty()
        self.root.mkdir(parents=True, exist_ok=True)
        (self.root / MARKER).write_text("made by checked-renderer's golden plugin; emptied on each run\n")
        self._prepared = True
        if not self.worker:
            self.write_index()

    def add(self, test: str, outcome: Outcome) -> Entry:
        """Write the entry's images and figures, then the page (not in a worker). Returns the entry."""
        self.prepare()
        expected, actual = outcome.expected, outcome.actual
        compared = expected is not None and expected.shape == actual.shape
        entry = Entry(test, outcome.name, outcome.status, self._new_folder(outcome.name), compared,
                      list(outcome.notes))
        path = self.root / entry.folder
        write_png(path / "actual.png", actual)
        if compared:
            threshold, deviation = outcome.policy.marking()
            write_png(path / "expected.png", expected)
            write_png(path / "diff.png", heat_map(actual, expected, threshold, deviation))
            mean_flip, flip_map = flip_error(expected, actual)
            write_png(path / "flip.png", flip_map)
            entry.figures = figures_of(outcome, mean_flip)
        entry.figures.update(test=test, golden=str(outcome.png), status=outcome.status, notes=outcome.notes)
        write_json(path / "figures.json", entry.figures, indent=2)
        if self.worker:
            self.entries.append(entry)
        else:
            self.collect(entry)
        return entry

    def collect(self, entry: Entry) -> None:
        """List an entry whose files are written (by this process or a worker) and rewrite the page."""
        self.prepare()
        self.entries.append(entry)
        self.write_index()

    def _new_folder(self, name: str) -> str:
        """NAME, or NAME-2, NAME-3, ...: the first that mkdir creates, so that two processes
        writing into the folder at once never share one."""
        folder, n = name, 1
        while True:
            try:
                (self.root / folder).mkdir()
                return folder
            except FileExistsError:
                n += 1
                folder = f"{name}-{n}"

    def write_index(self) -> None:
        failed = [e for e in self.entries if e.status in ("failed", "missing")]
        updated = [e for e in self.entries if e.status not in ("failed", "missing")]
        parts = [_HEAD, f"<h1>Golden images: {len(failed)} failing, {len(updated)} written</h1>"]
        if failed:
            parts.append("<p>Each row: the golden, the new frame, their difference (magenta: pixels "
                         "that fail) and the ꟻLIP map (brighter: more visible). If a change is "
                         "intended, accept it with <code>pytest --update-goldens</code>, review the "
                         "new PNGs and commit them.</p>")
            parts += [_entry_html(e) for e in failed]
        if updated:
            parts.append("<h2>Goldens written by --update-goldens (review before committing)</h2>")
            parts += [_entry_html(e) for e in updated]
        parts.append("</body></html>\n")
        write_text(self.index, "\n".join(parts))


_HEAD = """<!doctype html><html><head><meta charset="utf-8"><title>Golden images</title><style>
body{font-family:sans-serif;margin:1em 2em;background:#fafafa}
section{border-top:1px solid #ccc;padding:.5em 0}
figure{display:inline-block;margin:0 .5em .5em 0;text-align:center}
img{width:256px;image-rendering:pixelated;border:1px solid #999;
 background:repeating-conic-gradient(#ddd 0 25%,#fff 0 50%) 0 0/16px 16px}
td{padding:0 1em 0 0}.note{color:#a40}
</style></head><body>"""


def _entry_html(entry: Entry) -> str:
    e = html.escape
    images = "".join(
        f'<figure><a href="{e(entry.folder)}/{name}.png"><img src="{e(entry.folder)}/{name}.png" '
        f'alt="{name}"></a><figcaption>{caption}</figcaption></figure>'
        for name, caption in (("expected", "golden (expected)"), ("actual", "frame (actual)"),
                              ("diff", "difference"), ("flip", "ꟻLIP error"))
        if name == "actual" or entry.compared)
    rows = "".join(f"<tr><td>{e(key)}</td><td>{e(_show(value))}</td></tr>"
                   for key, value in entry.figures.items() if key not in ("notes", "test"))
    notes = "".join(f'<p class="note">{e(note)}</p>' for note in entry.notes)
    return (f"<section><h3>{e(entry.name)} — {e(entry.status)}</h3>"
            f"<p><code>{e(entry.test)}</code></p>{notes}<div>{images}</div><table>{rows}</table></section>")


def _show(value) -> str:
    if isinstance(value, float):
        return show_number(value) if not 0 < abs(value) < 1 else f"{value:.5f}"
    if isinstance(value, list):
        return "x".join(str(v) for v in value)
    return "" if value is None else str(value)
