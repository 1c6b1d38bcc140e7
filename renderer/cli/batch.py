"""`renderer batch`: a job file's items rendered once each into a folder with a manifest
(renderer/batch/), on Ray's workers when installed."""

from __future__ import annotations

import sys
import time

from renderer.cli.options import memory_option, output_path, positive_int


def add_parser(sub) -> None:
    """`batch`'s parser: the job file, --out, where it runs, --compare."""
    batch = sub.add_parser(
        "batch", help="render a job file's items (scenes x cameras x sweeps x settings) into a "
                      "folder with a manifest; on Ray's workers when installed (docs/batch-format.md)",
        description="Render every item of a job file once into --out, each item's files written "
                    "whole and recorded in --out/manifest.jsonl (SHA-256 of every file); a re-run "
                    "with the same --out skips the items already complete. Exit status: 0 when "
                    "every item was written, 1 when some failed (a re-run tries them again), 2 "
                    "for bad input, with nothing written, or a DIR another batch is writing "
                    "(one driver per DIR: a lock file in it), 130 after Ctrl-C (a re-run "
                    "resumes).")
    batch.add_argument("job", metavar="JOB.toml", help="the job file (docs/batch-format.md)")
    batch.add_argument("--out", type=output_path, required=True, metavar="DIR",
                       help="folder for the items' files and manifest.jsonl")
    batch.add_argument("--address", metavar="auto|HOST:PORT",
                       help="a running Ray cluster (auto: the one `ray start` made on this "
                            "machine); default: a local Ray started for this job, or this process "
                            "when Ray is not installed")
    batch.add_argument("--workers", type=positive_int, metavar="N",
                       help="workers of a local Ray (default: one per core)")
    batch.add_argument("--compare", action="store_true",
                       help="also render each item with the NumPy reference and compare, as "
                            "`renderer compare` does (gpu.png, reference.png, diff.png in the "
                            "item's compare/ folder, the figures in its record)")
    batch.add_argument("--context", choices=("auto", "egl", "osmesa"), default="auto",
                       help="the workers' headless GL context (default: EGL, then OSMesa)")
    memory_option(batch)


def run(args) -> int:
    """`renderer batch`: everything checked (job file, scenes, outputs, --out's manifest)
    before the executor starts (renderer/batch/run.py), --out locked for this driver
    (renderer/batch/folder.py); the summary on stderr. Ctrl-C: one line saying how many
    items are done, status 130."""
    from renderer.batch.folder import locked
    from renderer.batch.job_file import read_job
    from renderer.batch.run import Interrupted, plan_job, run_plan
    from renderer.cluster.executor import InProcessExecutor, open_executor
    from renderer.errors import INTERRUPTED
    start = time.perf_counter()                 # the summary's whole time: Ray's start too
    job = read_job(args.job)
    with locked(args.out) as out:
        plan = plan_job(job, out, compare=args.compare)
        done = Interrupted(len(plan.items) - len(plan.todo), len(plan.items))
        try:
            # Nothing left to render (a finished job run again): no workers to start.
            opened = open_executor(args.address, args.workers) if plan.todo else InProcessExecutor()
            with opened as executor:
                summary = run_plan(plan, executor, context_kind=args.context)
                done = Interrupted(summary.skipped + summary.done, summary.items)
        except KeyboardInterrupt as stop:       # while the workers start, render or stop
            print(f"renderer: {(stop if isinstance(stop, Interrupted) else done).line()}",
                  file=sys.stderr)
            return INTERRUPTED
    summary.wall = time.perf_counter() - start
    for line in summary.lines():
        print(f"renderer {line}", file=sys.stderr)
    return 1 if summary.failed else 0
