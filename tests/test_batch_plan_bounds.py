"""A batch job is planned in bounded time and memory (issue 30): items and scenes to build are
counted from the job file before any scene is read, a job over the limits is refused in well
under a second with its count, a sweep holds none of its points' scenes, and the job's
identity is hashed item by item, byte for byte the one-piece text's
(renderer/batch/job_file.py MAX_ITEMS, MAX_SCENES; items.py iter_items, job_identity)."""

import gc
import hashlib
import subprocess
import sys
import time
import weakref

import pytest

import renderer.batch.job_file as job_file
from renderer.batch.items import expand, item_count, iter_items, job_identity
from renderer.batch.job_file import MAX_ITEMS, MAX_SCENES, read_job
from renderer.core.jsonio import canonical_json

# renderer.cli.main in a process of its own; its peak resident memory (KiB) on the last line:
# VmHWM, the peak of this program's own memory (a new one at exec). Not ru_maxrss: Linux keeps
# through exec the peak of the process that forked it, here a pytest worker that may have grown
# past a GiB in the tests before (it read 1,018 MiB for a job refused in half a second).
MEASURED = """
import resource, sys
from renderer.cli import main


def peak_kib():
    try:
        with open("/proc/self/status") as status:
            for line in status:
                if line.startswith("VmHWM:"):
                    return int(line.split()[1])
    except OSError:
        pass
    return resource.getrusage(resource.RUSAGE_SELF).ru_maxrss


try:
    status = main(sys.argv[1:])
finally:
    print(peak_kib(), file=sys.stderr)
sys.exit(status)
"""


def measured(tmp_path, job_text: str, *args):
    """(status, stderr lines but the last, seconds, peak RSS in MiB) of `renderer batch`."""
    (tmp_path / "job.toml").write_text(job_text)
    start = time.perf_counter()
    done = subprocess.run([sys.executable, "-c", MEASURED, "batch", "job.toml", "--out", "out", *args],
                          cwd=tmp_path, capture_output=True, text=True, timeout=120)
    seconds = time.perf_counter() - start
    *lines, rss = done.stderr.splitlines()
    return done.returncode, lines, seconds, int(rss) / 1024


def orbit_job(views: int, settings: int) -> str:
    return ('size = [16, 12]\n[[scenes]]\nscene = "sphere"\n'
            f'cameras = {{ orbit = {{ views = {views} }} }}\n'
            + "".join(f'[[settings]]\nname = "s{k}"\n' for k in range(settings)))


def sweep_job(first: int, second: int, scene: str = "sphere") -> str:
    aperture = ", ".join(f"{k / first:.6f}" for k in range(first))
    fov = ", ".join(f"{30 + k / second:.6f}" for k in range(second))
    return (f'size = [16, 12]\n[[scenes]]\nscene = "{scene}"\n'
            f'sweep = {{ "camera.aperture" = [{aperture}], "camera.fov_y" = [{fov}] }}\n')


def test_a_job_of_a_million_items_is_refused_at_once_with_its_count(tmp_path):
    status, lines, seconds, rss = measured(tmp_path, orbit_job(100_000, 10))
    assert (status, lines) == (2, [f"renderer: job.toml: scenes: the job has 1,000,000 items; "
                                   f"at most {MAX_ITEMS:,}"])
    assert seconds < 10 and rss < 400          # the process, its imports and the TOML: ~1 s
    assert not (tmp_path / "out").exists()


def test_a_thousand_by_thousand_sweep_is_refused_before_any_point_is_built(tmp_path):
    status, lines, seconds, rss = measured(tmp_path, sweep_job(1000, 1000))
    assert (status, lines) == (2, [f"renderer: job.toml: scenes[0].sweep: 1,000,000 sweep points; "
                                   f"a job has at most {MAX_SCENES:,} (each is a scene, built and "
                                   f"checked before the first frame)"])
    assert seconds < 10 and rss < 400
    assert not (tmp_path / "out").exists()


def test_the_limits_are_counted_before_any_scene_is_read(tmp_path, monkeypatch):
    """A job over a limit is refused without reading or building a scene (so in well under
    a second, whatever its scenes hold); the count covers every entry together."""
    def no_scene(*args, **kwargs):
        raise AssertionError("a scene was read before the job's counts were checked")
    monkeypatch.setattr(job_file, "read_scene", no_scene)
    monkeypatch.setattr(job_file, "scene_from_dict", no_scene)
    half = sweep_job(80, 75, scene="no such scene")                      # 6,000 points each
    (tmp_path / "job.toml").write_text(half + half[half.index("[[scenes]]"):])
    start = time.perf_counter()
    with pytest.raises(job_file.UserError) as refused:
        read_job(tmp_path / "job.toml")
    assert time.perf_counter() - start < 1.0
    assert refused.value.line().endswith(
        f"scenes: the job has 12,000 scenes to build (one per entry and sweep point); at most "
        f"{MAX_SCENES:,}, each built and checked before the first frame")
    (tmp_path / "job.toml").write_text(orbit_job(50_001, 2))
    with pytest.raises(job_file.UserError, match="the job has 100,002 items; at most 100,000"):
        read_job(tmp_path / "job.toml")


def test_a_sweep_checks_every_point_and_holds_none_of_their_scenes(tmp_path, monkeypatch):
    built = []
    real = job_file.scene_from_dict

    def kept(*args, **kwargs):
        scene = real(*args, **kwargs)
        built.append(weakref.ref(scene))
        return scene
    monkeypatch.setattr(job_file, "scene_from_dict", kept)
    (tmp_path / "job.toml").write_text(sweep_job(6, 5))
    job = read_job(tmp_path / "job.toml")
    gc.collect()
    assert len(built) == 30                                     # every point built and checked
    assert [ref() for ref in built] == [None] * 30              # and none of them held
    assert len(job.scenes[0].points) == item_count(job) == 30
    assert len({point.digest for point in job.scenes[0].points}) == 30
    # a bad value in the last point still fails the job before its first frame
    (tmp_path / "job.toml").write_text(sweep_job(6, 5).replace("30.000000", "-30"))
    with pytest.raises(job_file.UserError, match=r"scenes\[0\]\.sweep: camera.aperture = 0.0, "
                                                 r"camera.fov_y = -30"):
        read_job(tmp_path / "job.toml")


def one_piece_identity(job, items) -> str:
    """The identity as it was first written: the whole canonical text, then its hash."""
    text = canonical_json({"seed": job.seed, "items": [item.describe() for item in items]})
    return hashlib.sha256(text.encode()).hexdigest()


@pytest.mark.parametrize("text", [
    'seed = 7\n' + sweep_job(3, 2) + '[[settings]]\nname = "r"\n[[settings]]\nname = "t"\n'
    'method = "raytrace"\nsamples = 4\noutputs = [{ format = "png16", transfer = "srgb" }, '
    '{ depth = "npy" }]\n',
    'seed = 18446744073709551615\n[[scenes]]\nscene = "hierarchy"\ncameras = { poses = ['
    '{ eye = [1, 2, 3], look = [0, 0, 0] }, { eye = [0.1, 1e-7, 3], look = [0, 0, 0], up = [0, 0, 1] }] }\n'
    '[[scenes]]\nscene = "sphere"\nname = "b-e"\n'
    'sweep = { "materials.red_plastic.kd" = [[1, 0, 0], [0.5, 0.25, 0.125]] }\n',
], ids=["sweep and settings", "poses and overrides"])
def test_the_streamed_identity_is_the_one_piece_texts(tmp_path, text):
    (tmp_path / "job.toml").write_text(text)
    job = read_job(tmp_path / "job.toml")
    assert job_identity(job, iter_items(job)) == one_piece_identity(job, expand(job))
    assert list(iter_items(job)) == expand(job) and item_count(job) == len(expand(job))


def test_the_example_job_keeps_its_identity():
    job = read_job("assets/jobs/orbit.toml")
    assert job_identity(job, iter_items(job)) == one_piece_identity(job, expand(job))


@pytest.mark.slow
def test_a_job_at_the_item_limit_is_planned_in_seconds_and_bounded_memory(tmp_path):
    """100,000 items (the limit) checked and planned: keys, files, output names, identity
    (~2 s and ~200 MiB here); then refused for its --out only to end it before rendering."""
    (tmp_path / "out").mkdir()
    (tmp_path / "out" / "manifest.jsonl").write_text('{"manifest": "renderer batch", "job": "other"}\n')
    status, lines, seconds, rss = measured(tmp_path, orbit_job(50_000, 2))
    assert status == 2 and len(lines) == 1 and "holds another job's manifest" in lines[0], lines
    assert seconds < 30 and rss < 600
