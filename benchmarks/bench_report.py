"""How long `renderer report` takes, and what its default run finds (issue 31).

    .venv/bin/python benchmarks/bench_report.py [--skip-default]

Runs, one after another, each in a new process with an empty ground-truth cache (every truth
made again) and its output in a temporary folder:
  renderer report --quick                    CI's sweep: two small scenes at 64x48
  renderer report --method raytrace --quick  the ray tracer's: classic at 64x48
  renderer report                            the default: every built-in raster scene at 160x120
and prints each one's wall time (start-up and writing included) and rows. From the default
run's results.csv it takes the fitted convergence of RMSE over samples per pixel (by pattern
and backend) and, for each RMSE target, the cheapest setting per scene. Writes
benchmarks/results/report.json and .md (docs/error-against-run-time.md includes the .md).
--skip-default: the two quick runs alone (a minute or two; the figures file is not written).
"""

from __future__ import annotations

import argparse
import csv
import os
import subprocess
import sys
import tempfile
import time
from collections import Counter
from pathlib import Path

from common import machine, measured_line, write_results

ROOT = Path(__file__).resolve().parents[1]
RENDERER = [sys.executable, "-m", "renderer"]
RUNS = (("quick", ["report", "--quick"]),
        ("ray tracer, quick", ["report", "--method", "raytrace", "--quick"]),
        ("default", ["report"]))


def timed_run(args: list[str], folder: Path) -> dict:
    """One report in a new process: its wall time, exit status and rows."""
    out, cache = folder / "out", folder / "cache"
    start = time.perf_counter()
    done = subprocess.run([*RENDERER, *args, "--out", str(out), "--cache", str(cache)],
                          cwd=folder, stdout=subprocess.PIPE, stderr=subprocess.DEVNULL, text=True)
    seconds = time.perf_counter() - start
    rows = read_rows(out / "results.csv") if done.returncode == 0 else []
    return {"seconds": round(seconds, 1), "status": done.returncode, "rows": len(rows),
            "scenes": len({row["scene"] for row in rows}), "said": done.stdout.strip(),
            "results": rows}


def read_rows(path: Path) -> list[dict]:
    """results.csv's rows, numbers as floats and empty cells as None."""
    def value(text: str):
        if text == "":
            return None
        try:
            return float(text)
        except ValueError:
            return text
    with open(path, newline="") as file:
        return [{key: value(text) for key, text in row.items()} for row in csv.DictReader(file)]


def findings(rows: list[dict]) -> dict:
    """The default run's convergence slopes and cheapest settings (report_output's own)."""
    from renderer.study.report_output import cheapest, convergence_slopes
    from renderer.study.report_settings import TARGETS_RMSE
    slopes = [{"pattern": name, "backend": backend, "slope": round(fit.slope, 2),
               "points": fit.points, "samples": [int(fit.samples[0]), int(fit.samples[1])]}
              for (name, backend), fit in convergence_slopes(rows).items()]
    scenes = sorted({row["scene"] for row in rows})
    targets = []
    for target in TARGETS_RMSE:
        for backend in ("gpu", "reference"):
            best = [cheapest(rows, scene, backend, target) for scene in scenes]
            reached = [row for row in best if row is not None]
            knobs = Counter(row["knob"] for row in reached)
            antialiased = [cheapest([r for r in rows if r["knob"] == "antialiasing"], scene,
                                    backend, target) for scene in scenes]
            settings = Counter(row["setting"] for row in antialiased if row is not None)
            targets.append({"rmse": target, "backend": backend, "scenes": len(scenes),
                            "reached": len(reached),
                            "ms": [round(min(r["median_ms"] for r in reached), 2),
                                   round(max(r["median_ms"] for r in reached), 2)] if reached else None,
                            "knobs": dict(knobs.most_common()),
                            "antialiasing": dict(settings.most_common(3))})
    return {"slopes": slopes, "targets": targets}


def _ms(value: float) -> str:
    return f"{value:.3g}" if value < 1000 else f"{value:,.0f}"


def markdown(document: dict) -> str:
    """docs/error-against-run-time.md's figures, from a results document (write_results)."""
    figures = document["figures"]
    lines = ["| command | scenes | rows | wall time |", "| --- | ---: | ---: | ---: |"]
    for run in figures["runs"]:
        lines.append(f"| `renderer {' '.join(run['args'])}` | {run['scenes']} | {run['rows']:,} | "
                     f"{run['seconds'] / 60:.1f} min ({run['seconds']:.0f} s) |")
    lines += ["", "Convergence of RMSE with N samples per pixel in the default run (the slope "
              "of log RMSE against log N, fitted over all scenes):", "",
              "| pattern | backend | slope | points | N |", "| --- | --- | ---: | ---: | --- |"]
    for slope in figures["slopes"]:
        lines.append(f"| {slope['pattern']} | {slope['backend']} | N^{slope['slope']:.2f} | "
                     f"{slope['points']} | {slope['samples'][0]}–{slope['samples'][1]} |")
    lines += ["", "The cheapest setting per scene reaching each RMSE target (report.md's "
              "tables, counted): over every knob, which knob it was; among the anti-aliasing "
              "settings alone, the commonest (in brackets, for how many scenes):", "",
              "| RMSE at most | backend | scenes reaching it | cheapest, ms | by knob | anti-aliasing alone |",
              "| ---: | --- | ---: | ---: | --- | --- |"]
    for t in figures["targets"]:
        ms = "" if t["ms"] is None else f"{_ms(t['ms'][0])} to {_ms(t['ms'][1])}"
        knobs = ", ".join(f"{knob} ({count})" for knob, count in t["knobs"].items())
        settings = ", ".join(f"{name} ({count})" for name, count in t["antialiasing"].items())
        lines.append(f"| {t['rmse']:g} | {t['backend']} | {t['reached']} of {t['scenes']} | "
                     f"{ms} | {knobs} | {settings} |")
    return "\n".join(lines + ["", measured_line(document), ""])


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--skip-default", action="store_true")
    args = parser.parse_args()
    print(machine())
    runs, default_rows = [], []
    for name, command in RUNS:
        if name == "default" and args.skip_default:
            continue
        with tempfile.TemporaryDirectory(prefix="bench-report-") as folder:
            run = timed_run(command, Path(folder))
        print(f"{name:20} {run['seconds']:8.1f} s  status {run['status']}  {run['rows']} rows, "
              f"{run['scenes']} scenes: {run['said']}", flush=True)
        if run["status"] != 0:
            sys.exit(f"renderer {' '.join(command)} failed (status {run['status']})")
        if name == "default":
            default_rows = run["results"]
        runs.append({"name": name, "args": command, **{k: run[k] for k in
                                                        ("seconds", "rows", "scenes")}})
    if args.skip_default:
        return
    figures = {"runs": runs, **findings(default_rows)}
    print(write_results("report", figures, markdown))


if __name__ == "__main__":
    os.chdir(ROOT)
    main()
