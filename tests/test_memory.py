"""Resource limits (renderer/core/memory.py): what a render will need is estimated before
anything is allocated and refused with one line over the limit (half of the machine's memory
unless --max-memory says otherwise); big primitives and mesh files are refused before they are
built or parsed. benchmarks/bench_memory.py holds the estimates against measured peaks."""

import numpy as np
import pytest

from renderer.core import memory
from renderer.core.builtin import assets_dir
from renderer.core.scene_file import load_scene, scene_from_dict
from renderer.errors import SceneError

MIB = 1 << 20


def test_the_estimates_by_hand():
    assert memory.gpu_bytes(1000, 1000, 0) == 128 * MIB + 32 * 10 ** 6
    assert memory.gpu_bytes(1000, 1000, 10, linear=True, samples=4) == \
        128 * MIB + (32 + 48 + 8 * 4) * 10 ** 6 + 896 * 10
    # The reference's working set is one band of at most 2^20 pixels, whatever the size:
    small, large = memory.reference_bytes(1000, 1000, 0), memory.reference_bytes(10000, 10000, 0)
    assert small == 64 * MIB + 12 * 10 ** 6 + 320 * 10 ** 6
    assert large == 64 * MIB + 12 * 10 ** 8 + 320 * (1 << 20)
    assert memory.reference_bytes(100000, 1, 0) == 64 * MIB + 12 * 100000 + 320 * 100000   # one row


def test_sizes_people_type():
    assert memory.parse_size("512M") == 512 * MIB
    assert memory.parse_size("2G") == memory.parse_size("2GiB") == memory.parse_size("2gb") == 2 << 30
    assert memory.parse_size("1.5G") == 3 << 29
    assert memory.parse_size("4096") == 4096
    for bad in ("", "two", "-1G", "0", "5X"):
        with pytest.raises(ValueError):
            memory.parse_size(bad)


def test_the_default_limit_is_half_the_machine():
    assert memory.limit() == memory.physical_memory() // 2
    with memory.limit_set(123):
        assert memory.limit() == 123
    assert memory.limit() == memory.physical_memory() // 2


def test_a_size_over_the_limit_is_refused_before_rendering(capsys, tmp_path, monkeypatch):
    from renderer import cli
    from renderer.gpu import pipeline
    monkeypatch.setattr(pipeline.GpuRenderer, "__init__", lambda *a, **k: pytest.fail("rendered"))
    out = tmp_path / "big.png"
    assert cli.main(["render", "sphere", "--size", "16384x16384", "--max-memory", "1G",
                     "-o", str(out)]) == 2
    assert capsys.readouterr().err.splitlines() == [
        "renderer: rendering sphere at 16384x16384 on gpu needs about 8.3 GiB of memory, over the "
        "limit of 1.0 GiB (set by --max-memory)"]
    assert list(tmp_path.iterdir()) == []


def test_compare_counts_both_pipelines(capsys):
    from renderer import cli
    assert cli.main(["compare", "sphere", "--size", "4096x4096", "--max-memory", "600M"]) == 2
    assert "on gpu and reference needs about" in capsys.readouterr().err


def test_a_bad_limit_is_an_argument_error(capsys):
    from renderer import cli
    assert cli.main(["render", "sphere", "--max-memory", "lots"]) == 2
    assert "argument --max-memory: expected a size such as 512M or 2G" in capsys.readouterr().err


def test_primitives_are_refused_before_they_are_built(monkeypatch):
    from renderer.core import primitives
    built = []

    def uv_sphere(radius=1.0, segments=32, rings=16):
        built.append((segments, rings))

    monkeypatch.setitem(primitives.PRIMITIVES, "uv_sphere", uv_sphere)
    big = {"primitive": "uv_sphere", "segments": 1024, "rings": 1024}     # 2,097,152 triangles
    with memory.limit_set(256 * MIB), pytest.raises(SceneError) as info:
        scene_from_dict({"objects": [{"name": "a", "mesh": big}]})
    assert info.value.line() == (
        "<dict>: objects[0].mesh: the scene's primitives up to here make up to 2,097,152 "
        "triangles: building them needs about 512 MiB of memory (704 MiB with the process's "
        "own), over the limit of 256 MiB (set by --max-memory)")
    assert built == []


def test_the_primitive_bounds_hold():
    from renderer.core.primitives import PRIMITIVES, TRIANGLES
    for name, build in PRIMITIVES.items():
        assert build().triangle_count <= TRIANGLES[name]()


def test_a_mesh_file_is_refused_before_it_is_parsed(monkeypatch):
    import trimesh
    monkeypatch.setattr(trimesh, "load", lambda *a, **k: pytest.fail("parsed"))
    bowl = assets_dir() / "meshes" / "bowl.obj"                           # 27 kB
    with memory.limit_set(100_000), pytest.raises(SceneError) as info:
        load_scene_with_mesh(bowl)
    assert info.value.line() == (
        f"<dict>: objects[0].mesh.file: {bowl}: a mesh file of 27 kB needs about 430 kB of "
        f"memory (192 MiB with the process's own), over the limit of 98 kB (set by --max-memory)")


def load_scene_with_mesh(path):
    return scene_from_dict({"objects": [{"name": "m", "mesh": {"file": str(path)}}]})


def test_the_built_in_scenes_are_far_under_the_default_limit():
    for path in sorted((assets_dir() / "scenes").glob("*.toml")):
        scene = load_scene(path)
        triangles = sum(obj.mesh.triangle_count for obj in scene.objects)
        assert memory.gpu_bytes(640, 480, triangles) + memory.reference_bytes(640, 480, triangles) \
            < min(memory.limit(), 2 << 30)
    assert np.isfinite(memory.limit())
