"""How `renderer report` times a setting: the median of `runs` runs of the whole call, after
an untimed first run where the call pays once for what later runs reuse (the GPU's shader
compilation, the first use of a render target)."""

from __future__ import annotations

import statistics
import time
from typing import Callable, TypeVar

Result = TypeVar("Result")


def median_timed(render: Callable[[], Result], runs: int, *, warm_up: bool) -> tuple[Result, float]:
    """(the last run's result, the median milliseconds of `runs` runs of `render()`)."""
    if warm_up:
        render()
    times = []
    for _ in range(runs):
        start = time.perf_counter()
        result = render()
        times.append((time.perf_counter() - start) * 1000.0)
    return result, statistics.median(times)
