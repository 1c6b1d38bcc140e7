"""Key-path overrides on parsed scene data (`with_overrides`), the batch runner's sweeps.

The split `load_scene` = `read_scene` + `scene_from_dict` lets a caller change the parsed
TOML in between; an override is checked by the scene reader as a file's value is.
"""

import pytest

from renderer.core.scene_file import load_scene, read_scene, scene_from_dict, with_overrides
from renderer.errors import SceneError

SCENE = """
[camera]
eye = [0, 0, 5]
look = [0, 0, 0]

[materials.red]
kd = [0.8, 0.1, 0.1]

[[objects]]
shape = { type = "sphere", centre = [0, 0, 0], radius = 1 }
material = { kd = [0.5, 0.5, 0.5] }
"""


@pytest.fixture
def scene_file(tmp_path):
    path = tmp_path / "ball.toml"
    path.write_text(SCENE)
    return path


def build(data, path):
    return scene_from_dict(data, source=str(path), base_dir=path.parent)


def test_read_scene_defaults_the_name_to_the_file_stem(scene_file):
    data, path = read_scene(scene_file)
    assert (data["name"], path) == ("ball", scene_file)
    assert build(data, path).name == load_scene(scene_file).name == "ball"


def test_overrides_set_key_paths_in_a_copy(scene_file):
    data, path = read_scene(scene_file)
    changed = with_overrides(data, {"objects[0].material.kd": [1, 0, 0],
                                    "camera.aperture": 0.25, "materials.red.n": 7}, "job.toml")
    assert data["objects"][0]["material"]["kd"] == [0.5, 0.5, 0.5]      # the original is kept
    assert "aperture" not in data["camera"]
    scene = build(changed, path)
    assert scene.objects[0].material.kd == (1.0, 0.0, 0.0)
    assert scene.camera.aperture == 0.25
    assert scene.camera.eye == load_scene(scene_file).camera.eye


def test_an_override_may_make_a_missing_table(scene_file):
    data, path = read_scene(scene_file)
    del data["camera"]
    assert build(with_overrides(data, {"camera.fov_y": 30}, "job.toml"), path).camera.fov_y == 30


@pytest.mark.parametrize("key, message", [
    ("objects[3].material.kd", "job.toml: objects: no entry [3]: the list has 1 item"),
    ("camera.eye.x", "job.toml: camera.eye: cannot set 'x' in a list of 3 items"),
    ("objects[0]material", "job.toml: objects[0]material: not a key path like "
                           "objects[0].material.kd"),
    ("[0].kd", "job.toml: [0].kd: not a key path like objects[0].material.kd"),
    ("camera..fov_y", "job.toml: camera..fov_y: not a key path like objects[0].material.kd"),
])
def test_a_path_that_cannot_be_set_is_one_line(scene_file, key, message):
    data, _ = read_scene(scene_file)
    with pytest.raises(SceneError) as info:
        with_overrides(data, {key: 1}, "job.toml")
    assert str(info.value) == message


def test_the_reader_checks_overridden_keys_and_values(scene_file):
    data, path = read_scene(scene_file)
    with pytest.raises(SceneError) as info:
        build(with_overrides(data, {"camera.aperure": 0.1}, "job.toml"), path)
    assert str(info.value) == f"{path}: camera.aperure: unknown key; did you mean 'aperture'?"
    with pytest.raises(SceneError) as info:
        build(with_overrides(data, {"objects[0].material.kd": "red"}, "job.toml"), path)
    assert str(info.value).startswith(f"{path}: objects[0].material.kd: expected")
