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
    differs from it: what the figures were measured with."""
    def git(*args) -> str:
        return subprocess.run(["git", *args], capture_output=True, text=True,
                              cwd=os.path.dirname(os.path.abspath(__file__))).stdout.strip()
    commit = git("rev-parse", "--short", "HEAD") or "unknown"
    return commit + (" + uncommitted changes" if git("status", "--porcelain", "--untracked-files=no") else "")


def alternating_ms(calls, frames: int) -> list[float]:
    """The median ms of each callable, called in turn `frames` times (so all see the same load)."""
    times = [[] for _ in calls]
    for _ in range(frames):
        for call, spent in zip(calls, times):
            start = time.perf_counter()
            call()
            spent.append((time.perf_counter() - start) * 1000.0)
    return [statistics.median(spent) for spent in times]
