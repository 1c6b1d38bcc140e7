"""Executors: run batches of work on workers, in this process or on Ray, the same way.

    with open_executor(address=None, workers=None) as ex:      # Ray when installed, else here
        for index, results in ex.map(factory, batches):          # any order: key by unit
            ...
        for index, value in ex.tasks(function, [args, ...]):      # plain tasks (the reference)
            ...

A *batch* is a list of picklable work units. A *worker* is a plain Python object that
`factory()` builds once per worker process (a picklable callable: a module-level class, or
functools.partial of one); it holds what is expensive to make (a GL context, renderers
cached by scene) and answers `worker.run(batch)` with one result per unit, in the batch's
order. `map` yields (batch index, results) as batches finish, in whatever order they finish:
callers key results by unit, never by arrival, so nothing depends on which worker ran what.

Faults (Ray): a worker process that dies costs only the batches it held. Ray restarts the
actor; the batches it held are queued again by the executor, and after MAX_ATTEMPTS failures
of one batch `map` raises BatchFailed. Work must therefore be
idempotent: a unit may run twice, and its results must be the same bytes both times.

Workers on Ray never write files: they return results and the caller (the driver) writes,
so a killed worker leaves nothing half-written anywhere.
"""

from __future__ import annotations

import math
import os
import socket
import sys
from typing import Any, Callable, Iterable, Iterator, Protocol

from renderer.cluster.faults import MAX_ATTEMPTS, BatchFailed  # noqa: F401 (named here too)

TARGET_BATCH_SECONDS = 0.25 # batch size: this much work per call (batch_size)
MAX_BATCH = 64
BATCHES_PER_WORKER = 4      # at least this many batches per worker, for balance at the end
RAY_EXTRA = "pip install 'checked-renderer[cluster]'"


def batch_size(item_seconds: float, items: int, workers: int) -> int:
    """Units per batch: TARGET_BATCH_SECONDS of work per call, so a call's fixed overhead
    (a round trip on Ray: benchmarks/results/batch.md) stays under 1 %,
    at most MAX_BATCH, and at most items / (BATCHES_PER_WORKER x workers) so that every worker
    gets several batches and none idles long at the end of the job."""
    by_time = round(TARGET_BATCH_SECONDS / item_seconds) if item_seconds > 0 else MAX_BATCH
    by_balance = math.ceil(items / (BATCHES_PER_WORKER * max(workers, 1)))
    return max(1, min(by_time, MAX_BATCH, by_balance))


def worker_identity() -> dict:
    """This process as a worker, for the records and rows it returns: {"host", "pid"}."""
    return {"host": socket.gethostname(), "pid": os.getpid()}


def worker_label(identity: dict) -> str:
    """A worker's identity written as HOST:PID (results.csv's `worker`, batch's summary)."""
    return f"{identity.get('host')}:{identity.get('pid')}"


def batches_of(units: list, size: int) -> list[list]:
    """`units` cut into consecutive batches of `size` (the last may be shorter)."""
    return [units[start:start + size] for start in range(0, len(units), size)]


class Executor(Protocol):
    kind: str           # "in-process" or "ray"
    workers: int        # how many workers run batches at once

    def map(self, factory: Callable[[], Any], batches: list[list]) -> Iterator[tuple[int, list]]:
        """(batch index, worker.run(batch)) for every batch, in the order they finish: a
        generator, which a caller stopping early closes (contextlib.closing) before it closes
        the executor, so that its calls in flight end first."""

    def tasks(self, function: Callable, args: Iterable[tuple]) -> Iterator[tuple[int, Any]]:
        """(index, function(*args[index])) for every argument tuple, in the order they finish;
        plain stateless tasks (the reference renders: no GL)."""

    def describe(self) -> str:
        """One line for the summary: where the work ran."""

    def close(self) -> None:
        """Stop the workers (and a local Ray started for this executor)."""


class InProcessExecutor:
    """Everything in this process, one worker, batches in order: the executor without Ray,
    and the one whose results the Ray runs are checked against."""

    kind = "in-process"
    workers = 1

    def map(self, factory, batches):
        worker = factory()
        try:
            for index, batch in enumerate(batches):
                yield index, worker.run(batch)
        finally:
            close = getattr(worker, "close", None)
            if close is not None:
                close()

    def tasks(self, function, args):
        for index, arguments in enumerate(args):
            yield index, function(*arguments)

    def describe(self) -> str:
        return "in this process"

    def close(self) -> None:
        pass

    def __enter__(self):
        return self

    def __exit__(self, *exc):
        self.close()


def ray_available() -> bool:
    """Whether Ray can be imported (the `cluster` extra), without importing it."""
    import importlib.util
    return importlib.util.find_spec("ray") is not None


def note(line: str) -> None:
    print(f"renderer: {line}", file=sys.stderr)


def open_executor(address: str | None = None, workers: int | None = None, *,
                  use_ray: bool = True, say: Callable[[str], None] = note):
    """The executor for a command's --address and --workers.

    address None and use_ray: a local Ray started for this run (ray.init(address="local"),
    never joining a cluster by accident) with `workers` actors (default: the cores), or, when
    Ray is not installed, this process with one note line. address "auto" or HOST:PORT: that
    cluster (checked before Ray is asked: an address nobody answers is a UserError, exit 2).
    use_ray False and no address: this process (what `renderer report` does by default)."""
    from renderer.errors import UserError
    if address is None and not use_ray:
        return InProcessExecutor()
    if not ray_available():
        if address is not None:
            raise UserError(f"needs Ray, which is not installed ({RAY_EXTRA})", key="--address")
        say(f"Ray is not installed ({RAY_EXTRA}); running in this process")
        return InProcessExecutor()
    from renderer.cluster.ray_executor import RayExecutor     # imports ray: only here
    return RayExecutor(address=address, workers=workers)
