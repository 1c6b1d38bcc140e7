"""The command line as a user types it.

Which cases run where: tests that start `python -m renderer` (the `cli` fixture, about 1.3 s
each) are in the default run where the process is what they hold; the three whose path other
tests hold in the default run are the full run's (--all), each marked with the tests that
hold it."""

import json
import re

import numpy as np
import pytest

from renderer.core.imageio import read_png


def test_render_default_scene_writes_png_and_depth(tmp_path, cli):
    out, depth = tmp_path / "a.png", tmp_path / "d.npy"
    result = cli("render", "-o", str(out), "--size", "64x48", "--depth", str(depth))
    assert result.returncode == 0, result.stderr
    image = read_png(out)
    assert image.shape == (48, 64, 4)
    d = np.load(depth)
    assert d.shape == (48, 64) and d.dtype == np.float32
    assert np.isinf(d).any() and np.isfinite(d).any()


# The default run holds this path in this process: the next test (the default name and the
# "wrote" line on stderr, stdout empty).
@pytest.mark.slow
def test_render_without_output_names_the_file_after_the_scene(tmp_path, cli):
    result = cli("render", "--size", "32x24", "--backend", "reference", cwd=tmp_path)
    assert result.returncode == 0, result.stderr
    assert [p.name for p in tmp_path.iterdir()] == ["out"]          # nothing loose in the folder
    assert (tmp_path / "out" / "sphere.png").exists()
    assert result.stdout == ""
    assert re.fullmatch(r"wrote out/sphere\.png \(32x24, reference, \d+\.\d ms\)\n", result.stderr)


def test_render_says_where_it_wrote_on_stderr_unless_quiet(tmp_path, capsys, monkeypatch):
    from renderer.cli import main
    monkeypatch.chdir(tmp_path)
    assert main(["render", "--size", "16x12", "--backend", "reference", "--depth", "d.npy"]) == 0
    out, err = capsys.readouterr()
    assert out == ""
    assert re.fullmatch(r"wrote out/sphere\.png and d\.npy \(16x12, reference, \d+\.\d ms\)\n", err)
    for quiet in ("--quiet", "-q"):
        (tmp_path / "out" / "sphere.png").unlink()
        assert main(["render", "--size", "16x12", "--backend", "reference", quiet]) == 0
        assert capsys.readouterr() == ("", "")
        assert (tmp_path / "out" / "sphere.png").exists()


# The full run's (--all), about 1.5 s: in the default run `renderer compare` with a real GPU
# frame runs in this process in tests/test_raytrace_trace.py
# (test_command_line_ray_traces_and_compares) and tests/test_compare_methods.py (OSMesa), its
# figures and three images in test_compare_exits_1_when_the_pipeline_tolerance_fails below and
# tests/test_json_outputs.py, and a command in a process of its own in the first test above.
@pytest.mark.slow
def test_compare_prints_the_figures_and_writes_three_images(tmp_path, cli):
    result = cli("compare", "sphere", "--size", "80x60", "--context", "osmesa", "--out", str(tmp_path))
    assert result.returncode == 0, result.stderr
    figures = json.loads(result.stdout)
    for key in ("max_abs", "mean_abs", "rmse", "psnr", "raw_mismatched_pixels", "mismatched_pixels",
                "mismatched_fraction", "depth_max_rel", "gpu_ms", "reference_ms"):
        assert key in figures
    assert figures["mismatched_pixels"] == 0
    assert figures["context"] == "osmesa" and "llvmpipe" in figures["gl_renderer"]
    for name in ("gpu.png", "reference.png", "diff.png"):
        assert read_png(tmp_path / name).shape[:2] == (60, 80)


def test_scenes_lists_one_name_first_on_each_line(cli):
    result = cli("scenes")
    assert result.returncode == 0
    names = [line.split()[0] for line in result.stdout.splitlines()]
    assert "sphere" in names and len(names) >= 8


def test_bad_size_is_the_reason_then_the_usage_and_status_2(tmp_path, cli):
    """An argument error: one line with the reason (the program named once), then the
    subcommand's usage on one line."""
    result = cli("render", "--size", "wide", "-o", str(tmp_path / "x.png"))
    assert result.returncode == 2
    assert result.stderr.splitlines() == [
        "renderer render: argument --size: expected WIDTHxHEIGHT such as 640x480, got 'wide'",
        build_parser_usage("render")]
    assert not (tmp_path / "x.png").exists()


def build_parser_usage(command: str) -> str:
    """The usage line `renderer COMMAND` prints after an argument error."""
    from renderer.cli import build_parser
    parser = build_parser()
    subparser = parser.parse_args([command]).parser if command else parser
    return subparser.usage_line()


def test_version_prints_the_version(capsys):
    import renderer
    from renderer.cli import main
    assert main(["--version"]) == 0
    assert capsys.readouterr().out == f"renderer {renderer.__version__}\n"


@pytest.mark.parametrize("argv, reason", [
    (["render", "--size", "0x10"], "renderer render: argument --size: width and height must be 1 to "
                                   "16384 pixels, got '0x10'"),
    (["render", "--bogus"], "renderer render: unrecognized arguments: --bogus"),
    (["render", "--backend", "cuda"], "renderer render: argument --backend: invalid choice: 'cuda' "
                                      "(choose from 'gpu', 'reference')"),
    (["view", "--stats", "s.json"], "renderer view: --stats needs --frames (the scripted mode)"),
    (["scenes", "extra"], "renderer scenes: unrecognized arguments: extra"),
    ([], "renderer: the following arguments are required: command"),
])
def test_an_argument_error_names_the_program_once_then_gives_the_usage(argv, reason, capsys, tmp_path,
                                                                        monkeypatch):
    from renderer.cli import main
    monkeypatch.chdir(tmp_path)
    assert main(argv) == 2
    out, err = capsys.readouterr()
    usage = build_parser_usage(argv[0] if argv else "")
    assert err.splitlines() == [reason, usage] and out == ""
    assert usage.startswith(f"usage: renderer {argv[0] if argv else '[-h] [--version]'}")
    assert list(tmp_path.iterdir()) == []


# The full run's, like tests/test_scene_file.py's
# test_cli_unknown_scene_name_exits_2_and_lists_builtins (this in a process, with more
# asserted); the default run holds the refusal through renderer.cli.main there
# (test_load_scene_unknown_name_is_the_command_lines_line) and a refusal in a process of its
# own in tests/test_refusals.py.
@pytest.mark.slow
def test_unknown_scene_names_the_built_in_ones(tmp_path, cli):
    result = cli("render", "no_such_scene", "-o", str(tmp_path / "x.png"))
    assert result.returncode == 2
    assert "sphere" in result.stderr and "Traceback" not in result.stderr


def test_written_files_get_the_usual_permissions(tmp_path, cli):
    import os
    out = tmp_path / "p.png"
    assert cli("render", "--size", "16x12", "--backend", "reference", "-o", str(out)).returncode == 0
    mask = os.umask(0)
    os.umask(mask)
    assert out.stat().st_mode & 0o777 == 0o666 & ~mask
    assert not [p for p in tmp_path.iterdir() if p.name.startswith(".")]     # no temporary left


def test_shaders_writes_the_exact_glsl_of_each_variant_the_scene_draws(tmp_path, gl_contexts, cli):
    """hierarchy draws with three variants, each looking the shadow maps up (phong, gouraud,
    flat with its geometry stage); each file is the text the renderer compiles, and it
    compiles as it is."""
    from renderer.core.builtin import builtin_scenes
    from renderer.gpu.context import activate
    from renderer.gpu.pipeline import GpuRenderer
    from renderer.core.scene_file import load_scene
    from renderer.core.shadow_settings import DEFAULT_FILTER, FILTERS
    from renderer.gpu.shaders import ShaderVariant, program_sources

    result = cli("shaders", "hierarchy", "--out", str(tmp_path))
    assert result.returncode == 0, result.stderr
    assert result.stdout.splitlines()[0] == \
        ("phong-specular-1dir-1point-shadows: phong-specular-1dir-1point-shadows.vert, "
         "phong-specular-1dir-1point-shadows.frag (objects: sun, planet, plinth)")
    assert sorted(p.name for p in tmp_path.iterdir()) == [
        "flat-specular-1dir-1point-shadows.frag", "flat-specular-1dir-1point-shadows.geom",
        "flat-specular-1dir-1point-shadows.vert",
        "gouraud-specular-1dir-1point-shadows.frag", "gouraud-specular-1dir-1point-shadows.vert",
        "phong-specular-1dir-1point-shadows.frag", "phong-specular-1dir-1point-shadows.vert"]
    ctx = gl_contexts["egl"]
    with GpuRenderer(load_scene(builtin_scenes()["hierarchy"]), 16, 16, context=ctx) as gpu:
        gpu.render()
        assert sorted(variant.name for variant in gpu.programs) == \
            ["flat-specular-1dir-1point-shadows", "gouraud-specular-1dir-1point-shadows",
             "phong-specular-1dir-1point-shadows"]
    flat = {stage: (tmp_path / f"flat-specular-1dir-1point-shadows.{suffix}").read_text()
            for stage, suffix in (("vertex_shader", "vert"), ("geometry_shader", "geom"),
                                  ("fragment_shader", "frag"))}
    assert flat == {stage: source.text for stage, source in
                    program_sources(ShaderVariant("flat", False, 1, 1, specular=True, shadows=True,
                                                  shadow_kernel=FILTERS[DEFAULT_FILTER])).items()}
    assert "#define SHADING_FLAT" in flat["fragment_shader"]
    assert "#define NUM_POINT_LIGHTS 1" in flat["vertex_shader"]
    assert "#define SPECULAR" in flat["geometry_shader"]
    assert "#define NUM_DIRECTIONAL_TERMS 1" in flat["geometry_shader"]
    activate(ctx)
    ctx.program(**flat).release()


# -- compare's exit status ------------------------------------------------------------------------

def sphere_with_a_square_off_by_128(reference_frames):
    """The reference's 32x24 sphere with a 4x4 square in its middle 128 levels off in R, G
    and B: as a GPU frame, 16 pixels that nothing within ±1 px matches at a threshold under 128."""
    from dataclasses import replace
    frame = reference_frames("sphere", 32, 24)
    rgba8 = frame.rgba8.copy()
    assert (rgba8[10:14, 14:18, 3] == 255).all()              # on the sphere
    rgba8[10:14, 14:18, :3] ^= 0x80
    return replace(frame, rgba8=rgba8)


@pytest.mark.parametrize("threshold, status", [(None, 1), ("127", 1), ("128", 0), ("255", 0)])
def test_compare_exits_1_when_the_pipeline_tolerance_fails(threshold, status, tmp_path, capsys,
                                                           gpu_stand_in, reference_frames):
    """The pipeline tolerance at the threshold asked for (default: the tolerance's own, 2)
    decides: 0 when the images agree, 1 when they do not, with what fails on stderr."""
    from renderer.cli import main
    gpu_stand_in(sphere_with_a_square_off_by_128(reference_frames))
    argv = ["compare", "sphere", "--size", "32x24", "--out", str(tmp_path)]
    assert main(argv + (["--threshold", threshold] if threshold else [])) == status
    out, err = capsys.readouterr()
    figures = json.loads(out)
    assert figures["passes"] is (status == 0)
    assert figures["threshold"] == int(threshold or 2)
    assert figures["mismatched_pixels"] == (16 if status else 0)
    if status:
        level = threshold or 2
        assert err.splitlines() == [
            f"renderer compare: sphere fails the pipeline tolerance: 16 pixels fail within ±1 px at "
            f"{level}/255 (at most 0 may); 2.0833% of pixels differ by more than {level}/255 in place "
            f"(at most 0.1%)"]
    else:
        assert err == ""
    assert sorted(p.name for p in tmp_path.iterdir()) == ["diff.png", "gpu.png", "reference.png"]


def test_compare_exits_0_when_the_images_agree(tmp_path, capsys, gpu_stand_in, reference_frames):
    from renderer.cli import main
    gpu_stand_in(reference_frames("sphere", 32, 24))
    assert main(["compare", "sphere", "--size", "32x24", "--out", str(tmp_path)]) == 0
    assert json.loads(capsys.readouterr().out)["passes"] is True


@pytest.mark.parametrize("threshold", ["-1", "256", "2.5", "two"])
def test_compare_refuses_a_threshold_outside_0_to_255(threshold, tmp_path, capsys):
    from renderer.cli import main
    out = tmp_path / "cmp"
    assert main(["compare", "sphere", "--out", str(out), "--threshold", threshold]) == 2
    err = capsys.readouterr().err
    assert err.splitlines() == [f"renderer compare: argument --threshold: expected a whole number of "
                                f"levels from 0 to 255, got {threshold!r}", build_parser_usage("compare")]
    assert not out.exists()


def test_compare_help_gives_the_exit_status(capsys):
    from renderer.cli import main
    assert main(["compare", "--help"]) == 0
    text = " ".join(capsys.readouterr().out.split())
    assert ("Exit status: 0 when the two agree within the pipeline tolerance" in text
            and "1 when they do not" in text and "2 for bad input" in text)


# -- the background of the files `render` writes ------------------------------------------------

def render_in_process(tmp_path, *args) -> int:
    from renderer.cli import main
    return main(["render", "--backend", "reference", "--size", "32x24", *map(str, args)])


def test_render_writes_the_picture_opaque_by_default(tmp_path, reference_frames):
    """orthographic's background is [0.9, 0.92, 0.95]: the file shows it, opaque (RGB), as
    an image viewer shows the picture; the pixels are the frame's colour everywhere."""
    from PIL import Image
    out = tmp_path / "o.png"
    assert render_in_process(tmp_path, "orthographic", "-o", out) == 0
    with Image.open(out) as image:
        assert image.mode == "RGB"
        pixels = np.asarray(image)
    frame = reference_frames("orthographic", 32, 24)
    assert np.array_equal(pixels, frame.rgba8[..., :3])
    nothing_drawn = frame.rgba8[..., 3] == 0
    assert nothing_drawn.any() and (pixels[nothing_drawn] == [230, 235, 242]).all()
    assert read_png(out)[..., 3].min() == 255


def test_render_background_transparent_writes_the_coverage_alpha(tmp_path, reference_frames):
    """--background transparent: RGBA, alpha 255 where something was drawn and 0 elsewhere,
    the frame's rgba8 as it is (what goldens and compare's images hold)."""
    from PIL import Image
    out = tmp_path / "t.png"
    assert render_in_process(tmp_path, "orthographic", "-o", out, "--background", "transparent") == 0
    with Image.open(out) as image:
        assert image.mode == "RGBA"
        pixels = np.asarray(image)
    frame = reference_frames("orthographic", 32, 24)
    assert np.array_equal(pixels, frame.rgba8)
    assert set(np.unique(pixels[..., 3])) == {0, 255}


def test_frame_image_by_background(reference_frames):
    frame = reference_frames("sphere", 32, 24)
    assert np.array_equal(frame.image(), frame.rgba8[..., :3])
    assert frame.image("transparent") is frame.rgba8
    with pytest.raises(ValueError, match="background must be one of"):
        frame.image("white")


# -- the format of the files the command line writes ------------------------------------------------

@pytest.mark.parametrize("name, image_format, mode", [
    ("o.jpg", "JPEG", "RGB"), ("o.JPEG", "JPEG", "RGB"), ("o.webp", "WEBP", "RGB"),
    ("o.tif", "TIFF", "RGB"), ("o.bmp", "BMP", "RGB"), ("o.png", "PNG", "RGB")])
def test_render_writes_the_format_its_suffix_names(name, image_format, mode, tmp_path, reference_frames):
    from PIL import Image
    out = tmp_path / name
    assert render_in_process(tmp_path, "sphere", "-o", out) == 0
    with Image.open(out) as image:
        assert (image.format, image.mode, image.size) == (image_format, mode, (32, 24))
        pixels = np.asarray(image).astype(int)
    expected = reference_frames("sphere", 32, 24).rgba8[..., :3].astype(int)
    difference = np.abs(pixels - expected)
    if image_format == "JPEG":                         # lossy, at quality 95
        assert difference.mean() < 2.0
    else:
        assert difference.max() == 0
    assert [p.name for p in tmp_path.iterdir()] == [name]


def test_render_transparent_keeps_alpha_in_a_format_that_has_it(tmp_path, reference_frames):
    from PIL import Image
    out = tmp_path / "t.webp"
    assert render_in_process(tmp_path, "sphere", "-o", out, "--background", "transparent") == 0
    with Image.open(out) as image:
        assert (image.format, image.mode) == ("WEBP", "RGBA")
        alpha = np.asarray(image)[..., 3]
    assert np.array_equal(alpha, reference_frames("sphere", 32, 24).rgba8[..., 3])


@pytest.mark.parametrize("name, args, reason", [
    ("o.xyz", (), "cannot write .xyz images; use .png, .jpg, .webp, .tif, .bmp or another suffix "
                  "Pillow writes"),
    ("o.h5", (), "cannot write .h5 images; use .png, .jpg, .webp, .tif, .bmp or another suffix "
                 "Pillow writes"),
    ("out", (), "no suffix to say the image format; name the file e.g. out.png or out.jpg"),
    ("o.jpg", ("--background", "transparent"),
     "JPEG (.jpg) keeps no alpha channel, which a transparent background needs; use .png, .webp "
     "or .tif"),
    ("o.bmp", ("--background", "transparent"),
     "BMP (.bmp) keeps no alpha channel, which a transparent background needs; use .png, .webp "
     "or .tif"),
])
def test_render_refuses_a_file_name_it_cannot_write(name, args, reason, tmp_path, capsys):
    out = tmp_path / name
    assert render_in_process(tmp_path, "sphere", "-o", out, *args) == 2
    assert capsys.readouterr().err.splitlines() == [f"renderer: {out}: {reason}"]
    assert list(tmp_path.iterdir()) == []


def test_render_refuses_depth_that_is_not_npy(tmp_path, capsys):
    depth = tmp_path / "d.png"
    assert render_in_process(tmp_path, "sphere", "-o", tmp_path / "o.png", "--depth", depth) == 2
    assert capsys.readouterr().err.splitlines() == [
        f"renderer: {depth}: --depth writes float32 depth as .npy (NumPy) or .exr (OpenEXR); name the "
        "file e.g. depth.npy"]
    assert list(tmp_path.iterdir()) == []


def test_view_refuses_a_screenshot_name_before_opening_a_window(tmp_path, capsys, monkeypatch):
    from renderer.cli import main
    monkeypatch.delenv("DISPLAY", raising=False)
    monkeypatch.delenv("WAYLAND_DISPLAY", raising=False)
    shot = tmp_path / "s.xyz"
    assert main(["view", "sphere", "--frames", "1", "--screenshot", str(shot)]) == 2
    assert capsys.readouterr().err.splitlines() == [
        f"renderer: {shot}: cannot write .xyz images; use .png, .jpg, .webp, .tif, .bmp or another "
        f"suffix Pillow writes"]
    assert list(tmp_path.iterdir()) == []


def test_ctrl_c_is_one_line_and_status_130_with_nothing_written(tmp_path, capsys, monkeypatch):
    # Any command: KeyboardInterrupt mid-write leaves no file and no temporary (issue 30).
    from renderer.cli import main, render
    from renderer.core.imageio import outputs

    def interrupted(args):
        with outputs() as out:
            out.png(tmp_path / "half.png", np.zeros((4, 4, 3), np.uint8))
            raise KeyboardInterrupt
    monkeypatch.setattr(render, "run", interrupted)
    assert main(["render", "-o", str(tmp_path / "x.png")]) == 130
    assert capsys.readouterr().err == "renderer: interrupted\n"
    assert list(tmp_path.iterdir()) == []


@pytest.mark.slow
def test_ctrl_c_stops_a_long_render_in_one_line(tmp_path):
    # SIGINT to the process mid-render (the reference ray tracer: minutes of NumPy).
    import signal
    import subprocess
    import sys
    import time
    command = subprocess.Popen([sys.executable, "-m", "renderer", "render", "--backend", "reference",
                                "--method", "raytrace", "--spp", "64", "--size", "400x300",
                                "-o", str(tmp_path / "r.png")], stdout=subprocess.PIPE,
                               stderr=subprocess.PIPE, text=True)
    try:
        time.sleep(2.0)
        command.send_signal(signal.SIGINT)
        out, err = command.communicate(timeout=60)
    finally:
        command.kill()
    assert (command.returncode, out, err) == (130, "", "renderer: interrupted\n")
    assert list(tmp_path.iterdir()) == []
