"""`renderer batch` end to end, in this process (InProcessExecutor; the Ray runs are
tests/test_cluster.py's): every item's files and record, the same bytes in any item order,
resume after a lost, damaged or half-recorded item, a failed item, --compare."""

import contextlib
import io
import json
import re
import shutil

import pytest

import renderer.cluster.executor as executor
from renderer.batch import run as batch_run
from renderer.batch.job_file import read_job
from renderer.batch.manifest import MANIFEST, file_sha256
from renderer.batch.render_item import ItemWorker, pixels_sha256
from renderer.cluster.executor import InProcessExecutor
from renderer.cli import main
from renderer.core.image_formats import read_png

JOB = """
seed = 3
size = [32, 24]

[[scenes]]
scene = "sphere"
cameras = { orbit = { views = 2 } }

[[settings]]
name = "raster"
outputs = [{ format = "png8", transfer = "srgb" }, { depth = "npy" }]

[[settings]]
name = "rt"
method = "raytrace"
samples = 2
pattern = "random"
"""
KEYS = ["sphere/orbit-000/sweep-000/raster", "sphere/orbit-000/sweep-000/rt",
        "sphere/orbit-001/sweep-000/raster", "sphere/orbit-001/sweep-000/rt"]


def manifest(out):
    """(header, {key: record}) of out/manifest.jsonl."""
    header, *records = [json.loads(line) for line in (out / MANIFEST).read_text().splitlines()]
    return header, {record["key"]: record for record in records}


def hashes(out):
    return {key: [o["sha256"] for o in record["outputs"]] for key, record in manifest(out)[1].items()}


@pytest.fixture(scope="module")
def job(tmp_path_factory):
    path = tmp_path_factory.mktemp("job") / "job.toml"
    path.write_text(JOB)
    return read_job(path)


@pytest.fixture(scope="module")
def finished(job, tmp_path_factory):
    """The job run once by the command line, without Ray: (status, stderr, DIR)."""
    out = tmp_path_factory.mktemp("done") / "out"
    err = io.StringIO()
    with pytest.MonkeyPatch.context() as patch, contextlib.redirect_stderr(err):
        patch.setattr(executor, "ray_available", lambda: False)
        status = main(["batch", job.path, "--out", str(out)])
    return status, err.getvalue(), out


class WarmExecutor(InProcessExecutor):
    """In this process, with one ItemWorker kept for the whole module: its context and
    renderers, warm from earlier runs, must not change a byte (and cost no compile)."""

    worker = None

    def map(self, factory, batches):
        if WarmExecutor.worker is None:
            WarmExecutor.worker = factory()
        for index, batch in enumerate(batches):
            yield index, WarmExecutor.worker.run(batch)


@pytest.fixture(scope="module", autouse=True)
def close_warm_worker():
    yield
    if WarmExecutor.worker is not None:
        WarmExecutor.worker.close()


def rerun(job, out, say=lambda line: None, **options):
    return batch_run.run_job(job, out, WarmExecutor(), progress=False, say=say, **options)


def test_a_finished_job_run_again_renders_nothing_and_starts_no_workers(job, finished, tmp_path, monkeypatch):
    out = copy(finished, tmp_path)
    before = hashes(out)

    def no_workers(*args, **kwargs):
        raise AssertionError("a finished job opened an executor")

    monkeypatch.setattr(executor, "open_executor", no_workers)
    err = io.StringIO()
    with contextlib.redirect_stderr(err):
        status = main(["batch", job.path, "--out", str(out)])
    assert (status, err.getvalue()) == (0, "renderer batch: 4 items: all already complete, "
                                           "nothing to render\n")
    assert hashes(out) == before


def copy(finished, tmp_path):
    shutil.copytree(finished[2], tmp_path / "out")
    return tmp_path / "out"


def test_every_item_has_its_files_and_a_record_that_describes_them(finished):
    status, stderr, out = finished
    assert status == 0
    assert stderr.splitlines()[0] == ("renderer: Ray is not installed (pip install "
                                      "'checked-renderer[cluster]'); running in this process")
    assert "renderer batch: 4 items: 4 rendered, 0 already complete, 0 failed" in stderr
    summary = next(line for line in stderr.splitlines() if "4 rendered" in line)
    rendering, whole = map(float, re.search(r"in ([\d.]+) s .*; ([\d.]+) s in all, with reading "
                                            r"the job and starting and stopping the workers$", summary).groups())
    assert whole >= rendering                   # the command's whole time beside the rendering's
    header, records = manifest(out)
    assert (header["items"], header["job_file"], sorted(records)) == (4, "job.toml", KEYS)
    raster = records[KEYS[0]]
    assert [o["path"] for o in raster["outputs"]] == [f"items/{KEYS[0]}/image.png",
                                                      f"items/{KEYS[0]}/depth.npy"]
    assert raster["setting"]["name"] == "raster" and raster["camera"] == {"kind": "orbit", "index": 0, "views": 2}
    assert raster["worker"]["gl_renderer"] and raster["worker"]["pid"] > 0
    for record in records.values():
        for output in record["outputs"]:
            assert file_sha256(out / output["path"]) == output["sha256"]
    png = read_png(out / raster["outputs"][0]["path"])       # the record's pixels are the file's
    assert (png.codes.shape, png.bits) == ((24, 32, 3), (8, 8, 8))
    assert pixels_sha256(png.codes) == raster["outputs"][0]["pixels_sha256"]
    assert not list(out.rglob("*.tmp"))


def test_items_in_another_order_give_the_same_bytes(job, finished, tmp_path):
    plan = batch_run.plan_job(job, tmp_path / "out")
    plan.todo.reverse()                      # each renderer's views the other way round
    batch_run.run_plan(plan, WarmExecutor(), progress=False)
    assert hashes(tmp_path / "out") == hashes(finished[2])


def test_a_complete_folder_is_left_as_it_is(job, finished, tmp_path):
    out = copy(finished, tmp_path)
    before = (out / MANIFEST).read_bytes()
    summary = rerun(job, out)
    assert (summary.skipped, summary.done, (out / MANIFEST).read_bytes()) == (4, 0, before)


@pytest.mark.parametrize("damage", ["delete", "corrupt"])
def test_a_lost_or_damaged_file_has_only_its_item_rendered_again(job, finished, tmp_path, damage):
    out = copy(finished, tmp_path)
    path = out / "items" / KEYS[3] / "image.png"
    path.unlink() if damage == "delete" else path.write_bytes(path.read_bytes()[:-1] + b"x")
    summary = rerun(job, out)
    assert (summary.skipped, summary.done) == (3, 1)
    assert hashes(out) == hashes(finished[2])
    assert len((out / MANIFEST).read_text().splitlines()) == 5           # the old record dropped


def test_a_record_cut_short_by_a_kill_is_dropped_and_its_item_rendered_again(job, finished, tmp_path):
    out = copy(finished, tmp_path)
    text = (out / MANIFEST).read_text()
    (out / MANIFEST).write_text(text[:len(text) - 40])                   # the last line cut
    summary = rerun(job, out)
    assert (summary.skipped, summary.done) == (3, 1)
    assert (out / MANIFEST).read_text().splitlines()[:4] == text.splitlines()[:4]
    assert hashes(out) == hashes(finished[2])


def test_a_failed_item_is_said_left_out_of_the_manifest_and_tried_again(job, finished, tmp_path, monkeypatch):
    out = copy(finished, tmp_path)
    (out / "items" / KEYS[1] / "image.png").unlink()
    (out / "items" / KEYS[2] / "image.png").unlink()
    real = ItemWorker.render

    def fails_once(self, item):
        if item.key == KEYS[1]:
            raise RuntimeError("the GL went away")
        return real(self, item)
    monkeypatch.setattr(ItemWorker, "render", fails_once)
    said = []
    summary = rerun(job, out, say=said.append)
    assert (summary.done, [key for key, _ in summary.failed]) == (1, [KEYS[1]])
    assert said == [f"{KEYS[1]}: failed: RuntimeError: the GL went away"]
    assert KEYS[1] not in manifest(out)[1]
    monkeypatch.setattr(ItemWorker, "render", real)
    assert (rerun(job, out).done, hashes(out)) == (1, hashes(finished[2]))


@pytest.mark.slow
def test_compare_adds_the_reference_the_difference_and_the_figures(job, finished, tmp_path):
    out = copy(finished, tmp_path)
    summary = batch_run.run_job(job, out, InProcessExecutor(), compare=True, progress=False)
    # The records without a comparison do not count for --compare: every item is redone.
    assert summary.done == 4
    records = manifest(out)[1]
    for key in KEYS:
        names = [o["path"].rsplit("/", 2)[-2:] for o in records[key]["outputs"]]
        assert names[-3:] == [["compare", "gpu.png"], ["compare", "reference.png"], ["compare", "diff.png"]]
        assert records[key]["compare"]["passes"] is True
        assert records[key]["compare"]["method"] == key.rsplit("/", 1)[1].replace("rt", "raytrace")
    assert hashes(out)[KEYS[0]][:2] == hashes(finished[2])[KEYS[0]]      # the GPU's files unchanged
    assert rerun(job, out).done == 0                 # a compared item also counts without --compare


def test_an_item_is_what_renderer_render_writes_for_its_scene_options_and_seed(tmp_path, cli_here):
    path = tmp_path / "own.toml"
    path.write_text(JOB.replace('cameras = { orbit = { views = 2 } }\n', ''))   # the scene's camera
    job = read_job(path)
    rerun(job, tmp_path / "out")
    records = manifest(tmp_path / "out")[1]
    raster, traced = (records[f"sphere/camera-000/sweep-000/{name}"] for name in ("raster", "rt"))
    common = ("render", "sphere", "--size", "32x24", "--quiet")
    assert cli_here(*common, "--transfer", "srgb", "-o", tmp_path / "r.png").returncode == 0
    assert cli_here(*common, "--method", "raytrace", "--spp", "2", "--pattern", "random",
                    "--seed", traced["seed"], "-o", tmp_path / "t.png").returncode == 0
    for record, rendered in ((raster, "r.png"), (traced, "t.png")):
        codes = read_png(tmp_path / rendered).codes
        assert pixels_sha256(codes[..., :3]) == record["outputs"][0]["pixels_sha256"]
