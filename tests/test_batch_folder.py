"""`renderer batch` keeps to its --out (issue 30, renderer/batch/folder.py): nothing written
through a symbolic link below it; manifest records naming a file outside it, or something
other than a regular file, dropped unread with one warning; one driver per folder (a lock
naming its holder); Ctrl-C one line, status 130, and the same command resumes.

Each refusal is one line and a status, with nothing written outside --out, no traceback and
a bounded time: in-process cases run under a SIGALRM deadline (a FIFO opened for reading
would block for ever), the processes under subprocess timeouts."""

import contextlib
import hashlib
import io
import json
import os
import shutil
import signal
import subprocess
import sys
import time
from pathlib import Path

import pytest

import renderer.cluster.executor as executor
from renderer.batch import run as batch_run
from renderer.batch.folder import LOCK_NAME, locked
from renderer.batch.job_file import read_job
from renderer.batch.manifest import MANIFEST
from renderer.batch.render_item import ItemWorker
from renderer.cluster.executor import InProcessExecutor
from renderer.cli import main
from renderer.core.paths import show_path
from renderer.errors import UserError

ROOT = Path(__file__).resolve().parents[1]
JOB = """
seed = 5
size = [32, 24]

[[scenes]]
scene = "sphere"
cameras = {{ orbit = {{ views = {views} }} }}

[[settings]]
name = "raster"
outputs = [{{ format = "png8", transfer = "srgb" }}]
"""
KEYS = ["sphere/orbit-000/sweep-000/raster", "sphere/orbit-001/sweep-000/raster"]
CANARY = "canary-3f9a: a file outside --out"
DEADLINE_S = 20                      # any in-process case; a hang is a failure, not a stall
PROCESS_TIMEOUT_S = 120
# `python -m renderer` in a process where Ray cannot be imported: the job runs in it
# (InProcessExecutor), as where Ray is not installed.
WITHOUT_RAY = [sys.executable, "-c", "import sys; sys.modules['ray'] = None; "
               "from renderer.cli import main; sys.exit(main(sys.argv[1:]))"]


# -- what the tests share ---------------------------------------------------------------------

OPENED: list[str] = []               # every path this process opened while `watching`
_WATCHING = []


def _audit(event, args):
    if _WATCHING and event == "open" and isinstance(args[0], (str, bytes, os.PathLike)):
        OPENED.append(os.path.realpath(os.fsdecode(args[0])))


sys.addaudithook(_audit)


@contextlib.contextmanager
def watching():
    """The paths opened inside the block (builtin open and os.open: the audit event) and a
    deadline: a read that blocks raises instead of hanging the run."""
    def late(number, frame):
        raise TimeoutError(f"still running after {DEADLINE_S} s")
    OPENED.clear()
    _WATCHING.append(True)
    previous = signal.signal(signal.SIGALRM, late)
    signal.alarm(DEADLINE_S)
    try:
        yield OPENED
    finally:
        signal.alarm(0)
        signal.signal(signal.SIGALRM, previous)
        _WATCHING.clear()


def lines(text: str) -> list[str]:
    """stderr's lines but the progress bar's (tqdm, redrawn with \\r)."""
    return [line for line in text.replace("\r", "\n").splitlines() if line and "%|" not in line]


def batch_here(job: Path, out: Path, monkeypatch) -> tuple[int, list[str]]:
    """`renderer batch JOB --out OUT` in this process, without Ray: (status, stderr lines
    but the note that Ray is not installed)."""
    monkeypatch.setattr(executor, "ray_available", lambda: False)
    err = io.StringIO()
    with contextlib.redirect_stderr(err), watching():
        status = main(["batch", str(job), "--out", str(out)])
    return status, [line for line in lines(err.getvalue()) if "Ray is not installed" not in line]


def files(folder: Path) -> set[str]:
    return {path.relative_to(folder).as_posix() for path in folder.rglob("*")}


def records(out: Path) -> dict:
    _, *found = (out / MANIFEST).read_text().splitlines()
    return {record["key"]: record for record in map(json.loads, found)}


@pytest.fixture(scope="module")
def job_file(tmp_path_factory) -> Path:
    path = tmp_path_factory.mktemp("job") / "job.toml"
    path.write_text(JOB.format(views=2))
    return path


@pytest.fixture(scope="module")
def finished(job_file, tmp_path_factory) -> Path:
    """The job's folder, complete (rendered once in this process)."""
    out = tmp_path_factory.mktemp("finished") / "out"
    summary = batch_run.run_job(read_job(job_file), out, InProcessExecutor(), progress=False,
                                say=print)
    assert summary.done == 2 and not summary.failed
    return out


@pytest.fixture
def outside(tmp_path) -> Path:
    """tmp/outside/victim.txt, holding CANARY: `../../outside/victim.txt` from tmp/x/out."""
    (tmp_path / "outside").mkdir()
    (tmp_path / "outside" / "victim.txt").write_text(CANARY)
    return tmp_path / "outside"


def copy(finished: Path, tmp_path: Path) -> Path:
    out = tmp_path / "x" / "out"
    shutil.copytree(finished, out)
    return out


# -- no write through a link ------------------------------------------------------------------

@pytest.mark.parametrize("link", ["items", "items/sphere", "items/sphere/orbit-001"])
def test_a_symbolic_link_below_out_is_refused_before_any_work(link, job_file, outside, tmp_path,
                                                              monkeypatch):
    out = tmp_path / "out"
    (out / link).parent.mkdir(parents=True, exist_ok=True)
    (out / link).symlink_to(outside, target_is_directory=True)
    before = files(out)
    start = time.monotonic()
    status, said = batch_here(job_file, out, monkeypatch)
    assert (status, said) == (2, [f"renderer: {out}: {link} is a symbolic link; batch writes "
                                  f"only inside its output folder, through no link: remove the "
                                  f"link or give another --out"])
    assert time.monotonic() - start < 5
    assert files(outside) == {"victim.txt"} and files(out) == before     # no lock left either


def test_a_link_made_after_the_plan_is_refused_before_the_write(job_file, outside, tmp_path):
    out = tmp_path / "out"
    plan = batch_run.plan_job(read_job(job_file), out)
    out.mkdir()
    (out / "items").symlink_to(outside, target_is_directory=True)
    with pytest.raises(UserError, match="items is a symbolic link"):
        batch_run.run_plan(plan, InProcessExecutor(), progress=False)
    assert files(outside) == {"victim.txt"}


# -- manifest records that leave --out --------------------------------------------------------

def _tamper(out: Path, outside: Path, how: str) -> None:
    """Give KEYS[0]'s record a path it must not follow; its SHA-256 the target's, so that a
    driver that read it would count the record."""
    folder = out / "items" / KEYS[0]
    victim = outside / "victim.txt"
    victim_sha = hashlib.sha256(victim.read_bytes()).hexdigest()
    extra = {"../../outside/victim.txt": victim_sha, "absolute": victim_sha,
             "/etc/shadow": "0" * 64, "/dev/zero": "0" * 64}
    path, sha = how, extra.get(how)
    if how == "absolute":
        path = str(victim)
    elif how == "fifo":
        os.mkfifo(folder / "fifo")
        path, sha = f"items/{KEYS[0]}/fifo", "0" * 64
    elif how == "link to a file outside":
        (folder / "link").symlink_to(victim)
        path, sha = f"items/{KEYS[0]}/link", victim_sha
    lines_ = (out / MANIFEST).read_text().splitlines()
    for index, line in enumerate(lines_[1:], 1):
        record = json.loads(line)
        if record["key"] != KEYS[0]:
            continue
        if how == "the item's own file a link":          # its first path, as the job names it
            image = out / record["outputs"][0]["path"]
            image.unlink()
            image.symlink_to(victim)
            record["outputs"][0]["sha256"] = victim_sha
        else:
            record["outputs"].append({"path": path, "sha256": sha, "pixels_sha256": None})
        lines_[index] = json.dumps(record)
    (out / MANIFEST).write_text("\n".join(lines_) + "\n")


@pytest.mark.parametrize("how", ["../../outside/victim.txt", "absolute", "/etc/shadow",
                                 "/dev/zero", "fifo", "link to a file outside",
                                 "the item's own file a link"])
def test_a_record_naming_a_file_outside_out_or_not_a_file_is_dropped_unread(
        how, job_file, finished, outside, tmp_path, monkeypatch):
    out = copy(finished, tmp_path)
    _tamper(out, outside, how)
    status, said = batch_here(job_file, out, monkeypatch)
    never = {os.path.realpath(outside / "victim.txt"), "/etc/shadow", "/dev/zero",
             os.path.realpath(out / "items" / KEYS[0] / "fifo")}
    assert not never & set(OPENED), "a path the record names was opened"
    assert status == 0
    assert said[0] == (f"renderer: warning: {out / MANIFEST}: 1 record names a file outside "
                       f"the output folder or not a regular file; dropped unread, their items "
                       f"are rendered again")
    assert said[1].startswith("renderer batch: 2 items: 1 rendered, 1 already complete, 0 failed")
    assert all(CANARY not in line for line in said)
    assert [o["sha256"] for o in records(out)[KEYS[0]]["outputs"]] == \
        [o["sha256"] for o in records(finished)[KEYS[0]]["outputs"]]       # redone, as before
    assert files(outside) == {"victim.txt"} and (outside / "victim.txt").read_text() == CANARY


@pytest.mark.parametrize("key", [["a"], {"k": 1}, 5, None])
def test_a_record_whose_key_is_not_a_string_is_dropped(key, job_file, finished, tmp_path,
                                                       monkeypatch):
    """Found by tests/test_fuzz.py (gen_manifests): a record's key of a list was looked up in a
    dict, a TypeError traceback. Such a record counts for nothing; its item is rendered again."""
    out = copy(finished, tmp_path)
    header, *lines_ = (out / MANIFEST).read_text().splitlines()
    record = json.loads(lines_[0])
    record["key"] = key
    (out / MANIFEST).write_text("\n".join([header, json.dumps(record), *lines_[1:]]) + "\n")
    status, said = batch_here(job_file, out, monkeypatch)
    assert status == 0, said
    assert any(line.startswith("renderer batch: 2 items: 1 rendered, 1 already complete, 0 failed")
               for line in said), said
    assert set(records(out)) == set(KEYS)


@pytest.mark.parametrize("line", ['{"render_ms": NaN}', '{"render_ms": -Infinity}',
                                  '{"render_ms": ' + "[" * 100_000 + "]" * 100_000 + "}"])
def test_a_record_that_is_not_json_as_written_is_dropped(line, job_file, finished, tmp_path,
                                                         monkeypatch):
    """Found by tests/test_fuzz.py (gen_manifests): a record holding NaN (Python's parser takes
    it) was kept, and rewriting the manifest for another dropped record raised ValueError
    (to_json writes no NaN), a traceback. Deep nesting raised RecursionError."""
    out = copy(finished, tmp_path)
    header, first, second = (out / MANIFEST).read_text().splitlines()
    first = first[:-1] + ", " + line[1:]                    # the record, with one key more
    (out / MANIFEST).write_text("\n".join([header, first, second, "{cut"]) + "\n")
    status, said = batch_here(job_file, out, monkeypatch)
    assert status == 0, said
    assert any(line.startswith("renderer batch: 2 items: 1 rendered, 1 already complete, 0 failed")
               for line in said), said
    assert set(records(out)) == set(KEYS)


@pytest.mark.parametrize("kind", ["fifo", "link"])
def test_a_manifest_that_is_not_a_regular_file_is_refused_unread(kind, job_file, outside,
                                                                 tmp_path, monkeypatch):
    out = tmp_path / "out"
    out.mkdir()
    if kind == "fifo":
        os.mkfifo(out / MANIFEST)
        reason = "is a named pipe (FIFO), not a regular file; a manifest must be one"
    else:
        (out / MANIFEST).symlink_to(outside / "victim.txt")
        reason = "is a symbolic link, not a batch manifest; give another --out"
    status, said = batch_here(job_file, out, monkeypatch)
    assert (status, said) == (2, [f"renderer: {show_path(out / MANIFEST)}: {reason}"])
    assert files(out) == {MANIFEST} and files(outside) == {"victim.txt"}


# -- one driver per folder --------------------------------------------------------------------

def test_a_second_driver_is_refused_naming_the_first(job_file, tmp_path, monkeypatch):
    out = tmp_path / "out"
    with locked(out):                                 # the first driver, in this process
        holder = json.loads((out / LOCK_NAME).read_text())
        status, said = batch_here(job_file, out, monkeypatch)
        assert files(out) == {LOCK_NAME}
    assert holder["pid"] == os.getpid()
    started = time.strftime("%Y-%m-%d %H:%M:%S UTC", time.gmtime(holder["started"]))
    assert (status, said) == (2, [
        f"renderer: {out}: another `renderer batch` is writing in this folder (pid "
        f"{os.getpid()} on {holder['host']}, since {started}); wait for it to end, or give "
        f"another --out"])
    assert not out.exists()                           # made for the lock, removed with it


@pytest.mark.parametrize("kind", ["folder", "socket", "fifo"])
def test_a_lock_file_that_is_not_a_regular_file_is_the_users_one_line(kind, job_file, tmp_path,
                                                                       monkeypatch):
    """Found by tests/test_fuzz.py (gen_manifests): a folder or a socket where the lock file
    goes was a system failure (status 1, "cannot make the lock file ...: is a directory"),
    a FIFO the user's (status 2): each is something in the user's folder, status 2."""
    import socket
    out = tmp_path / "out"
    out.mkdir()
    if kind == "folder":
        (out / LOCK_NAME).mkdir()
    elif kind == "fifo":
        os.mkfifo(out / LOCK_NAME)
    else:
        with socket.socket(socket.AF_UNIX) as sock:
            sock.bind(str(out / LOCK_NAME))
    status, said = batch_here(job_file, out, monkeypatch)
    assert (status, said) == (2, [f"renderer: {out}: {LOCK_NAME} is not a regular file; "
                                  f"remove it"])
    assert files(out) == {LOCK_NAME}


def test_the_lock_goes_when_a_driver_fails(job_file, finished, tmp_path, monkeypatch):
    out = copy(finished, tmp_path)
    header, *rest = (out / MANIFEST).read_text().splitlines()
    (out / MANIFEST).write_text("\n".join([header.replace('"job": "', '"job": "0'), *rest]) + "\n")
    status, said = batch_here(job_file, out, monkeypatch)
    assert status == 2 and len(said) == 1 and "holds another job's manifest" in said[0]
    assert LOCK_NAME not in files(out)
    with locked(out):                                 # free again
        pass


def driver(job: Path, out: Path) -> subprocess.Popen:
    return subprocess.Popen([*WITHOUT_RAY, "batch", str(job), "--out", str(out)], cwd=ROOT,
                            stdout=subprocess.PIPE, stderr=subprocess.PIPE, text=True)


def wait_for_records(out: Path, count: int, process: subprocess.Popen) -> int:
    end = time.monotonic() + PROCESS_TIMEOUT_S
    while time.monotonic() < end and process.poll() is None:
        with contextlib.suppress(FileNotFoundError):
            if len((out / MANIFEST).read_text().splitlines()) > count:
                return count
        time.sleep(0.01)
    raise AssertionError(f"the job ended or stalled before {count} records: {process.poll()}")


def job_of(views: int, tmp_path_factory) -> Path:
    path = tmp_path_factory.mktemp("long") / f"orbit-{views}.toml"
    path.write_text(JOB.format(views=views))
    return path


@pytest.fixture(scope="module")
def long_job(tmp_path_factory) -> Path:
    """40 items: about a second in one process, enough to interrupt mid-job."""
    return job_of(40, tmp_path_factory)


@pytest.fixture(scope="module")
def longer_job(tmp_path_factory) -> Path:
    """400 items: still running while a second driver starts (it is interrupted)."""
    return job_of(400, tmp_path_factory)


def interrupted(job: Path, out: Path, after: int, meanwhile=lambda command: None):
    """A driver of `job` sent SIGINT once `after` records are in: (its returncode, its
    stderr, what meanwhile(the driver's Popen) returned, called just before the signal)."""
    command = driver(job, out)
    try:
        wait_for_records(out, after, command)
        found = meanwhile(command)
        command.send_signal(signal.SIGINT)
        _, stderr = command.communicate(timeout=PROCESS_TIMEOUT_S)
    finally:
        command.kill()
    return command.returncode, stderr, found


@pytest.mark.slow
def test_two_drivers_at_once_the_second_refuses_in_one_line(longer_job, tmp_path):
    out = tmp_path / "out"
    start = time.monotonic()
    status, _, (first, second) = interrupted(longer_job, out, 2, lambda command: (
        command.pid, subprocess.run([*WITHOUT_RAY, "batch", str(longer_job), "--out", str(out)],
                                    cwd=ROOT, capture_output=True, text=True,
                                    timeout=PROCESS_TIMEOUT_S)))
    assert time.monotonic() - start < 60
    assert second.returncode == 2 and second.stdout == ""
    said = lines(second.stderr)
    assert len(said) == 1 and said[0].startswith(
        f"renderer: {out}: another `renderer batch` is writing in this folder (pid {first} on ")
    assert "Traceback" not in second.stderr
    assert status == 130 and LOCK_NAME not in files(out)


# -- Ctrl-C -----------------------------------------------------------------------------------

def test_ctrl_c_in_this_process_says_how_many_items_are_done(job_file, finished, tmp_path,
                                                             monkeypatch):
    # The default run's hold on the line (the signal itself: the slow tests below).
    out = copy(finished, tmp_path)
    (out / "items" / KEYS[1] / "image.png").unlink()

    def interrupt(self, item):
        raise KeyboardInterrupt
    monkeypatch.setattr(ItemWorker, "render", interrupt)
    status, said = batch_here(job_file, out, monkeypatch)
    assert (status, said) == (130, ["renderer: interrupted; 1 of 2 items done; run the same "
                                    "command to resume"])
    assert LOCK_NAME not in files(out) and not [f for f in files(out) if f.endswith(".tmp")]


def test_ctrl_c_while_an_item_is_written_ends_the_calls_before_the_executor_closes(
        job_file, tmp_path, monkeypatch):
    # The interrupt lands in the loop that writes, outside the executor's generator: the
    # generator is closed there (its calls cancelled, Ray's actors killed) before the executor
    # closes, not when the exception is freed (on Ray, the calls killed with the disconnected
    # driver's actors were retried, and Ray said so on stdout).
    events = []

    class Watched(executor.InProcessExecutor):
        def map(self, factory, batches):
            try:
                yield from super().map(factory, batches)
            finally:
                events.append("calls ended")

        def close(self):
            events.append("executor closed")

    def interrupt(self, item, result, *rest):
        raise KeyboardInterrupt
    monkeypatch.setattr(executor, "open_executor", lambda *args: Watched())
    monkeypatch.setattr(batch_run._Writer, "write", interrupt)
    status, said = batch_here(job_file, tmp_path / "out", monkeypatch)
    assert (status, said) == (130, ["renderer: interrupted; 0 of 2 items done; run the same "
                                    "command to resume"])
    assert events == ["calls ended", "executor closed"]


@pytest.mark.slow
def test_ctrl_c_mid_job_is_one_line_and_status_130_then_the_job_resumes(long_job, tmp_path):
    out = tmp_path / "out"
    status, stderr, _ = interrupted(long_job, out, 3)
    done = len(records(out))
    assert 3 <= done < 40 and status == 130, stderr
    said = [line for line in lines(stderr) if "Ray is not installed" not in line]
    assert said == [f"renderer: interrupted; {done} of 40 items done; run the same command to "
                    f"resume"]
    written = {f"items/{key}/image.png" for key in records(out)}
    assert files(out) - {f for f in files(out) if not f.endswith(".png")} == written  # no .tmp
    assert not [f for f in files(out) if f.endswith(".tmp")] and LOCK_NAME not in files(out)
    again = subprocess.run([*WITHOUT_RAY, "batch", str(long_job), "--out", str(out)], cwd=ROOT,
                           capture_output=True, text=True, timeout=PROCESS_TIMEOUT_S)
    assert again.returncode == 0, again.stderr
    assert f"{40 - done} rendered, {done} already complete, 0 failed" in again.stderr
    assert len(records(out)) == 40
