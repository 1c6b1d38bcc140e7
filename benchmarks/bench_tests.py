"""The default test run's duration: `python -m pytest` in one process and spread over
--workers pytest-xdist workers (as CI spreads the full run: `--dist loadgroup`), the runs
taking turns so that both see the same load.

    .venv/bin/python benchmarks/bench_tests.py [--repeats 1] [--workers 2] [PYTEST ARGUMENT ...]

Arguments after the options are added to pytest's (a test file, `-k EXPR`): without any, the
whole default run, which leaves out the tests marked slow and window (tests/conftest.py).
The full run (`--all`) is not timed here: it takes many minutes (CI's aim is ten).

Each run is a new process from the repository root, its golden results in a temporary
folder; printed and written per run: wall seconds, the CPU seconds of pytest and every process
it waited for (its xdist workers included), and pytest's own counts. It writes
benchmarks/results/tests.json (the figures, with machine, date, load and commit) and tests.md
(the table made from it: `markdown`), which docs/tests.md includes. Not a test: this machine
is shared and its load varies; the load average is in the results.
"""

from __future__ import annotations

import argparse
import re
import resource
import statistics
import subprocess
import sys
import tempfile
import time
from pathlib import Path

from common import machine, measured_line, write_results

ROOT = Path(__file__).resolve().parents[1]
COUNTED = ("passed", "failed", "skipped", "deselected", "xfailed", "xpassed", "error", "errors")


def pytest_run(arguments: list[str], junit: Path | None = None) -> dict:
    """`python -m pytest -q ARGUMENTS` from the repository root, its golden results in a
    temporary folder: {"seconds", "cpu_seconds", "counts", "goldens"} (counts: pytest's last
    line, {"passed": n, ...}; goldens: the golden plugin's summary line, or None). A run that
    fails raises, with the end of its output."""
    with tempfile.TemporaryDirectory(prefix="bench-tests-") as folder:
        command = [sys.executable, "-m", "pytest", "-q", "-p", "no:cacheprovider",
                   "--goldens-results", str(Path(folder) / "golden-results"), *arguments]
        if junit is not None:
            command += [f"--junitxml={junit}"]
        before = resource.getrusage(resource.RUSAGE_CHILDREN)
        start = time.perf_counter()
        result = subprocess.run(command, cwd=ROOT, capture_output=True, text=True)
        seconds = time.perf_counter() - start
        after = resource.getrusage(resource.RUSAGE_CHILDREN)
    output = result.stdout + result.stderr
    if result.returncode != 0:
        raise SystemExit(f"{' '.join(command)}: exit status {result.returncode}\n{output[-3000:]}")
    last = [line for line in output.splitlines() if re.search(r"\d+ passed", line)][-1]
    counts = {word: int(n) for n, word in re.findall(rf"(\d+) ({'|'.join(COUNTED)})\b", last)}
    goldens = re.search(r"^goldens: (.*)$", output, re.M)
    return {"seconds": round(seconds, 1),
            "cpu_seconds": round(after.ru_utime + after.ru_stime - before.ru_utime - before.ru_stime, 1),
            "counts": counts, "goldens": goldens.group(1).strip() if goldens else None}


def counts_text(counts: dict) -> str:
    return ", ".join(f"{n} {word}" for word, n in counts.items())


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--repeats", type=int, default=1, help="runs of each kind, in turn")
    parser.add_argument("--workers", type=int, default=2, help="pytest-xdist workers (-n)")
    args, extra = parser.parse_known_args()
    kinds = {"one process": [], f"-n {args.workers} --dist loadgroup":
             ["-n", str(args.workers), "--dist", "loadgroup"]}
    print(f"before: {machine()}")
    runs = []
    for repeat in range(args.repeats):
        for kind, options in kinds.items():
            run = {"run": kind} | pytest_run([*extra, *options])
            print(f"{kind:24s} {run['seconds']:7.1f} s  CPU {run['cpu_seconds']:7.1f} s  "
                  f"{counts_text(run['counts'])}", flush=True)
            runs.append(run)
    print(f"after: {machine()}")
    figures = {"pytest": " ".join(["python -m pytest", *extra]), "runs": runs}
    print(f"wrote {write_results('tests', figures, markdown)}")


def markdown(document: dict) -> str:
    """The table of docs/tests.md, made from a results document."""
    f = document["figures"]
    lines = [f"`{f['pytest']}`, in one process and on pytest-xdist's workers, the runs taking turns:",
             "", "| run | wall s | CPU s | tests |", "| --- | ---: | ---: | --- |"]
    for run in f["runs"]:
        lines.append(f"| {run['run']} | {run['seconds']:.1f} | {run['cpu_seconds']:.1f} | "
                     f"{counts_text(run['counts'])} |")
    kinds = list(dict.fromkeys(run["run"] for run in f["runs"]))
    median = {kind: statistics.median(r["seconds"] for r in f["runs"] if r["run"] == kind)
              for kind in kinds}
    if len(kinds) == 2:
        lines += ["", f"Wall time in one process over that with `{kinds[1]}` (medians): "
                      f"{median[kinds[0]] / median[kinds[1]]:.2f}."]
    return "\n".join(lines + ["", measured_line(document), ""])


if __name__ == "__main__":
    main()
