"""A job's items (renderer/batch/items.py): expansion in file order, stable keys, seeds from
(job seed, key) only, the job's identity; read from job files (renderer/batch/job_file.py)."""

import re
from pathlib import Path

import pytest

from renderer.batch.items import CameraSpec, expand, item_seed, job_identity
from renderer.batch.job_file import read_job
from renderer.core.scene import Camera
from renderer.errors import UserError

REPO = Path(__file__).resolve().parents[1]

SWEEP_JOB = """
name = "sweep"
seed = 7
size = [32, 24]

[[scenes]]
scene = "classic"
cameras = { orbit = { views = 3, elevation = 10 } }

[[scenes]]
scene = "sphere"
name = "ball"
cameras = { poses = [{ eye = [0, 0, 5], look = [0, 0, 0] }, { eye = [5, 0, 0], look = [0, 0, 0], up = [0, 0, 1] }] }
sweep = { "materials.red_plastic.kd" = [[1, 0, 0], [0, 1, 0]] }

[[settings]]
name = "flat"
shading = "flat"

[[settings]]
name = "rt"
method = "raytrace"
samples = 4
pattern = "jittered"
"""


def job_from(tmp_path, text, name="job.toml"):
    path = tmp_path / name
    path.write_text(text)
    return read_job(path)


def keys(job):
    return [item.key for item in expand(job)]


def test_seed_is_the_first_four_bytes_of_sha256_of_seed_and_key_little_endian():
    # printf '1/a/camera-000/sweep-000/raster' | sha256sum -> 7baa2a4f...: 0x4f2aaa7b
    assert item_seed(1, "a/camera-000/sweep-000/raster") == 0x4F2AAA7B
    # printf '7/classic/orbit-002/sweep-001/rt' | sha256sum -> 64677c85...: 0x857c6764
    assert item_seed(7, "classic/orbit-002/sweep-001/rt") == 0x857C6764


def test_items_are_scenes_then_cameras_then_sweep_points_then_settings(tmp_path):
    job = job_from(tmp_path, SWEEP_JOB)
    assert keys(job) == [
        "classic/orbit-000/sweep-000/flat", "classic/orbit-000/sweep-000/rt",
        "classic/orbit-001/sweep-000/flat", "classic/orbit-001/sweep-000/rt",
        "classic/orbit-002/sweep-000/flat", "classic/orbit-002/sweep-000/rt",
        "ball/pose-000/sweep-000/flat", "ball/pose-000/sweep-000/rt",
        "ball/pose-000/sweep-001/flat", "ball/pose-000/sweep-001/rt",
        "ball/pose-001/sweep-000/flat", "ball/pose-001/sweep-000/rt",
        "ball/pose-001/sweep-001/flat", "ball/pose-001/sweep-001/rt"]
    items = expand(job)
    assert [item.seed for item in items] == [item_seed(7, key) for key in keys(job)]
    assert items[0].files == ("items/classic/orbit-000/sweep-000/flat/image.png",)
    assert items[8].scene.overrides == (("materials.red_plastic.kd", [0, 1, 0]),)
    assert items[6].scene.digest != items[8].scene.digest          # another sweep point
    assert items[6].scene.digest == items[10].scene.digest         # another pose only
    assert (items[0].setting.options.shading, items[1].setting.options.samples) == ("flat", 4)


def test_a_scene_without_cameras_or_sweep_has_one_item_per_setting_with_fixed_key_parts(tmp_path):
    job = job_from(tmp_path, '[[scenes]]\nscene = "sphere"\n', name="plain.toml")
    (item,) = expand(job)
    assert (job.name, job.seed, item.key, item.setting.size) == (
        "plain", 0, "sphere/camera-000/sweep-000/raster", (640, 480))
    assert item.camera == CameraSpec("camera")


def test_a_scene_file_is_found_beside_the_job_and_named_by_its_stem(tmp_path):
    scene = (REPO / "assets" / "scenes" / "sphere.toml").read_text()
    (tmp_path / "scenes").mkdir()
    (tmp_path / "scenes" / "my ball.toml").write_text(scene)
    job = job_from(tmp_path, '[[scenes]]\nscene = "scenes/my ball.toml"\n')
    assert keys(job) == ["my_ball/camera-000/sweep-000/raster"]
    assert expand(job)[0].scene.path == str((tmp_path / "scenes" / "my ball.toml").resolve())


def test_animation_frames_open_the_shutter_at_frame_times_step_for_the_exposure(tmp_path):
    job = job_from(tmp_path, '[[scenes]]\nscene = "motion_blur"\n'
                             'cameras = { animation = { frames = 3, step = 0.5, exposure = 0.25 } }\n'
                             '[[settings]]\nmethod = "raytrace"\n')
    assert keys(job) == [f"motion_blur/frame-00{t}/sweep-000/raytrace" for t in range(3)]
    assert [item.camera.shutter for item in expand(job)] == [(0.0, 0.25), (0.5, 0.75), (1.0, 1.25)]
    base = Camera(shutter=(0.0, 1.0))
    assert expand(job)[2].camera.camera(base).shutter == (1.0, 1.25)


def test_a_pose_keeps_the_scenes_up_unless_it_gives_one():
    base = Camera(eye=(0.0, 0.0, 5.0), look=(0.0, 0.0, 0.0), up=(0.0, 1.0, 0.0), fov_y=30.0)
    pose = CameraSpec("pose", 0, eye=(1.0, 2.0, 3.0), look=(0.0, 0.0, 0.0))
    assert pose.camera(base) == Camera(eye=(1.0, 2.0, 3.0), look=(0.0, 0.0, 0.0),
                                       up=(0.0, 1.0, 0.0), fov_y=30.0)
    tilted = CameraSpec("pose", 1, eye=(1.0, 2.0, 3.0), look=(0.0, 0.0, 0.0), up=(0.0, 0.0, 1.0))
    assert tilted.camera(base).up == (0.0, 0.0, 1.0)


def test_dotted_sweep_keys_are_key_paths_and_the_first_varies_slowest(tmp_path):
    job = job_from(tmp_path, '[[scenes]]\nscene = "depth_of_field"\n'
                             '[scenes.sweep]\ncamera.aperture = [0.0, 0.1]\n'
                             '"camera.focus_distance" = [4.0, 6.0, 8.0]\n'
                             '[[settings]]\nmethod = "raytrace"\n')
    points = [dict(item.scene.overrides) for item in expand(job)]
    assert points == [{"camera.aperture": a, "camera.focus_distance": f}
                      for a in (0.0, 0.1) for f in (4.0, 6.0, 8.0)]


def test_adding_an_item_keeps_the_others_seeds_but_changes_the_jobs_identity(tmp_path):
    one = job_from(tmp_path, '[[scenes]]\nscene = "sphere"\ncameras = { orbit = { views = 2 } }\n')
    two = job_from(tmp_path, '[[scenes]]\nscene = "sphere"\ncameras = { orbit = { views = 2 } }\n'
                             '[[scenes]]\nscene = "classic"\n')
    assert [(i.key, i.seed) for i in expand(one)] == [(i.key, i.seed) for i in expand(two)][:2]
    assert job_identity(one, expand(one)) != job_identity(two, expand(two))
    again = job_from(tmp_path, '[[scenes]]\nscene = "sphere"\ncameras = { orbit = { views = 2 } }\n')
    assert job_identity(one, expand(one)) == job_identity(again, expand(again))


@pytest.mark.parametrize("change", ['seed = 2\n', 'size = [64, 48]\n'])
def test_the_jobs_seed_and_settings_are_part_of_its_identity(tmp_path, change):
    text = '[[scenes]]\nscene = "sphere"\n'
    base, changed = job_from(tmp_path, text), job_from(tmp_path, change + text)
    assert job_identity(base, expand(base)) != job_identity(changed, expand(changed))


def test_the_example_job_is_small_and_expands(tmp_path):
    job = read_job(REPO / "assets" / "jobs" / "orbit.toml")
    assert len(expand(job)) == 16
    assert {item.setting.method for item in expand(job)} == {"raster", "raytrace"}


def test_docs_batch_format_lists_every_key_the_reader_knows_and_no_other():
    from renderer.batch import job_file
    text = (REPO / "docs" / "batch-format.md").read_text()
    cells = re.findall(r"^\| `([^|]*?)` ", text, re.M)          # first cells of table rows
    documented = {re.match(r"\[*(?:[a-z]+\.)?([a-z_]+)", cell)[1] for cell in cells}
    known = {*job_file.TOP_KEYS, *job_file.SCENE_KEYS, *job_file.CAMERA_KINDS, *job_file.SETTING_KEYS,
             *job_file.OUTPUT_KEYS, *job_file.DEPTH_KEYS}
    assert documented == known


def test_a_scene_path_is_relative_to_the_job_file_not_the_working_folder(tmp_path, monkeypatch):
    (tmp_path / "here").mkdir()
    (tmp_path / "here" / "ball.toml").write_text((REPO / "assets" / "scenes" / "sphere.toml").read_text())
    (tmp_path / "jobs").mkdir()
    monkeypatch.chdir(tmp_path / "here")
    with pytest.raises(UserError) as refused:
        job_from(tmp_path / "jobs", '[[scenes]]\nscene = "ball.toml"\n')
    assert refused.value.line() == (f"{tmp_path / 'jobs' / 'job.toml'}: scenes[0].scene: "
                                    f"{tmp_path / 'jobs' / 'ball.toml'}: scene file not found")
