"""pytest plugin for golden-image tests, registered through the `pytest11` entry point.

    def test_my_scene(golden):
        golden.check_scene("my_scene.toml")      # GPU, 256x256, against goldens/test_my_scene.png
        golden.check_scene("classic", "classic-rt", method="raytrace", samples=4)   # ray traced

    pytest                       # compare; failures go to golden-results/index.html
    pytest --update-goldens      # create missing goldens, rewrite those that fail (the only writer)
    pytest --update-goldens=all  # ... and rewrite every golden whose pixels differ at all

Goldens live in a `goldens/` folder beside the test file, as NAME.png with a NAME.json
sidecar (renderer/checks/goldens.py); NAME defaults to the test's name. Policies: renderer/checks/policies.py;
the default is "threshold", or the ini option `goldens_policy`. docs/goldens.md has the rest.

The plugin is inert until a test asks for the `golden` fixture: it imports no GL at start-up
and touches no folder (under pytest-xdist the controller empties a results folder of ours
when the run starts; see the next paragraph).

Under pytest-xdist (`-n`) each worker checks its tests' goldens and writes their images, but
never empties the results folder nor writes its page: it attaches what it found to each test
report (`report.goldens`, a list of plain dicts; pytest carries a report's extra attributes
to the controller), and the controller, which emptied the folder before starting the workers,
counts them, writes index.html and prints the summary, as one process would.
--update-goldens runs in one process (it turns -n off): a golden written by one test is read
by later ones (two tests of one golden name; tests/test_goldens.py's reference checks).
"""

from __future__ import annotations

import re
import warnings
from collections import Counter
from pathlib import Path

import pytest

RESULTS_DEFAULT = "golden-results"



class GoldenWarning(UserWarning):
    """A golden passed, but was made on another GL implementation than the frame."""


def pytest_addoption(parser):
    group = parser.getgroup("goldens", "golden images (checked-renderer)")
    # Two option strings rather than an optional value: `--update-goldens tests/` must not
    # take the path as its value. argparse matches "--update-goldens=all" whole first.
    group.addoption("--update-goldens", action="store_const", const="failing", default=None,
                    dest="update_goldens",
                    help="write missing goldens and rewrite those the frame fails under their "
                         "policy (the only way a golden is ever written); goldens that pass "
                         "keep their pixels")
    group.addoption("--update-goldens=all", action="store_const", const="all",
                    dest="update_goldens",
                    help="as --update-goldens, and also rewrite every golden whose pixels "
                         "differ from the frame at all (after a deliberate change, or to make "
                         "goldens exact on this machine)")
    group.addoption("--goldens-results", metavar="DIR", default=None,
                    help=f"folder for the images and index.html of failing comparisons "
                         f"(default: {RESULTS_DEFAULT} in the rootdir)")
    parser.addini("goldens_policy", default=None,
                  help="tolerance policy of golden checks that name none: exact, threshold (the "
                       "default) or flip")


class GoldenSession:
    """What one pytest run knows about its golden checks."""

    def __init__(self, config):
        self.update = config.getoption("update_goldens") or False   # False, "failing" or "all"
        option = config.getoption("--goldens-results")
        self.results_root = Path(option).resolve() if option else config.rootpath / RESULTS_DEFAULT
        self.default_policy = config.getini("goldens_policy") or None
        self.counts: Counter = Counter()
        self.claimed: dict[Path, str] = {}       # golden PNG -> the first test that checked it under
                                                 # --update-goldens in this run (written or not)
        self.changed: list[Path] = []            # goldens created or updated in this run
        self.worker = hasattr(config, "workerinput")                 # a pytest-xdist worker
        self.notice = None                       # a line for the report header
        self._results = None

    @property
    def results(self):
        if self._results is None:
            from renderer.checks.golden_report import ResultsFolder
            self._results = ResultsFolder(self.results_root, worker=self.worker)
        return self._results

    def record(self, status: str, png: Path) -> None:
        """Count one check and note a golden written (in the process that made the check, or
        in the controller from a worker's report)."""
        self.counts[status] += 1
        if status in ("created", "updated"):
            self.changed.append(png)

    def take_report(self, records: list[dict]) -> None:
        """The controller: the checks a worker made for one test report."""
        from renderer.checks.golden_report import Entry
        from renderer.errors import UserError

        for record in records:
            self.record(record["status"], Path(record["png"]))
            if record["entry"] is not None:
                try:
                    self.results.collect(Entry(**record["entry"]))
                except UserError:       # a folder not ours: the worker's test already failed saying so
                    pass


_SESSION = pytest.StashKey[GoldenSession]()
_PENDING = pytest.StashKey[list]()       # a worker's checks not yet attached to a report


def pytest_configure(config):
    session = config.stash[_SESSION] = GoldenSession(config)
    # Before pytest-xdist's own pytest_configure (trylast), which starts the distributed
    # session only while "dist" is on.
    if session.update and not session.worker and config.getoption("dist", "no") != "no":
        config.option.dist, config.option.tx, config.option.numprocesses = "no", [], 0
        session.notice = ("goldens: --update-goldens runs the tests in one process (pytest-xdist's "
                          "-n is off): a golden written by one test is read by later ones")


def pytest_report_header(config):
    session = config.stash.get(_SESSION, None)
    return session.notice if session is not None else None


@pytest.hookimpl(tryfirst=True)
def pytest_sessionstart(session):
    """pytest-xdist's controller empties the results folder before its workers start (its own
    pytest_sessionstart, trylast, starts them) and listens to their reports; workers and a
    plain run empty it lazily, at their first check."""
    config = session.config
    if config.pluginmanager.has_plugin("dsession"):
        golden_session = config.stash[_SESSION]
        golden_session.results.empty()
        config.pluginmanager.register(_Controller(golden_session), "golden-controller")


class _Controller:
    """pytest-xdist's controller: takes the golden checks its workers attach to their reports."""

    def __init__(self, session: GoldenSession):
        self.session = session

    def pytest_runtest_logreport(self, report):
        records = getattr(report, "goldens", None)
        if records:
            self.session.take_report(records)


@pytest.hookimpl(hookwrapper=True)
def pytest_runtest_makereport(item, call):
    """A worker: attach the checks made in this phase of the test to its report."""
    outcome = yield
    pending = item.stash.get(_PENDING, None)
    if pending:
        outcome.get_result().goldens = pending[:]
        pending.clear()


@pytest.fixture
def golden(request) -> "GoldenChecker":
    """Hold rendered frames against golden PNGs: golden.check(frame) or golden.check_scene(scene)."""
    return GoldenChecker(request, request.config.stash[_SESSION])


def default_name(test_name: str) -> str:
    """A golden name from a test's name: test_x[a-b] -> test_x-a-b."""
    name = test_name.replace("[", "-").replace("]", "")
    return re.sub(r"[^A-Za-z0-9._-]", "_", name)[:150]


def _fail_plainly(error) -> None:
    """Fail the test with a UserError's one line. Raised `from None`: called in an `except`
    block, pytest.fail would show the UserError again as the exception it happened during."""
    raise pytest.fail.Exception(error.line(), pytrace=False) from None


def _shown(path: Path) -> str:
    try:
        return str(path.relative_to(Path.cwd()))
    except ValueError:
        return str(path)


class GoldenChecker:
    """The `golden` fixture: one per test."""

    def __init__(self, request, session: GoldenSession):
        self._request = request
        self._session = session
        self.directory = Path(request.path).parent / "goldens"
        self._names: set[str] = set()

    def check(self, frame, name: str | None = None, *, policy=None, scene: str | None = None,
              gl_info: dict | None = None):
        """Hold `frame` (a Frame, or an (H, W, 4) uint8 array) against golden `name`.

        `policy`: "exact", "threshold", "flip", a dict or a renderer.checks.policies instance.
        `scene` is recorded in the sidecar; `gl_info` defaults to the frame's own.
        Fails the test with the figures and the results page's path; returns the Outcome.
        """
        from renderer.errors import UserError
        from renderer.checks.goldens import check_golden, golden_paths

        session, nodeid = self._session, self._request.node.nodeid
        name = name or default_name(self._request.node.name)
        if name in self._names:
            pytest.fail(f"this test already checked a golden named {name!r}; give each check its "
                        "own name=", pytrace=False)
        self._names.add(name)
        try:
            session.results.prepare()      # first check of the run: clear the last run's results
        except UserError as error:
            _fail_plainly(error)
        rgba8 = getattr(frame, "rgba8", frame)
        gl_info = gl_info or getattr(frame, "gl_info", None)
        try:
            png = golden_paths(self.directory, name)[0]
            # A golden an earlier test of this run updated (two tests sharing a name) is
            # compared, not written again: if they disagree, that is the failure to see.
            update = session.update if png not in session.claimed else False
            outcome = check_golden(self.directory, name, rgba8, policy=policy or session.default_policy,
                                   scene=scene, gl_info=gl_info, update=update)
        except UserError as error:
            _fail_plainly(error)
        session.record(outcome.status, png)
        if update:               # "unchanged" and "passed" too: a later test of the same name must not rewrite it
            session.claimed[png] = nodeid
        entry = trouble = None
        if outcome.status in ("created", "updated"):
            entry = session.results.add(nodeid, outcome)   # for review before committing
        elif outcome.status in ("failed", "missing"):
            try:
                entry = session.results.add(nodeid, outcome)
            except Exception as error:         # the report must not hide the failure itself
                trouble = error
        if session.worker:                     # for the controller (pytest_runtest_makereport)
            self._request.node.stash.setdefault(_PENDING, []).append(
                {"status": outcome.status, "png": str(png), "entry": entry and entry.as_dict()})
        if outcome.status == "passed":
            for note in outcome.notes:
                warnings.warn(GoldenWarning(f"golden {name!r}: {note}"), stacklevel=2)
        elif outcome.status in ("failed", "missing"):
            self._fail(outcome, entry, trouble)
        return outcome

    def _fail(self, outcome, entry, trouble):
        session = self._session
        if entry is None:
            report = f"(the results folder could not be written: {trouble})"
        else:
            report = (f"images: {_shown(session.results.root / entry.folder)}/; "
                      f"all failures: {_shown(session.results.index)}")
        if outcome.status == "missing":
            lines = [f"golden {outcome.name!r} does not exist ({_shown(outcome.png)}); run pytest "
                     "--update-goldens to make it from this frame, look at it, and commit the .png "
                     "and .json"]
        else:
            lines = [f"golden {outcome.name!r} ({_shown(outcome.png)}) does not match under "
                     f"{outcome.policy.describe()}: {outcome.verdict.summary}"]
            if entry is not None and entry.figures:
                f = entry.figures
                lines.append(f"{f['pixels_differing']} pixels differ at all, {f['pixels_failing']} "
                             f"fail ({f['failing_rule']}), largest channel difference "
                             f"{f['max_channel_difference']}/255, mean ꟻLIP {f['mean_flip']:.5f}")
        lines += outcome.notes
        lines.append(report)
        if outcome.status == "failed":
            lines.append("if the change is intended: pytest --update-goldens, then review and commit")
        pytest.fail("\n".join(lines), pytrace=False)

    def check_scene(self, scene, name: str | None = None, *, size=(256, 256), context="auto",
                    shading: str | None = None, policy=None, method: str = "raster", **trace):
        """Render `scene` on the GPU and check it; returns the Frame.

        `scene`: a renderer.core.scene.Scene, a built-in scene's name, or a scene file (relative
        paths are taken from the test file's folder). `context`: "auto", "egl", "osmesa" or
        a moderngl context to reuse. `shading`: render every material flat, gouraud or phong.
        `method`: "raster" or "raytrace" (renderer/methods, open_renderer); `trace`: the
        method's options by field (RayOptions': samples, pattern, max_depth, seed, shadows...).
        """
        from renderer.errors import UserError
        from renderer.core.scene import Scene

        from renderer.errors import OptionError
        from renderer.methods import method_options, open_renderer
        try:
            options, refused = method_options(method, trace), None
        except OptionError as error:
            options, refused = None, f"{error.fields[0]}: {error.reason}"
        if refused is not None:                   # outside the except: one line, no chained cause
            pytest.fail(refused, pytrace=False)
        try:
            if not isinstance(scene, Scene):
                scene = self._load(scene)
            if shading is not None:
                scene = scene.with_shading(shading)
            where = {"context_kind": context} if isinstance(context, str) else {"context": context}
            with open_renderer(scene, size, method=method, options=options, **where) as renderer:
                frame = renderer.render(depth=False)
        except UserError as error:
            _fail_plainly(error)
        self.check(frame, name, policy=policy, scene=scene.name)
        return frame

    def _load(self, scene):
        from renderer.core.builtin import builtin_scenes, resolve_scene
        from renderer.core.scene_file import load_scene

        scene = str(scene)
        local = Path(self._request.path).parent / scene
        if scene not in builtin_scenes() and local.is_file():
            return load_scene(local)
        return load_scene(resolve_scene(scene))


def pytest_terminal_summary(terminalreporter, exitstatus, config):
    session = config.stash.get(_SESSION, None)
    if session is None or not session.counts:
        return
    counts = ", ".join(f"{n} {status}" for status, n in sorted(session.counts.items()))
    terminalreporter.write_sep("-", "golden images")
    terminalreporter.write_line(f"goldens: {counts}")
    for png in session.changed:
        terminalreporter.write_line(f"written: {_shown(png)}")
    if session._results is not None and session._results.entries:
        terminalreporter.write_line(f"results: {_shown(session._results.index)}")
