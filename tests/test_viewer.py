"""The window viewer (`renderer view`, renderer/viewer/viewer.py) in a real window on a virtual X
display (Xvfb): what the window shows is the headless render of the same camera and size;
the controls act on it; the scripted mode, the reference view and double/triple buffering
work end to end; without a display it says so in one line and exits with status 2."""

import json
import os
import subprocess
import sys
from dataclasses import replace

import glfw
import numpy as np
import pytest

from renderer.core.builtin import resolve_scene
from renderer.checks.compare import compare_frames
from renderer.checks.tolerance import PIPELINE_TOLERANCE
from renderer.gpu import GpuRenderer
from renderer.core.imageio import read_png
from renderer.viewer.orbit import OrbitCamera
from renderer.core.scene_file import load_scene
from renderer.checks.methods import without_shadow_maps
from renderer.viewer.viewer import SCREEN_CLEAR, Viewer

SIZE = (160, 120)


def scene(name="sphere"):
    return load_scene(resolve_scene(name))


def headless(scene_, size=SIZE, context=None):
    with GpuRenderer(scene_, *size, context=context) as gpu:
        return gpu.render(depth=False).rgba8


def assert_matches(window_rgb, headless_rgba8):
    """The pipeline's tolerance (the same as the extreme cases'): no pixel fails the ±1 px
    threshold compare, and at most 0.1 % differ by more than 2/255 in place. The window has
    no alpha to show, so both are compared opaque."""
    shown = np.concatenate([window_rgb, np.full(window_rgb.shape[:2] + (1,), 255, np.uint8)], axis=2)
    expected = headless_rgba8.copy()
    expected[..., 3] = 255
    result = compare_frames(shown, expected)
    assert PIPELINE_TOLERANCE.passes(result), (PIPELINE_TOLERANCE.failures(result), result)


# -- no display ---------------------------------------------------------------------------------
def test_without_a_display_one_line_suggests_xvfb_run_and_exits_2(tmp_path, cli):
    shot = tmp_path / "shot.png"
    result = cli("view", "sphere", "--frames", "2", "--screenshot", str(shot), display=None)
    assert result.returncode == 2
    lines = result.stderr.strip().splitlines()
    assert len(lines) == 1 and "xvfb-run" in lines[0] and "DISPLAY" in lines[0], result.stderr
    assert "Traceback" not in result.stderr and not shot.exists()


def test_a_bad_option_is_one_line_and_status_2(cli):
    result = cli("view", "sphere", "--frames", "0")
    assert result.returncode == 2 and "at least 1" in result.stderr


# -- the scripted mode, through the command line --------------------------------------------------
def test_scripted_screenshot_is_the_headless_render(x_display, tmp_path, cli):
    shot = tmp_path / "shot.png"
    result = cli("view", "sphere", "--size", "160x120", "--frames", "3", "--screenshot", str(shot),
                 display=x_display)
    assert result.returncode == 0, result.stderr
    assert "frame time median" in result.stdout and "fps" in result.stdout
    assert result.stdout.splitlines()[0].startswith("3 frames: "), result.stdout
    assert_matches(read_png(shot)[..., :3], headless(scene()))


def test_scripted_screenshot_in_the_format_its_suffix_names(x_display, tmp_path, cli):
    from PIL import Image
    shot = tmp_path / "shot.jpg"
    result = cli("view", "sphere", "--size", "160x120", "--frames", "1", "--screenshot", str(shot),
                 display=x_display)
    assert result.returncode == 0, result.stderr
    with Image.open(shot) as image:
        assert (image.format, image.mode, image.size) == ("JPEG", "RGB", (160, 120))
        pixels = np.asarray(image).astype(int)
    assert np.abs(pixels - headless(scene())[..., :3].astype(int)).mean() < 2.0     # lossy


@pytest.mark.parametrize("buffering, frames_late", [("double", 0), ("triple", 1)])
def test_orbiting_shows_the_camera_of_the_frame_on_the_screen(x_display, tmp_path, buffering,
                                                              frames_late, cli):
    """--orbit turns the camera before each frame is drawn; with triple buffering the window
    shows the frame before the last one drawn."""
    shot = tmp_path / "shot.png"
    args = ["hierarchy", "--size", "160x120", "--frames", "4", "--orbit", "10",
            "--screenshot", str(shot)]
    result = cli("view", *args, *(["--triple-buffering"] if buffering == "triple" else []),
                 display=x_display)
    assert result.returncode == 0, result.stderr
    authored = scene("hierarchy")
    orbit = OrbitCamera(authored.camera)
    for _ in range(4 - frames_late):
        orbit.orbit(10.0, 0.0)
    assert_matches(read_png(shot)[..., :3], headless(replace(authored, camera=orbit.camera)))
    if buffering == "triple":
        assert "latency" in result.stdout


def test_reference_side_by_side_shows_both_pipelines_alike(x_display, tmp_path, cli):
    shot = tmp_path / "shot.png"
    result = cli("view", "gouraud_vs_phong", "--size", "240x120", "--frames", "2", "--reference",
                 "side-by-side", "--screenshot", str(shot), display=x_display)
    assert result.returncode == 0, result.stderr
    assert "GPU vs reference" in result.stdout and "0 mismatched px" in result.stdout
    image = read_png(shot)[..., :3].astype(int)
    # Each half holds its 240x120 image at half size, letterboxed: rows 30-89; the overlay
    # (which half is which, and the figures) covers the top left down to row 44 or so.
    left, right = image[50:90, :120], image[50:90, 120:]
    assert np.abs(left - right).mean() < 1.0
    clear = np.round(np.array(SCREEN_CLEAR) * 255)
    assert (image[100:, :] == clear).all()         # the letterbox below the images


def test_scripted_reference_is_of_the_last_frames_view_when_orbiting(x_display, cli):
    result = cli("view", "sphere", "--size", "80x60", "--frames", "3", "--orbit", "15",
                 "--reference", "difference", display=x_display)
    assert result.returncode == 0, result.stderr
    assert "GPU vs reference" in result.stdout and "0 mismatched px" in result.stdout


def test_scripted_frame_count_with_the_reference_view(x_display, tmp_path, cli):
    """--frames N reports N frames with a reference view too (the wait for the reference
    before the last frame is not a frame time, but the last frame is a frame)."""
    stats = tmp_path / "stats.json"
    result = cli("view", "sphere", "--size", "80x60", "--frames", "4", "--reference",
                 "difference", "--no-vsync", "--stats", stats, display=x_display)
    assert result.returncode == 0, result.stderr
    assert result.stdout.splitlines()[0].startswith("4 frames: "), result.stdout
    summary = json.loads(stats.read_text())
    assert summary["frames"] == 4 and summary["reference"]["mismatched"] == 0


def test_reference_difference_is_a_dark_heat_map(x_display, tmp_path, cli):
    shot = tmp_path / "shot.png"
    result = cli("view", "sphere", "--size", "160x120", "--frames", "2", "--reference",
                 "difference", "--screenshot", str(shot), display=x_display)
    assert result.returncode == 0, result.stderr
    image = read_png(shot)[..., :3]
    below_overlay = image[40:]                      # the figures' panel is at the top left
    assert (below_overlay.max(axis=-1) < 100).mean() > 0.99


# -- the viewer in this process: controls and resizing -------------------------------------------
@pytest.fixture
def viewer(on_x_display):
    messages = []
    with Viewer(scene("coloured_lights"), *SIZE, on_message=messages.append) as v:
        v.messages = messages
        yield v


def press(viewer, key, mods=0):
    viewer.controls.key(key, 0, glfw.PRESS, mods)


def shown_after_a_frame(viewer):
    viewer.frame()
    viewer._compose(viewer.presenter.shown)         # the frame again, in the back buffer
    return viewer.window_image()


def test_first_frame_is_the_headless_render(viewer):
    assert_matches(shown_after_a_frame(viewer), headless(scene("coloured_lights")))


def test_shading_keys_switch_every_object(viewer):
    press(viewer, glfw.KEY_F)
    assert_matches(shown_after_a_frame(viewer), headless(scene("coloured_lights").with_shading("flat")))
    assert any("flat" in line for line in viewer.messages)
    press(viewer, glfw.KEY_G)
    assert_matches(shown_after_a_frame(viewer), headless(scene("coloured_lights").with_shading("gouraud")))


def test_light_key_turns_that_light_off(viewer):
    authored = scene("coloured_lights")
    press(viewer, glfw.KEY_1)
    lights_left = replace(authored, directional_lights=authored.directional_lights[1:]) \
        if authored.directional_lights else replace(authored, point_lights=authored.point_lights[1:])
    assert_matches(shown_after_a_frame(viewer), headless(lights_left))
    press(viewer, glfw.KEY_1)
    assert_matches(shown_after_a_frame(viewer), headless(authored))


def test_wireframe_key_draws_edges_only(viewer):
    solid = shown_after_a_frame(viewer)
    press(viewer, glfw.KEY_W)
    edges = shown_after_a_frame(viewer)
    assert viewer.gpu.wireframe
    background = np.round(np.array(scene("coloured_lights").background) * 255)
    # Edges leave most of what was covered showing the background.
    covered = (solid != background).any(axis=-1)
    still = (edges != background).any(axis=-1)
    assert still.sum() < 0.8 * covered.sum() and still.any()


def test_dragging_orbits_and_r_resets(viewer):
    start = shown_after_a_frame(viewer)
    viewer.controls.cursor(80, 60)
    viewer.controls.mouse_button(glfw.MOUSE_BUTTON_LEFT, glfw.PRESS, 0)
    viewer.controls.cursor(120, 60)
    viewer.controls.mouse_button(glfw.MOUSE_BUTTON_LEFT, glfw.RELEASE, 0)
    moved = shown_after_a_frame(viewer)
    assert np.abs(moved.astype(int) - start).mean() > 1.0
    assert_matches(moved, headless(replace(scene("coloured_lights"), camera=viewer.orbit.camera)))
    press(viewer, glfw.KEY_R)
    assert_matches(shown_after_a_frame(viewer), headless(scene("coloured_lights")))


def test_wheel_zooms_in(viewer):
    distance = np.linalg.norm(np.subtract(viewer.orbit.camera.eye, viewer.orbit.camera.look))
    viewer.controls.scroll(0.0, 2.0)
    viewer.frame()
    after = np.linalg.norm(np.subtract(viewer.orbit.camera.eye, viewer.orbit.camera.look))
    assert after < distance


def test_resizing_keeps_the_aspect_ratio_right(viewer):
    viewer.window.set_size(200, 100)
    for _ in range(20):                              # the new size arrives with the events
        viewer.frame()
        if viewer.window.framebuffer_size == (200, 100):
            break
    image = shown_after_a_frame(viewer)
    assert image.shape == (100, 200, 3) and (viewer.gpu.width, viewer.gpu.height) == (200, 100)
    assert_matches(image, headless(scene("coloured_lights"), size=(200, 100)))


def test_buffering_and_vsync_keys(viewer):
    press(viewer, glfw.KEY_B)
    for _ in range(3):
        viewer.frame()
    assert viewer.presenter.buffering == 3 and viewer.presenter.latency_ms is not None
    assert "triple buffering" in viewer.title()
    press(viewer, glfw.KEY_V)
    viewer.frame()
    assert not viewer.state.vsync and "v-sync off" in viewer.title()


def test_help_is_printed_and_drawn(viewer):
    plain = shown_after_a_frame(viewer)
    press(viewer, glfw.KEY_H)
    with_help = shown_after_a_frame(viewer)
    assert any("Esc" in line for line in viewer.messages)
    assert (with_help != plain).any(axis=-1)[:20, :40].mean() > 0.5     # a panel at the top left


def test_s_saves_a_screenshot(viewer, tmp_path, monkeypatch):
    monkeypatch.chdir(tmp_path)
    press(viewer, glfw.KEY_S)
    viewer.frame()
    saved = sorted((tmp_path / "out").glob("view-coloured_lights-*.png"))
    assert len(saved) == 1
    assert_matches(read_png(saved[0])[..., :3], headless(scene("coloured_lights")))


def test_escape_quits(viewer):
    press(viewer, glfw.KEY_ESCAPE)
    stats = viewer.run()                             # returns at once: quit was asked for
    assert viewer.state.quit and stats.frame_ms == []


# -- end to end: a user's keys and mouse, typed by xdotool -------------------------------------
def test_keys_and_mouse_end_to_end_with_xdotool(x_display, tmp_path):
    """The interactive viewer in its own process: xdotool focuses its window, types W
    (wireframe), drags with the left button (orbit), types S (screenshot) and Esc."""
    from renderer.viewer.controls import Controls, ViewState
    shot = tmp_path / "shot.png"
    env = {**os.environ, "DISPLAY": x_display}
    viewer = subprocess.Popen([sys.executable, "-m", "renderer", "view", "coloured_lights", "--size",
                               "160x120", "--screenshot", str(shot)], env=env,
                              stdout=subprocess.PIPE, stderr=subprocess.PIPE, text=True)

    def xdotool(*args):
        return subprocess.run(["xdotool", *args], env=env, check=True, capture_output=True,
                              text=True, timeout=30).stdout

    try:
        window = xdotool("search", "--sync", "--name", "renderer view: coloured_lights").split()[0]
        xdotool("windowfocus", "--sync", window)
        xdotool("key", "w")
        xdotool("mousemove", "--window", window, "--sync", "80", "60")
        xdotool("mousedown", "1")
        xdotool("mousemove", "--window", window, "--sync", "120", "60")
        xdotool("mouseup", "1")
        xdotool("key", "s")
        for _ in range(100):                          # the screenshot is taken at the next frame
            if shot.exists():
                break
            subprocess.run(["sleep", "0.1"])
        xdotool("key", "Escape")
        out, err = viewer.communicate(timeout=30)
    finally:
        if viewer.poll() is None:
            viewer.kill()
    assert viewer.returncode == 0, err
    assert "wireframe: on" in out and f"screenshot: {shot}" in out

    # The same events fed to the handlers give the camera the window must show.
    authored = scene("coloured_lights")
    orbit = OrbitCamera(authored.camera)
    controls = Controls(ViewState(), orbit, ["light"] * 4, on_message=lambda line: None)
    controls.resize(160, 120)
    controls.cursor(80, 60)
    controls.mouse_button(glfw.MOUSE_BUTTON_LEFT, glfw.PRESS, 0)
    controls.cursor(120, 60)
    controls.mouse_button(glfw.MOUSE_BUTTON_LEFT, glfw.RELEASE, 0)
    with GpuRenderer(replace(authored, camera=orbit.camera), *SIZE) as gpu:
        gpu.wireframe = True
        expected = gpu.render(depth=False).rgba8
    assert_matches(read_png(shot)[..., :3], expected)


def test_t_toggles_two_sided_lighting_for_every_object(viewer):
    press(viewer, glfw.KEY_T)
    authored = scene("coloured_lights")
    two_sided = replace(authored, objects=[replace(obj, material=replace(obj.material, two_sided=True))
                                           for obj in authored.objects])
    assert_matches(shown_after_a_frame(viewer), headless(two_sided))
    assert all(obj.material.two_sided for obj in viewer.shown.objects)


def test_a_window_opens_while_a_headless_egl_context_is_current(on_x_display, gl_contexts):
    """glfw binds a new window's GLX context as it makes it; with an EGL context still current
    GLX refused (BadAccess) and Xlib ended the process."""
    from renderer.gpu.context import activate
    activate(gl_contexts["egl"])
    with Viewer(scene("sphere"), 32, 24, on_message=lambda line: None) as viewer:
        viewer.frame()
        assert_matches(viewer.shown_image(), headless(scene("sphere"), (32, 24),
                                                      context=gl_contexts["egl"]))


def test_closing_the_window_ends_the_run(viewer):
    glfw.set_window_should_close(viewer.window._handle, True)   # what the close button does
    stats = viewer.run()
    assert stats.frame_ms == [] and not viewer.state.quit


@pytest.mark.parametrize("reference", ["off", "side-by-side"])
def test_run_reports_the_frames_it_ran(on_x_display, reference):
    """run(frames=N) swaps N frames and says N, with or without the reference view; the
    frame times are the intervals between swaps, less the one across the wait for the
    reference before the last frame."""
    with Viewer(scene("point_light_plane"), 80, 60, vsync=False, reference=reference,
                on_message=lambda line: None) as viewer:
        for frames in (1, 2, 5):
            viewer.stats = type(viewer.stats)()
            viewer._last_swap = None
            stats = viewer.run(frames=frames, orbit=3.0)
            assert stats.summary()["frames"] == frames
            assert stats.line().startswith(f"{frames} frame")
            assert stats.frames == frames
            waits = 1 if reference != "off" and frames > 1 else 0
            assert len(stats.frame_ms) == frames - 1 - waits
        assert stats.line().startswith("5 frames: frame time median")


def test_the_reference_is_asked_again_only_for_a_new_image(on_x_display):
    with Viewer(scene("point_light_plane"), *SIZE, reference="difference",
                on_message=lambda line: None) as viewer:
        viewer.run(frames=2)                          # the last frame waits for the reference
        assert viewer.figures is not None and viewer.figures["mismatched"] == 0
        for key in (glfw.KEY_W, glfw.KEY_H):          # wireframe and help: the same image
            press(viewer, key)
            viewer.frame()
        assert not viewer.background.busy and viewer.figures is not None
        press(viewer, glfw.KEY_F)                     # flat shading: a new image
        viewer.frame()
        assert viewer.figures is None                 # none yet for the view on the screen
        assert viewer.background.wait(timeout=60) is not None


# -- the ray tracer: progressive refinement ------------------------------------------------------
def test_ray_tracing_refines_while_still_and_starts_again_when_the_camera_moves(on_x_display):
    """M (or method="raytrace") traces one sample per pixel a frame into the running mean;
    the window shows the mean, the title counts its samples, a camera move starts again with
    sample 0 of the new view (the headless RayTracer's frame); M on: the path tracer's own mean
    (the headless PathTracer's frame), then the rasteriser, then the ray tracer anew."""
    from renderer.core.path_options import PathOptions
    from renderer.gpu.pathtracer import PathTracer
    from renderer.gpu.raytracer import RayTracer
    from renderer.viewer.progressive import PATTERN, SAMPLES_PER_FRAME
    messages = []
    with Viewer(scene("coloured_lights"), *SIZE, vsync=False, method="raytrace",
                on_message=messages.append) as viewer:
        viewer.run(frames=3)
        assert viewer.samples == 3 and "ray tracing: 3 spp" in viewer.title()
        assert (viewer.shown_image() == viewer.accumulator.rgba8[..., :3]).all()
        assert any(line.startswith("ray tracer ready") for line in messages)

        viewer.run(frames=2, orbit=10.0)                  # moving: one sample, the new view's
        assert viewer.samples == 1 and not viewer.idle
        moved = replace(scene("coloured_lights"), camera=viewer.orbit.camera)
        with RayTracer(moved, *SIZE, samples=SAMPLES_PER_FRAME, pattern=PATTERN) as tracer:
            expected = tracer.render(first_sample=0).rgba8[..., :3]
        assert (viewer.shown_image() == expected).all()

        tracer = viewer._tracer
        press(viewer, glfw.KEY_M)                         # radiosity (not drawn: no frame)
        press(viewer, glfw.KEY_M)                         # the path tracer: its own mean
        viewer.frame()
        assert viewer.samples == 1 and "path tracing: 1 spp" in viewer.title()
        assert tracer._released and any(line.startswith("path tracer ready") for line in messages)
        with PathTracer(moved, *SIZE, PathOptions(samples=SAMPLES_PER_FRAME, pattern=PATTERN)) as paths:
            assert (viewer.shown_image() == paths.render(first_sample=0).rgba8[..., :3]).all()
        press(viewer, glfw.KEY_M)                         # the rasteriser, the same view
        assert_matches(shown_after_a_frame(viewer), headless(moved))
        assert viewer.samples is None and "tracing" not in viewer.title()
        press(viewer, glfw.KEY_M)                         # the ray tracer again: a new mean
        viewer.frame()
        assert viewer.samples == 1
        tracer = viewer._tracer
    assert tracer._released                               # closed with the viewer


# -- radiosity: progressive refinement converging -------------------------------------------------
def test_radiosity_converges_a_step_a_frame_and_a_camera_move_keeps_it_going(on_x_display):
    """method="radiosity": the first frame shows the direct light (with the ambient term for the
    bounces to come), the hemicubes come a batch a frame, then shots, the unshot light falling
    every frame, until it converges and the loop idles; the picture is then the headless
    radiosity's (solved by Gauss-Seidel to its own tolerance) within the pipeline tolerance. An
    orbit on the way does not start it again; turning a light off does."""
    from renderer.core.radiosity_progressive import HEMICUBES_PER_STEP
    from renderer.methods import open_renderer
    plates = scene("radiosity_specular")                 # lights, sky, a specular term
    with Viewer(plates, *SIZE, vsync=False, method="radiosity", on_message=lambda line: None) as viewer:
        viewer.run(frames=1)
        assert "direct light" in viewer.title() and not viewer.idle
        viewer.run(frames=1, orbit=5.0)                   # a camera move: the hemicubes go on
        assert f"hemicubes {HEMICUBES_PER_STEP:,} of" in viewer.radiosity_line
        lines = []
        for _ in range(2000):
            viewer.run(frames=1)
            lines.append(viewer.radiosity_line)
            if viewer.idle:
                break
        assert viewer.idle and "converged" in lines[-1] and "(done)" not in viewer.title()
        unshot = [float(line.split("unshot ")[1].split("%")[0]) for line in lines if "unshot" in line]
        assert len(unshot) > 3 and all(b <= a for a, b in zip(unshot, unshot[1:]))
        moved = replace(plates, camera=viewer.orbit.camera)
        with open_renderer(moved, SIZE, method="radiosity") as radiosity:
            assert_matches(viewer.shown_image(), radiosity.render(depth=False).rgba8)
        viewer.run(frames=1, orbit=5.0)                   # converged: a camera move solves nothing
        assert "converged" in viewer.radiosity_line
        press(viewer, glfw.KEY_1)                         # the sun off: the lights change, again
        viewer.run(frames=1)
        assert "direct light" in viewer.radiosity_line and not viewer.idle


def test_ray_tracing_stops_at_the_cap_and_idles(on_x_display):
    with Viewer(scene("sphere"), 32, 24, vsync=False, method="raytrace",
                on_message=lambda line: None) as viewer:
        viewer.accumulator = type(viewer.accumulator)(cap=2)
        viewer.run(frames=4)
        assert viewer.samples == 2 and viewer.idle and "2 spp (done)" in viewer.title()
        viewer.controls.scroll(0.0, 1.0)                  # zoom: a new view
        viewer.frame()
        assert viewer.samples == 1 and not viewer.idle


def test_scripted_ray_tracing_from_the_command_line(x_display, tmp_path, cli):
    shot, stats = tmp_path / "shot.png", tmp_path / "stats.json"
    result = cli("view", "sphere", "--size", "80x60", "--method", "raytrace", "--frames", "4",
                 "--reference", "difference", "--screenshot", str(shot), "--stats", str(stats),
                 display=x_display)
    assert result.returncode == 0, result.stderr
    assert "ray tracing: 4 spp" in result.stdout.splitlines()
    summary = json.loads(stats.read_text())
    assert summary["raytrace_spp"] == 4 and summary["reference"] is None
    assert read_png(shot).shape[:2] == (60, 80)


# -- shadows: O toggles them, D shows a light's map ------------------------------------------------
SHADOW_SIZE = (120, 220)     # the map view's 120x120 square at rows 50-169, below the overlay


@pytest.fixture
def shadow_viewer(on_x_display):
    messages = []
    with Viewer(scene("shadow_plane"), *SHADOW_SIZE, vsync=False, on_message=messages.append) as v:
        v.messages = messages
        yield v


def test_o_toggles_shadows_in_the_picture_and_the_title(shadow_viewer):
    authored = scene("shadow_plane")
    with_shadows = shown_after_a_frame(shadow_viewer)
    assert_matches(with_shadows, headless(authored, SHADOW_SIZE))
    press(shadow_viewer, glfw.KEY_O)
    without = shown_after_a_frame(shadow_viewer)
    assert_matches(without, headless(without_shadow_maps(authored), SHADOW_SIZE))
    assert (np.abs(without.astype(int) - with_shadows).max(axis=-1) > 20).mean() > 0.02
    assert not shadow_viewer.gpu.shadows and "shadows off" in shadow_viewer.title()
    press(shadow_viewer, glfw.KEY_O)
    assert np.array_equal(shown_after_a_frame(shadow_viewer), with_shadows)
    assert "shadows on" in shadow_viewer.title()


def test_d_shows_the_map_the_frame_drew_and_again_the_picture(shadow_viewer):
    """The map fills the 120x120 square in the middle of the 120x220 window, each pixel the
    texel under its centre as grey: the casters' depths, and white where nothing was drawn."""
    picture = shown_after_a_frame(shadow_viewer)
    press(shadow_viewer, glfw.KEY_D)
    shown = shown_after_a_frame(shadow_viewer)
    plan = shadow_viewer.gpu.drawn_shadow_plan
    (light_map,) = plan.layout.maps
    r = light_map.resolution
    layer = shadow_viewer.gpu.shadow_maps.read_layer(light_map.kind, 0)[:r, :r]
    lo, hi = shadow_viewer._map_view.depth_range
    square = shown[::-1][50:170].astype(int)             # GL rows, as the layer
    texel = ((np.arange(120) + 0.5) * r / 120).astype(int)
    depths = layer[np.ix_(texel, texel)]
    expected = np.where(depths < 1.0, np.round(0.85 * (depths - lo) / (hi - lo) * 255), 255)
    assert (np.abs(square[..., 0] - expected) > 1).mean() < 0.01
    assert (square[..., 0] == square[..., 1]).all() and (square[..., 1] == square[..., 2]).all()
    # The casters' texels are grey, darker than the cleared texels around them (white).
    casters = depths < 1.0
    assert 0.05 < casters.mean() < 0.95
    assert (square[..., 0][casters] <= 217).mean() > 0.99 and (square[..., 0][~casters] == 255).mean() > 0.99
    assert shadow_viewer._overlay_text() == (f"shadow map of directional light 1: {r}x{r}",
                                             f"depth {lo:.6g} black to {hi:.6g} grey, 1.0 white")
    assert "(map of directional light 1)" in shadow_viewer.title()
    press(shadow_viewer, glfw.KEY_D)                     # the only map: then off
    assert shadow_viewer.state.shadow_map is None
    assert np.array_equal(shown_after_a_frame(shadow_viewer), picture)


def test_with_shadows_off_d_says_there_is_no_map_and_the_reference_matches(on_x_display):
    """The reference view is asked for the scene with shadows off while O has them off."""
    with Viewer(scene("shadow_plane"), 80, 60, reference="difference",
                on_message=lambda line: None) as viewer:
        press(viewer, glfw.KEY_O)
        press(viewer, glfw.KEY_D)
        viewer.run(frames=2)                             # the last frame waits for the reference
        assert viewer.figures is not None and viewer.figures["mismatched"] == 0
        assert "shadow map of directional light 1: shadows are off (O)" in viewer._overlay_text()
        assert not viewer._map_shown


# -- tessellation: the title's levels, W's wireframe of the generated triangles ----------------------

def test_the_title_shows_the_tessellation_levels_and_w_draws_the_generated_triangles(on_x_display):
    """tessellated_sphere at 160x120: the title's levels are the control stage's twin's for
    the view (its least and largest); the wireframe is the stages' triangles, more lines than
    the 80 patches alone would draw."""
    from reference.tessellation.surface import levels_in_view
    authored = scene("tessellated_sphere")
    found = levels_in_view(authored, 160, 120)
    low, high = min(f[1] for f in found), max(f[2] for f in found)
    with Viewer(authored, 160, 120, vsync=False) as v:
        shaded = shown_after_a_frame(v)
        assert f"tessellation levels {low:.1f}-{high:.1f}" in v.title() and high > 2
        press(v, glfw.KEY_W)
        lines = shown_after_a_frame(v)
        patches = replace(authored, objects=[replace(o, tessellation=replace(o.tessellation, level=1.0))
                                             if o.tessellation else o for o in authored.objects])
    with Viewer(patches, 160, 120, vsync=False) as v:
        press(v, glfw.KEY_W)
        coarse = shown_after_a_frame(v)
    background = shaded[0, 0].astype(int)                     # the sky: a corner
    drawn = lambda image: (np.abs(image.astype(int) - background).max(axis=-1) > 8).sum()   # noqa: E731
    assert drawn(lines) > 1.5 * drawn(coarse) > 0 and drawn(lines) < drawn(shaded)
