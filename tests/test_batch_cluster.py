"""`renderer batch` on a local Ray (the module's `ray_executor`, tests/conftest.py; slow):
the same files with 1 worker, 2 workers or none; a worker killed with SIGKILL mid-job
costs a retry and nothing else (the issue's test); a killed command resumes to the same
result; --compare's reference in Ray's tasks gives this process's figures. "The same" is
the manifest's SHA-256 of every file, and the folder holding exactly the files the
manifest lists (no temporary, no half-written file)."""

import json
import os
import signal
import subprocess
import sys
import time
from pathlib import Path

import pytest

from renderer.batch.job_file import read_job
from renderer.batch.manifest import MANIFEST
from renderer.batch.run import run_job
from renderer.cluster.executor import InProcessExecutor

ROOT = Path(__file__).resolve().parents[1]
VIEWS = 32                          # x 2 scenes: 64 items, enough to kill a worker mid-job
JOB = f"""
seed = 19
size = [40, 30]

[[scenes]]
scene = "sphere"
cameras = {{ orbit = {{ views = {VIEWS} }} }}

[[scenes]]
scene = "hierarchy"
cameras = {{ orbit = {{ views = {VIEWS}, elevation = 25.0 }} }}

[[settings]]
name = "raster"
outputs = [{{ format = "png8", transfer = "srgb" }}]
"""
TRACED = """
[[settings]]
name = "rt"
method = "raytrace"
samples = 2
pattern = "random"
"""
KILL_AFTER = 8                      # records in the manifest before the kill
WORKER_TITLE = b"ray::WorkerHost"   # an actor's process title (ray_executor.WorkerHost)


def records(out: Path) -> dict:
    """{key: record} of out/manifest.jsonl."""
    _, *lines = (out / MANIFEST).read_text().splitlines()
    return {record["key"]: record for record in map(json.loads, lines)}


def hashes(out: Path) -> dict:
    return {key: [(o["path"], o["sha256"]) for o in record["outputs"]]
            for key, record in records(out).items()}


def files_in(out: Path) -> set:
    return {path.relative_to(out).as_posix() for path in out.rglob("*") if path.is_file()}


def assert_same_job(out: Path, undisturbed: Path) -> None:
    """Every item's files with the undisturbed run's SHA-256, and no other file in `out`."""
    assert hashes(out) == hashes(undisturbed)
    listed = {path for outputs in hashes(out).values() for path, _ in outputs}
    assert files_in(out) == listed | {MANIFEST}, "a file the manifest does not list"


def parent_of(pid) -> int:
    # /proc/PID/stat: "PID (COMMAND) STATE PPID ...", COMMAND may hold spaces and brackets.
    return int(Path(f"/proc/{pid}/stat").read_text().rpartition(")")[2].split()[1])


def pids_of_workers() -> list[int]:
    """The processes of the RayExecutor actors on this module's Ray: their raylet is a child
    of this process (LocalRay started it), unlike other Rays running on the machine."""
    pids = []
    for entry in filter(str.isdigit, os.listdir("/proc")):
        try:
            if Path(f"/proc/{entry}/cmdline").read_bytes().startswith(WORKER_TITLE) and \
                    parent_of(parent_of(entry)) == os.getpid():
                pids.append(int(entry))
        except (OSError, ValueError, IndexError):
            continue                # gone meanwhile
    return pids


def wait_for_records(out: Path, count: int, process: subprocess.Popen, timeout=120.0) -> None:
    end = time.monotonic() + timeout
    while time.monotonic() < end and process.poll() is None:
        try:
            if len((out / MANIFEST).read_text().splitlines()) > count:
                return
        except FileNotFoundError:
            pass
        time.sleep(0.01)
    raise AssertionError(f"the job ended or stalled before {count} records: {process.poll()}")


def batch_command(job: Path, out: Path, *options) -> subprocess.Popen:
    return subprocess.Popen([sys.executable, "-m", "renderer", "batch", str(job), "--out", str(out),
                             *map(str, options)], cwd=ROOT, stdout=subprocess.PIPE,
                            stderr=subprocess.PIPE, text=True)


@pytest.fixture(scope="module")
def job_file(tmp_path_factory) -> Path:
    path = tmp_path_factory.mktemp("job") / "orbits.toml"
    path.write_text(JOB + TRACED)
    return path


@pytest.fixture(scope="module")
def undisturbed(job_file, tmp_path_factory) -> Path:
    """The job rendered in this process, once: what every other run must equal."""
    out = tmp_path_factory.mktemp("undisturbed") / "out"
    summary = run_job(read_job(job_file), out, InProcessExecutor(), progress=False, say=print)
    assert summary.done == 2 * VIEWS * 2 and not summary.failed       # scenes x views x settings
    return out


@pytest.mark.parametrize("workers", [1, 2])
def test_any_number_of_workers_writes_the_same_job(ray_executor, job_file, undisturbed,
                                                   tmp_path, workers):
    out = tmp_path / "out"
    with ray_executor(workers) as executor:
        summary = run_job(read_job(job_file), out, executor, progress=False, say=print)
    assert not summary.failed
    assert_same_job(out, undisturbed)
    assert len({record["worker"]["pid"] for record in records(out).values()}) == workers


def test_compare_on_ray_gives_the_figures_of_this_process(ray_executor, tmp_path):
    # The reference runs in Ray's plain tasks (executor.tasks), after the GPU's map.
    path = tmp_path / "small.toml"
    path.write_text(JOB.replace(f"views = {VIEWS}", "views = 2") + TRACED)
    outs = {}
    for name, executor in (("here", InProcessExecutor()), ("ray", ray_executor(2))):
        outs[name] = tmp_path / name
        with executor:
            summary = run_job(read_job(path), outs[name], executor, compare=True, progress=False)
        assert summary.done == 8 and not summary.failed
    assert_same_job(outs["ray"], outs["here"])
    figures = {name: {key: {figure: value for figure, value in record["compare"].items()
                            if not figure.endswith("_ms")}          # but the timings
                      for key, record in records(out).items()} for name, out in outs.items()}
    assert figures["ray"] == figures["here"]
    assert all(item["passes"] for item in figures["ray"].values())


def test_a_worker_killed_mid_job_costs_only_a_retry(ray_executor, job_file, undisturbed, tmp_path):
    out = tmp_path / "out"
    command = batch_command(job_file, out, "--address", ray_executor.address, "--workers", 2)
    try:
        wait_for_records(out, KILL_AFTER, command)
        before = pids_of_workers()
        assert len(before) == 2, before
        os.kill(before[0], signal.SIGKILL)
        _, stderr = command.communicate(timeout=180)
    finally:
        command.kill()
    assert command.returncode == 0, stderr
    assert_same_job(out, undisturbed)
    pids = {record["worker"]["pid"] for record in records(out).values()}
    assert pids - set(before), "no item was rendered by the restarted worker"


def test_a_killed_command_resumes_to_the_same_job(ray_executor, job_file, undisturbed, tmp_path):
    out = tmp_path / "out"
    command = batch_command(job_file, out, "--address", ray_executor.address)
    try:
        wait_for_records(out, KILL_AFTER, command)
        command.send_signal(signal.SIGKILL)                  # the driver itself, mid-job
        command.communicate(timeout=60)
    finally:
        command.kill()
    done_before = len(records(out))
    assert KILL_AFTER <= done_before < len(hashes(undisturbed))
    assert_resumes(job_file, out, ray_executor.address, done_before, undisturbed)


def assert_resumes(job_file: Path, out: Path, address: str, done: int, undisturbed: Path) -> None:
    """The same command run again skips the `done` items and finishes the undisturbed job."""
    again = subprocess.run([sys.executable, "-m", "renderer", "batch", str(job_file), "--out",
                            str(out), "--address", address],
                           cwd=ROOT, capture_output=True, text=True, timeout=180)
    assert again.returncode == 0, again.stderr
    assert f"{done} already complete" in again.stderr
    assert_same_job(out, undisturbed)


def test_ctrl_c_on_ray_is_one_line_and_status_130_then_the_job_resumes(ray_executor, job_file,
                                                                        undisturbed, tmp_path):
    # SIGINT to the driver mid-job (issue 30): the calls in flight are cancelled, so Ray says
    # nothing of the actors killed with them; the lock goes; the same command finishes.
    out = tmp_path / "out"
    command = batch_command(job_file, out, "--address", ray_executor.address)
    try:
        wait_for_records(out, KILL_AFTER, command)
        command.send_signal(signal.SIGINT)
        stdout, stderr = command.communicate(timeout=60)
    finally:
        command.kill()
    done = len(records(out))
    assert command.returncode == 130, stderr
    said = [line for line in stderr.replace("\r", "\n").splitlines() if line and "%|" not in line]
    total = len(hashes(undisturbed))
    assert said == [f"renderer: interrupted; {done} of {total} items done; run the same "
                    f"command to resume"]
    assert stdout == "" and KILL_AFTER <= done < total
    listed = {path for outputs in hashes(out).values() for path, _ in outputs}
    assert files_in(out) == listed | {MANIFEST}, "a file the manifest does not list"
    assert_resumes(job_file, out, ray_executor.address, done, undisturbed)
