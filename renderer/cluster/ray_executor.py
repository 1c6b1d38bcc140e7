"""The Executor of executor.py on Ray actors: a local Ray started for the run, or a cluster.

    with RayExecutor(workers=2) as ex:                  # a local Ray, 2 actors (default: cores)
        for index, results in ex.map(factory, batches): ...
    RayExecutor(address="auto")                          # the Ray running on this machine
    RayExecutor(address="head.example:6379")             # a cluster's head (GCS) address

Start. A local Ray is `ray.init(address="local")`: always a fresh one for this run, never a
cluster that happens to run on the machine (a bare ray.init() would join it). It is quiet (no
dashboard, worker output not forwarded, Ray's log lines at ERROR) and keeps its session files
in a short temporary folder that close() removes: Ray's socket paths must fit in 107 bytes,
and its default /tmp/ray/session_* folders are never deleted. An --address is checked with a
socket first (address.py): nobody answering is one line at once; where something answers
that is not a Ray head, Ray's own connection attempts are bounded (CONNECT_BOUNDS, ~5 s) and
its C++ log lines on fd 2 hidden: one line too. "auto" is Ray's own rule: $RAY_ADDRESS, else
the cluster `ray start` made here, else any Ray running on this machine (also one another
`renderer batch` started). A process already connected to Ray (ray.init called by the
program, or a test's cluster) is used as it is and left connected.

Workers. One actor per worker, each holding one worker object (factory(), made on its first
batch). CPU nodes: one actor per CPU (num_cpus=1), with LP_NUM_THREADS=1 set before the
factory runs, so that llvmpipe draws on one thread and the actors, not llvmpipe's threads,
share the cores (at 320x240 most of a frame's time is serial anyway: one actor with two
llvmpipe threads used one core). GPU nodes: one actor per GPU (num_gpus=1), its EGL device
the GPU Ray gave it (GLCONTEXT_DEVICE_INDEX, which glcontext reads when it makes an EGL
context). The GPU path is untested: no machine here has a GPU, and it assumes that the EGL
devices are numbered as Ray numbers the GPUs (CUDA's order; EGL_NV_device_cuda could map
them where they are not).

Scheduling. A ray.wait loop with IN_FLIGHT calls queued on each actor, so that an actor
finishing a batch finds the next one waiting (a call's round trip, benchmarks/results/batch.md, is hidden
this way). Faults: actors restart without limit (max_restarts=-1); Ray retries no call
(CALL_RETRIES = 0): a call lost with its process is queued again here, and a batch failing
MAX_ATTEMPTS times raises BatchFailed (a batch that kills its process every time takes the
batch queued behind it on the same actor down with it, so BatchFailed may name either). An
exception raised by the worker's own code is not a fault but a bug (or a UserError): it is
raised here at once, as in-process. A map or tasks left early (that error, or Ctrl-C in the
driver) cancels its calls still in flight, then the actors go with any call still running
in them; Ray retries none of them and prints nothing of them.
"""

from __future__ import annotations

import contextlib
import os
import shutil
import tempfile
from collections import Counter, deque
from typing import Any, Callable, Iterable, Iterator

from renderer.cluster.address import AUTO, check_address
from renderer.cluster.faults import MAX_ATTEMPTS, BatchFailed
from renderer.errors import UserError

IN_FLIGHT = 2                   # calls queued per actor
# Ray's own retries of a call lost with its process: none. Ray prints a line on stdout for each
# retry it would make, also of the calls of actors killed at a map's end (a Ctrl-C); the loop
# here queues a lost call again itself (MAX_ATTEMPTS), the one retry rule.
CALL_RETRIES = 0
QUIET = dict(log_to_driver=False, logging_level="ERROR")
# Ray's connection bounds while connecting to an --address (its defaults retry for minutes
# where something answers that is not a Ray head: 82 s measured with the first alone at 2);
# with these such an address fails in ~5 s here. Ray's core reads them once, when ray is
# first imported: a process that imported ray before keeps Ray's defaults.
CONNECT_BOUNDS = {"RAY_gcs_server_port_wait_time_s": "1",
                  "RAY_gcs_rpc_server_connect_timeout_s": "1",
                  "RAY_py_gcs_connect_timeout_s": "2"}
TEMP_PREFIX = "ray"             # /tmp/rayXXXXXXXX: short enough for Ray's socket paths


class WorkerHost:
    """The body of each actor: the process's settings, then one worker from factory()."""

    def __init__(self, factory: Callable[[], Any], gpu: bool):
        import ray
        if gpu:
            os.environ["GLCONTEXT_DEVICE_INDEX"] = str(int(ray.get_gpu_ids()[0]))
        else:
            os.environ["LP_NUM_THREADS"] = "1"      # llvmpipe reads it when a context is made
        self._factory, self._worker = factory, None

    def run(self, batch: list) -> list:
        if self._worker is None:
            self._worker = self._factory()
        return self._worker.run(batch)

    def pid(self) -> int:
        return os.getpid()


class LocalRay:
    """A Ray started in this process for one run (or a test module), and stopped by stop()."""

    def __init__(self, cpus: int):
        import ray
        self.temp_dir = tempfile.mkdtemp(prefix=TEMP_PREFIX, dir=_short_temp_root())
        try:
            info = ray.init(address="local", num_cpus=cpus, include_dashboard=False,
                            _temp_dir=self.temp_dir, **QUIET)
        except BaseException:
            shutil.rmtree(self.temp_dir, ignore_errors=True)
            raise
        self.address = info.address_info["gcs_address"]    # HOST:PORT for other processes

    def stop(self) -> None:
        import ray
        ray.shutdown()
        shutil.rmtree(self.temp_dir, ignore_errors=True)


class RayExecutor:
    """Batches on Ray actors (see the module's docstring). `address` None: a local Ray with
    `workers` CPUs (default: this machine's cores); "auto" or HOST:PORT: that cluster, with
    `workers` actors (default: one per GPU where it has GPUs, else one per CPU)."""

    kind = "ray"

    def __init__(self, address: str | None = None, workers: int | None = None):
        if workers is not None and workers < 1:
            raise UserError(f"{workers} workers: give at least 1", key="--workers")
        self._local: LocalRay | None = None
        self._connected = False
        if address is not None:
            check_address(address)          # before `import ray` (~0.6 s): a mistake is quick
            _connect(address)               # imports ray, its connection bounds set first
            self._connected = True
            self.where = f"the Ray cluster at {address}"
        else:
            import ray
            if ray.is_initialized():
                self.where = "the Ray this process is connected to"
            else:
                self._local = LocalRay(workers or os.cpu_count() or 1)
                self.where = "a local Ray"
        import ray
        try:
            self.workers, self.gpu = _workers_for(ray.cluster_resources(), workers)
        except BaseException:
            self.close()
            raise
        self.worker_pids: list[int] = []    # the actors' processes, once a map has started them

    # -- the Executor interface -------------------------------------------------------------

    def map(self, factory: Callable[[], Any], batches: list[list]) -> Iterator[tuple[int, list]]:
        import ray
        host = ray.remote(WorkerHost).options(
            num_cpus=1, num_gpus=1 if self.gpu else 0,
            max_restarts=-1, max_task_retries=CALL_RETRIES)
        actors = [host.remote(factory, self.gpu)
                  for _ in range(min(self.workers, len(batches)))]
        try:
            self.worker_pids = ray.get([actor.pid.remote() for actor in actors])
            yield from _schedule(actors, batches)
        finally:
            for actor in actors:
                ray.kill(actor, no_restart=True)

    def tasks(self, function: Callable, args: Iterable[tuple]) -> Iterator[tuple[int, Any]]:
        """Plain tasks, one CPU each: run them before or after a map, not from inside its loop
        (the map's actors hold the CPUs until it ends)."""
        import ray
        remote = ray.remote(function).options(num_cpus=1, max_retries=CALL_RETRIES)
        args = list(args)
        pending = {remote.remote(*arguments): (index, None) for index, arguments in enumerate(args)}

        def again(tag) -> None:
            pending[remote.remote(*args[tag[0]])] = tag

        for (index, _), value in _as_finished(pending, "task", again):
            yield index, value

    def describe(self) -> str:
        unit = "GPU" if self.gpu else "CPU"
        if self.workers == 1:
            return f"{self.where}, 1 worker (a Ray actor on one {unit})"
        return f"{self.where}, {self.workers} workers (Ray actors, one {unit} each)"

    def close(self) -> None:
        """Stop a local Ray we started, or disconnect from a cluster we connected to; a Ray
        this process was already connected to is left as it was."""
        import ray
        if self._local is not None:
            self._local.stop()
            self._local = None
        elif self._connected:
            ray.shutdown()
            self._connected = False

    def __enter__(self):
        return self

    def __exit__(self, *exc):
        self.close()


def _schedule(actors: list, batches: list[list]) -> Iterator[tuple[int, list]]:
    """IN_FLIGHT calls per actor; an actor that answers gets the next batch, and a batch
    lost to a fault goes back to the front of the queue."""
    queue = deque(range(len(batches)))
    pending: dict = {}                   # ObjectRef -> (batch index, actor)

    def submit(actor) -> None:
        if queue:
            index = queue.popleft()
            pending[actor.run.remote(batches[index])] = (index, actor)

    def again(tag) -> None:
        queue.appendleft(tag[0])
        submit(tag[1])

    for _ in range(IN_FLIGHT):
        for actor in actors:
            submit(actor)
    for (index, actor), results in _as_finished(pending, "batch", again):
        yield index, results
        submit(actor)


def _cancel(pending: dict) -> None:
    """Cancel the calls still queued or running: a queued one is dropped, a running plain
    task interrupted. A call running in an actor is not stopped (a synchronous actor's is
    not): it goes with its actor (map's end)."""
    import ray
    for ref in pending:
        with contextlib.suppress(Exception):
            ray.cancel(ref)


def _as_finished(pending: dict, what: str, again: Callable) -> Iterator[tuple[tuple, Any]]:
    """(tag, result) for each call of `pending` ({ObjectRef: (index, ...)}, which grows as
    the caller submits more) as it finishes: the ray.wait loop. A call lost to a fault
    (its process died) is handed to again(tag) to be submitted
    once more, MAX_ATTEMPTS times per index at most (then BatchFailed); an exception
    raised by the work itself is raised here (_get)."""
    import ray
    failures: Counter[int] = Counter()
    try:
        while pending:
            [ref], _ = ray.wait(list(pending), num_returns=1)
            tag = pending.pop(ref)
            try:
                result = _get(ref)
            except ray.exceptions.RayTaskError:
                raise                           # the work's own error: a bug, not a fault
            except ray.exceptions.RayError as exc:
                failures[tag[0]] += 1
                if failures[tag[0]] >= MAX_ATTEMPTS:
                    raise BatchFailed(f"{what} {tag[0]} failed {MAX_ATTEMPTS} times on Ray: "
                                      f"its worker's process was lost each time "
                                      f"({type(exc).__name__}; out of memory, or a crash in "
                                      f"the GL driver?)") from exc
                again(tag)
                continue
            yield tag, result
    finally:                                    # left early (an error, Ctrl-C): calls go
        _cancel(pending)


def _get(ref):
    """ray.get, with an exception raised by the worker's code raised as in-process: a
    UserError as itself (one line for the user), a bug as Ray's error with the worker's
    traceback. Ray's faults (a process lost) stay RayErrors for the caller to retry."""
    import ray
    try:
        return ray.get(ref)
    except ray.exceptions.RayTaskError as exc:
        if isinstance(exc.cause, UserError):
            raise exc.cause from None
        raise


def _workers_for(resources: dict, asked: int | None) -> tuple[int, bool]:
    """(actors, on GPUs?): one per GPU where the cluster has GPUs, else one per CPU; `asked`
    more than that is a UserError (the extra actors would wait for ever)."""
    gpu = resources.get("GPU", 0) >= 1
    available = int(resources.get("GPU" if gpu else "CPU", 0))
    if asked is None:
        return max(available, 1), gpu
    if asked > available:
        unit = "GPUs" if gpu else "CPUs"
        raise UserError(f"{asked} workers, but the Ray cluster has {available} {unit}",
                        key="--workers")
    return asked, gpu


def _connect(address: str) -> None:
    """ray.init(address=...) with Ray's attempts bounded (CONNECT_BOUNDS) and its fd-2 log
    lines hidden; a failure is a UserError (key --address)."""
    with _environment(**CONNECT_BOUNDS), _fd2_hidden():
        import ray                          # after the bounds: Ray's core reads them on import
        if ray.is_initialized():
            raise RuntimeError("this process is already connected to Ray: use that one "
                               "(address=None) or ray.shutdown() first")
        try:
            ray.init(address=address, **QUIET)
            return
        except (ConnectionError, RuntimeError, ValueError) as exc:
            ray.shutdown()
            cause = " ".join(str(exc).split())[:160] or type(exc).__name__
    if address == AUTO:
        raise UserError("auto: no Ray cluster runs on this machine (start one with "
                        "`ray start --head`, or give its HOST:PORT)", key="--address")
    raise UserError(f"{address} answers, but Ray could not connect to it ({cause})",
                    key="--address")


@contextlib.contextmanager
def _environment(**values: str):
    saved = {name: os.environ.get(name) for name in values}
    os.environ.update(values)
    try:
        yield
    finally:
        for name, value in saved.items():
            if value is None:
                os.environ.pop(name, None)
            else:
                os.environ[name] = value


@contextlib.contextmanager
def _fd2_hidden():
    """Ray's C++ core logs a failed connection on file descriptor 2 (no setting stops it)."""
    saved = os.dup(2)
    try:
        with open(os.devnull, "w") as null:
            os.dup2(null.fileno(), 2)
        yield
    finally:
        os.dup2(saved, 2)
        os.close(saved)


def _short_temp_root() -> str | None:
    """/tmp when it exists: a long $TMPDIR would push Ray's socket paths past 107 bytes."""
    return "/tmp" if os.path.isdir("/tmp") else None
