"""The memory limit holds for the whole command (renderer/core/memory.py): a mesh too big for
the command is refused once it is parsed, before it is built, and a command let through stays
under its --max-memory, loading included. Measured in a new process: its peak resident memory
(renderer/study/peak_memory.py: VmHWM, the kernel's high-water mark of that process alone).

The large cases (a generated 5,005,448-triangle PLY, and every method and backend run under
a limit equal to their own estimate) are slow; benchmarks/bench_memory.py prints the same
figures for larger scenes."""

import pytest

from renderer.core import memory
from renderer.methods import METHODS
from renderer.study.peak_memory import grid_scene, measure_command


def test_a_mesh_too_big_for_the_command_is_refused_before_it_is_built(tmp_path, monkeypatch, capsys):
    """Building 20,000 triangles fits 330 MiB; ray tracing them on the GPU does not: refused
    once the file is parsed, its crease normals never made, nothing written."""
    from renderer import cli
    from renderer.core import meshio
    scene, triangles = grid_scene(tmp_path, 100)
    monkeypatch.setattr(meshio, "_crease", lambda *a: pytest.fail("built"))
    out = tmp_path / "out.png"
    assert cli.main(["render", str(scene), "--method", "raytrace", "--size", "64x48",
                     "--max-memory", "330M", "-o", str(out)]) == 2
    need = memory.raytrace_need((64, 48), ["gpu"], 1).bytes_for(triangles)
    assert capsys.readouterr().err.splitlines() == [
        f"renderer: {scene}: objects[0].mesh.file: {tmp_path / 'grid.ply'}: ray tracing at "
        f"64x48, 1 spp (20,000 triangles so far) on gpu needs about {memory.show(need)} of "
        f"memory, over the limit of 330 MiB (set by --max-memory)"]
    assert not out.exists()


def test_the_plan_counts_every_mesh_of_the_scene():
    """Two objects' triangles together: the second is refused when both are over."""
    tally = memory.TriangleTally()
    need = memory.raster_need((64, 48), ["gpu"])
    allowed = need.bytes_for(1000)
    with memory.limit_set(allowed), memory.planned(need):
        assert tally.add(600) is None
        assert tally.add(400, shape=True) is None              # shapes count for the rasteriser
        assert "(1,001 triangles so far)" in tally.add(1)
    traced = memory.raytrace_need((64, 48), ["gpu"], 1)
    with memory.limit_set(traced.bytes_for(600)), memory.planned(traced):
        tally = memory.TriangleTally()
        assert tally.add(600) is None
        assert tally.add(10_000, shape=True) is None            # the ray tracer's: meshes only


@pytest.mark.slow
def test_five_million_triangles_are_refused_with_the_peak_under_the_limit(tmp_path):
    """The case of the issue: a 5,005,448-triangle PLY (91 MiB) ray traced with --max-memory
    3G, then 5G. Before: refused after building it, at a peak of 4.4 GiB (over 3G) and 28 s."""
    scene, triangles = grid_scene(tmp_path, 1582)
    assert triangles == 5_005_448
    for limit, words in (("3G", "building its 5,005,448 triangles needs about 4.8 GiB"),
                         ("5G", "ray tracing at 64x48, 1 spp (5,005,448 triangles so far) on gpu "
                                "needs about 7.2 GiB")):
        run = measure_command("render", scene, "--method", "raytrace", "--size", "64x48",
                              "--max-memory", limit, "-o", tmp_path / "out.png")
        assert run.status == 2 and len(run.stderr.splitlines()) == 1 and words in run.stderr, run.stderr
        assert run.peak < memory.parse_size(limit), (limit, memory.show(run.peak))
        assert run.seconds < 30
        assert not (tmp_path / "out.png").exists()


@pytest.mark.slow
@pytest.mark.parametrize("method,backend", [("raster", "gpu"), ("raster", "reference"),
                                            ("raytrace", "gpu"), ("raytrace", "reference")])
def test_a_command_let_through_stays_under_its_limit(tmp_path, method, backend):
    """Each method and backend on a 51,200-triangle mesh, under a limit equal to its own
    estimate (rounded up to the MiB): it renders, and its whole peak stays under (a million
    triangles: benchmarks/bench_memory.py)."""
    scene, triangles = grid_scene(tmp_path, 160)
    need = METHODS[method].need((160, 120), [backend], METHODS[method].options())
    limit = f"{(need.bytes_for(triangles) >> 20) + 1}M"
    run = measure_command("render", scene, "--method", method, "--backend", backend,
                          "--size", "160x120", "--max-memory", limit, "-q", "-o", tmp_path / "out.png")
    assert run.status == 0, run.stderr
    assert run.peak < memory.parse_size(limit), (limit, memory.show(run.peak))


@pytest.mark.slow
@pytest.mark.parametrize("method", ["raster", "raytrace"])
def test_a_texture_let_through_stays_under_its_limit(tmp_path, method):
    """A 2048 x 2048 texture's decode (TEXTURE_BYTES_PER_TEXEL, beside the process) is the
    command's largest step: under a limit equal to it, the GPU renders, under the limit."""
    from renderer.core.textures import TEXTURE_BYTES_PER_TEXEL
    from renderer.study.peak_memory import texture_scene
    scene = texture_scene(tmp_path, 2048)
    decode = memory.PROCESS_BYTES + 2048 * 2048 * TEXTURE_BYTES_PER_TEXEL
    limit = f"{(decode >> 20) + 1}M"
    run = measure_command("render", scene, "--method", method, "--size", "160x120",
                          "--max-memory", limit, "-q", "-o", tmp_path / "out.png")
    assert run.status == 0, run.stderr
    assert run.peak < memory.parse_size(limit), (limit, memory.show(run.peak))
    refused = measure_command("render", scene, "--method", method, "--size", "160x120",
                              "--max-memory", f"{(decode >> 20) - 1}M", "-o", tmp_path / "no.png")
    assert refused.status == 2 and "a 2048 x 2048 texture needs about 640 MiB" in refused.stderr
    assert refused.peak < 256 << 20            # refused from the header, nothing decoded
