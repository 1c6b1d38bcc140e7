"""A long ray-traced frame is traced in bands of rows (renderer/gpu/raytracer.py, BAND_SAMPLES):
the same image bit for bit, progress after each band, and Ctrl-C stops it after the band in
flight with one line and status 130 (issue 30: minutes with no progress and no way out)."""

import signal
import subprocess
import sys
import time

import numpy as np
import pytest

import renderer.gpu.raytracer as raytracer


@pytest.mark.parametrize("options", [dict(samples=4), dict(samples=9, pattern="adaptive"),
                                     dict(samples=4, pattern="jittered", light_samples=2)],
                         ids=["regular", "adaptive", "jittered"])
def test_bands_give_the_frame_of_one_pass(gl_contexts, monkeypatch, options):
    from renderer.core.builtin import resolve_scene
    from renderer.core.scene_file import load_scene
    scene = load_scene(resolve_scene("soft_shadows" if "light_samples" in options else "classic"))
    with raytracer.RayTracer(scene, 37, 23, context=gl_contexts["egl"], **options) as tracer:
        whole = tracer.render()
        assert len(tracer.bands()) == 1
        monkeypatch.setattr(raytracer, "BAND_SAMPLES", 37 * 9 * 4)      # a few rows a band
        seen = []
        banded = tracer.render(progress=lambda done, rows: seen.append((done, rows)))
        assert len(tracer.bands()) >= 3 and seen[-1] == (23, 23) and len(seen) == len(tracer.bands())
        assert [done for done, _ in seen] == sorted(done for done, _ in seen)
    for name in ("rgba8", "linear", "depth", "samples"):
        assert np.array_equal(getattr(whole, name), getattr(banded, name)), name


@pytest.mark.slow
def test_ctrl_c_stops_a_long_ray_traced_render_in_one_line(tmp_path):
    out = tmp_path / "long.png"
    child = subprocess.Popen([sys.executable, "-m", "renderer", "render", "classic", "--method", "raytrace",
                              "--spp", "256", "--size", "1600x1200", "-o", str(out)],
                             stdout=subprocess.PIPE, stderr=subprocess.PIPE, text=True, cwd=tmp_path)
    time.sleep(6)                                # past start-up and the compile: tracing bands
    assert child.poll() is None
    sent = time.perf_counter()
    child.send_signal(signal.SIGINT)
    _, err = child.communicate(timeout=60)
    stopped = time.perf_counter() - sent
    assert (child.returncode, err) == (130, "renderer: interrupted\n")
    assert stopped < 10 and not out.exists() and sorted(p.name for p in tmp_path.iterdir()) == []


@pytest.mark.parametrize("options", [dict(samples=4), dict(samples=9, pattern="adaptive")],
                         ids=["regular", "adaptive"])
def test_the_reference_ray_tracer_reports_progress_by_chunk(monkeypatch, options):
    """The twin traces its rays a chunk at a time (CHUNK_RAYS): it says how far it is after
    each, in rows as the GPU does, the same frame whatever the chunk."""
    import reference.raytrace.pipeline as pipeline
    from renderer.core.builtin import resolve_scene
    from renderer.core.ray_options import RayOptions
    from renderer.core.scene_file import load_scene
    from renderer.methods import open_renderer
    scene = load_scene(resolve_scene("classic"))
    with open_renderer(scene, (37, 23), method="raytrace", backend="reference",
                       options=RayOptions(**options)) as tracer:
        whole = tracer.render()
        monkeypatch.setattr(pipeline, "CHUNK_RAYS", 400)
        seen = []
        chunked = tracer.render(progress=lambda done, rows: seen.append((done, rows)))
    assert len(seen) >= 5 and seen[-1] == (23, 23) and {rows for _, rows in seen} == {23}
    assert [done for done, _ in seen] == sorted(done for done, _ in seen)
    assert np.array_equal(whole.rgba8, chunked.rgba8)
