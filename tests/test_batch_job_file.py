"""`renderer batch` refuses a bad job file, or an --out it must not write into, with one line
naming the file, the key and the reason, exit status 2, before anything is written
(renderer/batch/job_file.py, renderer/batch/manifest.py; docs/bad-input.md)."""

import json

import pytest

import renderer.cluster.executor as executor

SPHERE = '[[scenes]]\nscene = "sphere"\n'

# (job file, the line after "renderer: job.toml: ")
MISTAKES = {
    "unknown key": ('sedd = 1\n' + SPHERE, "sedd: unknown key; did you mean 'seed'?"),
    "TOML syntax": ('[[scenes]\nscene = "sphere"\n', "TOML syntax error at line 1, column 9: "
                    "Expected ']]' at the end of an array declaration"),
    "no scenes": ('name = "x"\n', "scenes: a job needs at least one [[scenes]] table (scene = "
                  "NAME or FILE)"),
    "no scene": ('[[scenes]]\nname = "x"\n', "scenes[0]: needs scene = NAME (a built-in scene) "
                 "or FILE (relative to the job file)"),
    "scene key": (SPHERE + 'camera = {}\n', "scenes[0].camera: unknown key; did you mean 'cameras'?"),
    "orbit views": (SPHERE + 'cameras = { orbit = { views = 0 } }\n',
                    "scenes[0].cameras.orbit.views: must be >= 1, got 0"),
    "orbit views type": (SPHERE + 'cameras = { orbit = { views = 2.5 } }\n',
                         "scenes[0].cameras.orbit.views: expected an integer, got a number (2.5)"),
    "orbit elevation": (SPHERE + 'cameras = { orbit = { views = 2, elevation = 95 } }\n',
                        "scenes[0].cameras.orbit.elevation: must be between -89 and 89 degrees, got 95"),
    "two camera kinds": (SPHERE + 'cameras = { orbit = { views = 2 }, poses = [] }\n',
                         "scenes[0].cameras: expected one of orbit, poses, animation, got orbit, poses"),
    "pose": (SPHERE + 'cameras = { poses = [{ eye = [1, 2, 3], look = [1, 2, 3] }] }\n',
             "scenes[0].cameras.poses[0].look: is the same point as scenes[0].cameras.poses[0].eye; "
             "the camera needs eye - look to be a direction"),
    "raster animation": ('[[scenes]]\nscene = "motion_blur"\ncameras = { animation = { frames = 4 } }\n',
                         "scenes[0].cameras.animation: an animation is the ray tracer's (motion during "
                         "the shutter; the rasteriser draws time 0), but setting 'raster' is method raster"),
    "still animation": (SPHERE + 'cameras = { animation = { frames = 4 } }\n[[settings]]\nmethod = "raytrace"\n',
                        "scenes[0].cameras.animation: nothing in the scene moves (no object has a "
                        "velocity or angular_velocity): every frame would be the same"),
    "sweep value": (SPHERE + 'sweep = { "materials.red_plastic.kd" = [[1, 0, 0], [-1, 0, 0]] }\n',
                    "scenes[0].sweep: materials.red_plastic.kd = [-1, 0, 0]: {sphere}: "
                    "materials.red_plastic.kd: must be >= 0 in every component, item 0 is -1"),
    "sweep key": (SPHERE + 'sweep = { "camera.fovy" = [30] }\n', "scenes[0].sweep: camera.fovy = 30: "
                  "{sphere}: camera.fovy: unknown key; did you mean 'fov_y'?"),
    "sweep not a list": (SPHERE + 'sweep = { "camera.fov_y" = 30 }\n', "scenes[0].sweep.camera.fov_y: "
                         "expected a list of the values to sweep, got an integer (30)"),
    "setting names": (SPHERE + '[[settings]]\nmethod = "raster"\n[[settings]]\nname = "raster"\n',
                      "settings[1].name: the setting name 'raster' is already settings[0]'s; give "
                      "each its own name"),
    "scene names": (SPHERE + SPHERE, "scenes[1].name: the scene name 'sphere' is already "
                    "scenes[0]'s; give each its own name"),
    "a name that is a path": (SPHERE + 'name = "../up"\n', "scenes[0].name: '../up' cannot name a "
                              "folder: use letters, digits, '.', '_' and '-' (at most 100, starting "
                              "with a letter or digit)"),
    "ray option for raster": (SPHERE + '[[settings]]\nsamples = 4\n',
                              'settings[0].samples: is for method raytrace, not raster'),
    "adaptive samples": (SPHERE + '[[settings]]\nmethod = "raytrace"\npattern = "adaptive"\nsamples = 2\n',
                         "settings[0].samples: adaptive sampling needs at least 4 samples per pixel "
                         "(its first set), got 2"),
    "method": (SPHERE + '[[settings]]\nmethod = "raytrce"\n', "settings[0].method: unknown method "
               "'raytrce'; did you mean 'raytrace'? expected one of: raster, raytrace, radiosity, pathtrace"),
    "shading for the ray tracer": (SPHERE + '[[settings]]\nmethod = "raytrace"\nshading = "flat"\n',
                                   "settings[0].shading: is for method raster, not raytrace"),
    "bits": (SPHERE + '[[settings]]\noutputs = [{ format = "png8", bits = 12 }]\n',
             "settings[0].outputs[0].bits: png8 holds at most 8 bits per channel; use png16"),
    "exr transparent": (SPHERE + '[[settings]]\nbackground = "transparent"\noutputs = [{ format = "exr" }]\n',
                        "settings[0].outputs[0].format: OpenEXR's alpha is premultiplied, and the "
                        "frame's colour where nothing is drawn is the background's under alpha 0; "
                        "write format npy (straight RGBA)"),
    "output suffix": (SPHERE + '[[settings]]\noutputs = [{ format = "exr", name = "colour.png" }]\n',
                      "settings[0].outputs[0].name: 'colour.png' is written as .exr; name it colour.exr"),
    "output names": (SPHERE + '[[settings]]\noutputs = [{ format = "png8" }, { format = "png16" }]\n',
                     "settings[0].outputs[1].name: the file name 'image.png' is already "
                     "settings[0].outputs[0]'s; give each its own name"),
    "size": ('size = [0, 10]\n' + SPHERE, "size[0]: must be >= 1, got 0"),
    "too many items": (SPHERE + '[scenes.sweep]\n' + "".join(
        f'"camera.fov_y{i}" = [{", ".join(["30"] * 100)}]\n' for i in range(4)),
        "scenes[0].sweep: 100,000,000 sweep points; a job has at most 10,000 (each is a "
        "scene, built and checked before the first frame)"),
}


@pytest.fixture
def batch(cli_here, monkeypatch, tmp_path):
    """`renderer batch JOB --out DIR` in this process, without Ray."""
    monkeypatch.setattr(executor, "ray_available", lambda: False)

    def run(job_text, out="out", *options):
        (tmp_path / "job.toml").write_text(job_text)
        return cli_here("batch", "job.toml", "--out", out, *options, cwd=tmp_path)
    return run


@pytest.mark.parametrize("text, line", MISTAKES.values(), ids=MISTAKES.keys())
def test_a_job_file_mistake_is_one_line_status_2_and_nothing_written(batch, tmp_path, text, line):
    from renderer.core.builtin import resolve_scene
    result = batch(text)
    assert result.returncode == 2
    assert result.stderr.splitlines() == [
        f"renderer: job.toml: {line.replace('{sphere}', str(resolve_scene('sphere')))}"]
    assert sorted(p.name for p in tmp_path.iterdir()) == ["job.toml"]


def test_a_missing_job_file_is_one_line(cli_here, tmp_path):
    result = cli_here("batch", tmp_path / "nope.toml", "--out", tmp_path / "out")
    assert (result.returncode, result.stderr) == (2, f"renderer: {tmp_path / 'nope.toml'}: job file not found\n")


def manifest_header(**fields):
    return json.dumps({"manifest": "renderer batch", "format": 1, "job": "0" * 64,
                       "job_file": "other.toml", "name": "other", "renderer": "0.1.0",
                       "items": 3} | fields) + "\n"


@pytest.mark.parametrize("held, reason", [
    (manifest_header(), "holds another job's manifest ('other' from other.toml, 3 items); give "
                        "another --out, or remove that folder to start again"),
    ("id,value\n1,2\n", "is not a renderer batch manifest; give another --out (a new folder, or "
                        "this job's own)"),
], ids=["another job's", "not a manifest"])
def test_an_out_folder_holding_another_manifest_is_refused_and_left_alone(batch, tmp_path, held, reason):
    out = tmp_path / "out"
    out.mkdir()
    (out / "manifest.jsonl").write_text(held)
    result = batch(SPHERE)
    assert (result.returncode, result.stderr) == (2, f"renderer: out/manifest.jsonl: {reason}\n")
    assert [p.name for p in out.iterdir()] == ["manifest.jsonl"]
    assert (out / "manifest.jsonl").read_text() == held


def test_an_out_that_is_a_file_is_refused(batch, tmp_path):
    (tmp_path / "out").write_text("x")
    result = batch(SPHERE)
    assert (result.returncode, result.stderr) == (
        2, "renderer: out: is not a folder, so nothing can be written in it\n")
