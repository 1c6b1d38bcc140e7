"""What the benchmark scripts share: the command line (image size, how many frames to time,
the GL context), the machine line they print, and frames timed side by side."""

from __future__ import annotations

import argparse
import os
import platform
import statistics
import subprocess
import time

from renderer.cli.options import parse_size


def parser(doc: str, count: str, default_count: int) -> argparse.ArgumentParser:
    """--size WxH (640x480), --COUNT N (default_count) and --context egl|osmesa (egl); a
    script adds its own options before parsing."""
    parser = argparse.ArgumentParser(description=doc.splitlines()[0])
    parser.add_argument("--size", type=parse_size, default=(640, 480))
    parser.add_argument(f"--{count}", type=int, default=default_count)
    parser.add_argument("--context", choices=("egl", "osmesa"), default="egl")
    return parser


def arguments(doc: str, count: str, default_count: int) -> argparse.Namespace:
    """The common options alone, parsed (`parser`)."""
    return parser(doc, count, default_count).parse_args()


def machine() -> str:
    """The host, its CPU count and load average: absolute times depend on them."""
    load = ", ".join(f"{x:.2f}" for x in os.getloadavg())
    return f"{platform.node()}: {os.cpu_count()} CPUs, load average {load}"


def revision() -> str:
    """The repository's commit (short hash), with "+ uncommitted changes" when the work tree
    differs from it (the results files, which benchmarks write, aside): what the figures were
    measured with."""
    def git(*args) -> str:
        return subprocess.run(["git", *args], capture_output=True, text=True,
                              cwd=os.path.dirname(os.path.abspath(__file__))).stdout.strip()
    commit = git("rev-parse", "--short", "HEAD") or "unknown"
    return commit + (" + uncommitted changes" if git("status", "--porcelain", "--untracked-files=no", "--", ":(top)",
                                                    ":(exclude,top)benchmarks/results") else "")


def alternating_ms(calls, frames: int) -> list[float]:
    """The median ms of each callable, called in turn `frames` times (so all see the same load)."""
    times = [[] for _ in calls]
    for _ in range(frames):
        for call, spent in zip(calls, times):
            start = time.perf_counter()
            call()
            spent.append((time.perf_counter() - start) * 1000.0)
    return [statistics.median(spent) for spent in times]


# Results files: what a benchmark measured, with where and when, so that a page of the manual
# quotes a file rather than a figure typed by hand (issue 31). benchmarks/results/NAME.json
# holds the figures; NAME.md, made from it by the benchmark's own `markdown(results)`, is what
# the page includes; tests/test_docs_figures.py makes the .md again from the .json and holds
# the two equal.
RESULTS = os.path.join(os.path.dirname(os.path.abspath(__file__)), "results")


def write_results(name: str, figures, markdown) -> str:
    """benchmarks/results/NAME.json ({"machine", "cpus", "load", "date", "commit", "command",
    "figures"}) and NAME.md (markdown(that dict)); the .json's path."""
    import json
    import sys
    document = {"machine": platform.node(), "cpus": os.cpu_count(),
                "load": [round(x, 2) for x in os.getloadavg()],
                "date": time.strftime("%Y-%m-%d %H:%M UTC", time.gmtime()), "commit": revision(),
                "command": " ".join([".venv/bin/python", os.path.relpath(sys.argv[0]), *sys.argv[1:]]),
                "figures": figures}
    os.makedirs(RESULTS, exist_ok=True)
    path = os.path.join(RESULTS, f"{name}.json")
    with open(path, "w") as out:
        json.dump(document, out, indent=1)
        out.write("\n")
    with open(os.path.join(RESULTS, f"{name}.md"), "w") as out:
        out.write(markdown(document))
    return path


README = os.path.join(os.path.dirname(os.path.dirname(os.path.abspath(__file__))), "README.md")


def readme_block(text: str, name: str) -> tuple[int, int]:
    """(start, end) of the README's block for results file `name`: the text between the lines
    `<!-- results: NAME -->` and `<!-- /results -->` (the README is read on GitHub, which
    includes no file: the block is the results file's .md, copied in by `fill_readme_block`;
    tests/test_docs_figures.py holds the two equal)."""
    opening = f"<!-- results: {name} -->\n"
    start = text.index(opening) + len(opening)
    return start, text.index("<!-- /results -->", start)


def fill_readme_block(name: str) -> None:
    """Copy benchmarks/results/NAME.md into the README's block for it (readme_block)."""
    with open(README) as source:
        text = source.read()
    with open(os.path.join(RESULTS, f"{name}.md")) as source:
        made = source.read()
    start, end = readme_block(text, name)
    with open(README, "w") as out:
        out.write(text[:start] + made + text[end:])


def measured_line(document: dict) -> str:
    """"Measured on vm (2 CPUs, load average 1.3), 2026-12-03 18:50 UTC, at 3c62807. Reproduce:
    `...`." for a results document."""
    load = ", ".join(f"{x:.2f}" for x in document["load"])
    return (f"Measured on {document['machine']} ({document['cpus']} CPUs, load average {load}), "
            f"{document['date']}, at {document['commit']}. Reproduce: `{document['command']}`.")
