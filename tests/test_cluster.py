"""Executors (renderer/cluster/): the Ray executor gives what the in-process one gives, in any
order and through a killed worker; a wrong --address is one line, at once; without Ray the
work runs in this process with one note; and the command line does not import Ray.

Tests on a local Ray take the module's `ray_executor` (tests/conftest.py: one Ray for this
module, the tests marked slow). The toy workers below travel to the actors by value.
"""

import functools
import hashlib
import os
import signal
import socket
import subprocess
import sys
import threading
import time
from pathlib import Path

import pytest

from renderer.cluster import executor as executor_module
from renderer.cluster.address import check_address, split_address
from renderer.cluster.executor import BatchFailed, InProcessExecutor, batches_of, open_executor
from renderer.errors import UserError

VIEWS = 12                  # orbit views of the toy GL worker
SIZE = (32, 24)
ROOT = os.path.dirname(os.path.dirname(os.path.abspath(__file__)))


class OrbitWorker:
    """A toy GL worker as the batch runner's: one context and one GpuRenderer per process,
    reused; unit k is orbit view k of the sphere, answered (k, SHA-256 of its pixels, pid)."""

    def __init__(self):
        from renderer.core.camera_paths import orbit_cameras
        from renderer.core.scene_file import load_scene
        from renderer.gpu.pipeline import GpuRenderer
        self.gpu = GpuRenderer(load_scene("sphere"), *SIZE)
        self.cameras = orbit_cameras(self.gpu.scene.camera, VIEWS, 30.0)

    def run(self, batch):
        results = []
        for view in batch:
            self.gpu.scene.camera = self.cameras[view]
            self.gpu.update()
            pixels = self.gpu.render().rgba8
            results.append((view, hashlib.sha256(pixels.tobytes()).hexdigest(), os.getpid()))
        return results

    def close(self):
        self.gpu.release()


class SquareWorker:
    """Unit n -> (n, n * n, pid), `seconds` per batch, so that a kill lands mid-map."""

    def __init__(self, seconds=0.0):
        self.seconds = seconds

    def run(self, batch):
        time.sleep(self.seconds)
        return [(n, n * n, os.getpid()) for n in batch]


class DyingWorker:
    """Unit 13 kills its own process, every time it is run (a crash Ray cannot retry away)."""

    def run(self, batch):
        if 13 in batch:
            os.kill(os.getpid(), signal.SIGKILL)
        return [(n, n * n, os.getpid()) for n in batch]


class FailingWorker:
    def __init__(self, error):
        self.error = error

    def run(self, batch):
        raise self.error


class LlvmpipeThreads:
    """Unit -> how many llvmpipe threads this process has once it has made a GL context."""

    def run(self, batch):
        from renderer.gpu.context import make_context, release_context
        ctx = make_context("auto")
        threads = sum(Path(f"/proc/self/task/{task}/comm").read_text().startswith("llvmpipe")
                      for task in os.listdir("/proc/self/task"))
        release_context(ctx)
        return [threads for _ in batch]


def square_task(n):
    return n * n


def open_elsewhere(address: str, before: str = "") -> subprocess.CompletedProcess:
    """open_executor(address) in a new process (Ray's connection bounds hold only where ray
    is imported afterwards; this process holds the module's Ray): stdout is the UserError's
    line. `before`: Python run first."""
    code = (f"import sys\n{before}\n"
            "from renderer.cluster.executor import open_executor\n"
            "from renderer.errors import UserError\n"
            "try: open_executor(sys.argv[1], 1)\n"
            "except UserError as e: print(e.line())\n")
    return subprocess.run([sys.executable, "-c", code, address], capture_output=True, text=True,
                          cwd=ROOT, timeout=60, env={**os.environ, "RAY_ADDRESS": ""})


def by_unit(mapped, batches: int) -> dict:
    """{unit: (value, pid)} from map's (index, results), each of the batches seen once."""
    seen, results = [], {}
    for index, batch_results in mapped:
        seen.append(index)
        for unit, value, pid in batch_results:
            results[unit] = (value, pid)
    assert sorted(seen) == list(range(batches)), "a batch came back twice or not at all"
    return results


# -- without a Ray ----------------------------------------------------------------------------

@pytest.mark.parametrize("address", ["localhost", "localhost:", ":6379", "localhost:0",
                                     "localhost:65536", "localhost:http", "[::1]"])
def test_an_address_is_auto_or_host_colon_port(address):
    with pytest.raises(UserError) as caught:
        check_address(address)
    assert caught.value.line() == \
        f"--address: {address!r} is not auto or HOST:PORT (a port from 1 to 65535)"


TINY_JOB = """
size = [16, 12]

[[scenes]]
scene = "sphere"

[[settings]]
name = "raster"
outputs = [{ format = "png8" }]
"""


@pytest.fixture
def tiny_job(tmp_path):
    path = tmp_path / "job.toml"
    path.write_text(TINY_JOB)
    return path


@pytest.mark.parametrize("address, reason", [
    ("127.0.0.1:1", "no Ray head answers at 127.0.0.1:1 (Connection refused)"),
    ("head.example", "'head.example' is not auto or HOST:PORT (a port from 1 to 65535)"),
    ("nonexistent.invalid:6379", "cannot resolve the host 'nonexistent.invalid'"),
])
def test_batch_with_a_wrong_address_is_one_line_at_once(cli_here, tiny_job, tmp_path, address,
                                                       reason):
    start = time.perf_counter()
    done = cli_here("batch", tiny_job, "--out", tmp_path / "out", "--address", address)
    assert time.perf_counter() - start < 5                 # not Ray's minutes of retries
    assert (done.returncode, done.stdout) == (2, "")
    assert done.stderr.startswith(f"renderer: --address: {reason}")
    assert len(done.stderr.splitlines()) == 1 and not (tmp_path / "out").exists()


@pytest.mark.slow
def test_batch_without_ray_runs_here_with_one_note(tiny_job, tmp_path):
    code = ("import sys; sys.modules['ray'] = None\n"            # as if it were not installed
            "from renderer.cli import main; sys.exit(main(sys.argv[1:]))")
    done = subprocess.run([sys.executable, "-c", code, "batch", str(tiny_job), "--out",
                           str(tmp_path / "out")], capture_output=True, text=True, cwd=ROOT,
                          timeout=120)
    assert done.returncode == 0, done.stderr
    notes = [line for line in done.stderr.splitlines() if "Ray" in line]
    assert notes == ["renderer: Ray is not installed (pip install 'checked-renderer[cluster]'); "
                     "running in this process"]
    assert "1 rendered" in done.stderr and "; in this process)" in done.stderr   # the summary
    assert (tmp_path / "out" / "manifest.jsonl").exists()


def test_an_address_that_answers_passes_the_check():
    with socket.socket() as server:
        server.bind(("127.0.0.1", 0))
        server.listen()
        check_address(f"127.0.0.1:{server.getsockname()[1]}")
    assert split_address("[::1]:6379") == ("::1", 6379)


def test_without_ray_the_work_runs_here_with_one_note(monkeypatch):
    monkeypatch.setattr(executor_module, "ray_available", lambda: False)
    said = []
    executor = open_executor(None, 2, say=said.append)
    assert isinstance(executor, InProcessExecutor)
    assert len(said) == 1 and "Ray is not installed" in said[0] and "[cluster]" in said[0]
    with pytest.raises(UserError) as caught:               # a cluster cannot be had without it
        open_executor("auto", None, say=said.append)
    assert caught.value.key == "--address" and len(said) == 1


def test_the_command_line_does_not_import_ray():
    code = ("import sys, renderer.cli, renderer.cluster.ray_executor; "
            "print('ray' in sys.modules)")
    done = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True,
                          cwd=ROOT, timeout=60)
    assert done.returncode == 0, done.stderr
    assert done.stdout.strip() == "False"


def test_in_process_map_is_the_order_of_the_batches():
    mapped = list(InProcessExecutor().map(SquareWorker, batches_of(list(range(7)), 3)))
    assert mapped == [(0, [(0, 0, os.getpid()), (1, 1, os.getpid()), (2, 4, os.getpid())]),
                      (1, [(3, 9, os.getpid()), (4, 16, os.getpid()), (5, 25, os.getpid())]),
                      (2, [(6, 36, os.getpid())])]


# -- on a local Ray (slow: the module's ray_executor) ----------------------------------------

def test_ray_renders_what_this_process_renders_in_any_order(ray_executor):
    here = by_unit(InProcessExecutor().map(OrbitWorker, batches_of(list(range(VIEWS)), 5)), 3)
    views = list(range(VIEWS))[::-1]                        # other batches, another order
    with ray_executor(workers=2) as executor:
        there = by_unit(executor.map(OrbitWorker, batches_of(views, 2)), VIEWS // 2)
        pids = set(executor.worker_pids)
    assert {view: value for view, (value, _) in there.items()} == \
        {view: value for view, (value, _) in here.items()}
    assert len(set(here.values())) == VIEWS                 # twelve different frames
    assert {pid for _, pid in there.values()} == pids and len(pids) == 2


@pytest.mark.skipif(not os.path.isdir("/proc/self/task"), reason="reads /proc")
def test_each_worker_draws_on_one_llvmpipe_thread(ray_executor):
    with ray_executor(workers=2) as executor:      # the actors, not llvmpipe, share the cores
        assert [threads for _, threads in executor.map(LlvmpipeThreads, [[1], [2]])] == [[1], [1]]


def test_a_worker_killed_mid_map_costs_only_a_retry(ray_executor):
    units = list(range(40))
    with ray_executor(workers=2) as executor:
        mapped = executor.map(functools.partial(SquareWorker, 0.1), batches_of(units, 2))
        first = next(mapped)
        killed = executor.worker_pids[0]
        os.kill(killed, signal.SIGKILL)
        results = by_unit([first, *mapped], len(units) // 2)
    assert {unit: value for unit, (value, _) in results.items()} == {n: n * n for n in units}
    pids = {pid for _, pid in results.values()}
    assert pids - {killed} - set(executor.worker_pids), "no batch ran on the restarted actor"


def test_a_batch_that_always_kills_its_worker_fails_the_map(ray_executor, monkeypatch):
    done = []
    with ray_executor(workers=1) as executor:
        # The batches waiting on the actor (IN_FLIGHT) die with it: any of them may be the
        # first to fail MAX_ATTEMPTS times.
        attempts = executor_module.MAX_ATTEMPTS
        with pytest.raises(BatchFailed, match=f"failed {attempts} times") as caught:
            for index, results in executor.map(DyingWorker, batches_of(list(range(20)), 2)):
                done.append(index)
                units = (2 * index, 2 * index + 1)
                assert [value for _, value, _ in results] == [n * n for n in units]
    assert 6 not in done and len(done) >= 4
    assert caught.value.status == 1 and "process was lost" in caught.value.line()


def test_the_workers_own_errors_are_raised_as_in_process(ray_executor):
    with ray_executor(workers=1) as executor:
        with pytest.raises(UserError, match="^scene.toml: a reason$"):
            list(executor.map(lambda: FailingWorker(UserError("a reason", file="scene.toml")),
                              [[1]]))
        with pytest.raises(ZeroDivisionError, match="a bug"):   # a bug keeps its traceback
            list(executor.map(lambda: FailingWorker(ZeroDivisionError("a bug")), [[1]]))


def test_tasks_answer_every_argument_once(ray_executor):
    with ray_executor() as executor:
        answers = dict(executor.tasks(square_task, [(n,) for n in range(10)]))
        assert answers == {n: n * n for n in range(10)}
        assert "a local Ray" not in executor.describe()     # the module's Ray, not its own


def test_more_workers_than_the_cluster_has_cpus_is_one_line(ray_executor):
    with pytest.raises(UserError) as caught:        # the extra actors would wait for ever
        ray_executor(workers=3)
    assert caught.value.line() == "--workers: 3 workers, but the Ray cluster has 2 CPUs"


def test_a_cluster_by_its_address(ray_executor):
    code = (
        "import os, sys\n"
        "from renderer.cluster.executor import open_executor\n"
        "class Pid:\n"
        "    def run(self, batch): return [os.getpid() for _ in batch]\n"
        "with open_executor(sys.argv[1], 1) as ex:\n"
        "    print(ex.describe()); print(sorted(i for i, _ in ex.map(Pid, [[1], [2], [3]])))\n")
    done = subprocess.run([sys.executable, "-c", code, ray_executor.address],
                          capture_output=True, text=True, cwd=ROOT, timeout=120)
    assert done.returncode == 0, done.stderr
    assert done.stdout.splitlines() == [
        f"the Ray cluster at {ray_executor.address}, 1 worker (a Ray actor on one CPU)",
        "[0, 1, 2]"]


@pytest.mark.slow
@pytest.mark.skipif(os.path.exists("/tmp/ray/ray_current_cluster"), reason="`ray start` ran here")
def test_auto_without_a_cluster_is_one_line_at_once():
    # "auto" is also any Ray running on the machine (Ray finds their processes): such as
    # other test sessions' own. Here Ray is made to find none.
    done = open_elsewhere("auto", "import functools, ray._private.services as services\n"
                          "services._cached_find_gcs_addresses = functools.lru_cache()(set)")
    assert (done.stdout, done.stderr) == ("--address: auto: no Ray cluster runs on this machine "
                                          "(start one with `ray start --head`, or give its "
                                          "HOST:PORT)\n", "")


@pytest.mark.slow
def test_an_address_that_answers_but_is_no_ray_is_one_line_in_seconds():
    with socket.socket() as server:
        server.bind(("127.0.0.1", 0))
        server.listen(16)
        threading.Thread(target=lambda: [server.accept()[0].close() for _ in range(64)],
                         daemon=True).start()
        start = time.perf_counter()
        done = open_elsewhere(f"127.0.0.1:{server.getsockname()[1]}")
        seconds = time.perf_counter() - start
    assert done.stdout.startswith("--address: 127.0.0.1:")
    assert "Ray could not connect" in done.stdout
    assert len(done.stdout.splitlines()) == 1 and done.stderr == ""
    assert seconds < 15, f"{seconds:.1f} s"
