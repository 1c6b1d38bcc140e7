"""Issue 13, output faults and wrong or leaked files: whatever goes wrong while a command
writes, the user gets one line, never a traceback, a half-written or wrong file, or a
temporary left behind.

- A bad output name (an existing folder, a parent path that is a file, an empty name, two
  outputs of one command naming the same file) is refused before any work: exit status 2.
- A write the system refuses (read-only folder or file system, full disk, I/O error) is one
  line and exit status 1 (renderer.errors.SystemFault).
- Either way every existing target is left untouched and no temporary remains.
- The files of one command are committed together: all or none (imageio.outputs).
- A temporary left by a process killed mid-write is removed by the next write of that file.

Tests run as root, which a chmod-ed folder does not stop: read-only folders and file
systems are injected (os.open / os.replace raising the errno); a full disk is a real small
tmpfs where the sandbox lets us mount one.

Which cases run where: the two that start `python -m renderer` (about 1.5 s each) are the full
run's (--all): the real full disk (the default run injects ENOSPC at each step instead) and
the temporary of a killed render (the default run removes a dead process's temporary in
test_a_temporary_of_a_live_process_is_left_alone, once its process has ended).
"""

import errno
import os
import signal
import subprocess
import sys
import textwrap
from pathlib import Path

import numpy as np
import pytest

from renderer.core import imageio
from renderer.core.imageio import outputs, read_png

OLD_PNG = b"\x89PNG old bytes the command must not touch"


def render(tmp_path, *args) -> int:
    from renderer.cli import main
    return main(["render", "--size", "16x12", "--backend", "reference", *map(str, args)])


def leftovers(folder) -> list[str]:
    """Temporaries (and backups) the transaction may have left: dot files."""
    return sorted(p.name for p in folder.rglob(".*"))


def one_line(capsys) -> str:
    out, err = capsys.readouterr()
    lines = err.splitlines()
    assert len(lines) == 1 and "Traceback" not in err, err
    return lines[0]


# -- bad names: status 2, before any rendering ---------------------------------------------------

@pytest.fixture
def no_rendering(monkeypatch):
    """Any attempt to render fails the test: the refusal must come first."""
    import reference

    def refuse(*args, **kwargs):
        raise AssertionError("rendered before refusing the output name")
    monkeypatch.setattr(reference, "render", refuse)


def test_an_existing_folder_as_output_is_refused(tmp_path, capsys, no_rendering):
    folder = tmp_path / "out.png"
    folder.mkdir()
    assert render(tmp_path, "-o", folder) == 2
    assert one_line(capsys) == f"renderer: {folder}: is a folder; name a file in it, e.g. {folder}/out.png"
    assert list(folder.iterdir()) == []


def test_a_parent_path_that_is_a_file_is_refused(tmp_path, capsys, no_rendering):
    parent = tmp_path / "notes.txt"
    parent.write_text("keep me\n")
    out = parent / "img.png"
    assert render(tmp_path, "-o", out) == 2
    assert one_line(capsys) == (f"renderer: {out}: {parent} is not a folder, so nothing can be "
                                f"written in it")
    assert parent.read_text() == "keep me\n"


@pytest.mark.parametrize("argv", [
    ["render", "-o", ""], ["render", "--depth", ""], ["compare", "--out", ""],
    ["shaders", "--out", ""], ["extremes", "--out", ""], ["report", "--out", ""],
    ["view", "--frames", "1", "--screenshot", ""],
])
def test_an_empty_output_name_is_one_line(argv, tmp_path, capsys, monkeypatch):
    from renderer.cli import main
    monkeypatch.chdir(tmp_path)
    assert main(argv) == 2
    assert one_line(capsys) == ("renderer: an empty output name; name the file or folder, e.g. "
                                "out.png or out/")
    assert list(tmp_path.iterdir()) == []


def test_render_refuses_depth_and_image_of_the_same_file(tmp_path, capsys, monkeypatch, no_rendering):
    """`-o out/img.npy.png`-style tricks aside, the only way two outputs of `render` name one
    file is by spelling or symlink: both refused before rendering, status 2."""
    from renderer.cli import main
    monkeypatch.chdir(tmp_path)
    (tmp_path / "out").mkdir()
    (tmp_path / "out" / "img.npy").symlink_to("img.png")      # the depth would land in the PNG
    for image, depth in (("out/img.png", "out/img.npy"), ("./out/img.png", "out/img.npy"),
                         ("out/img.png", "out/../out/img.npy")):
        assert main(["render", "-o", image, "--depth", depth]) == 2
        line = one_line(capsys)
        assert line == (f"renderer: {Path(depth)}: the same file as {Path(image)}; give each output "
                        f"its own name")
    assert sorted(p.name for p in (tmp_path / "out").iterdir()) == ["img.npy"]


def test_outputs_refuses_the_same_file_twice_by_any_spelling(tmp_path):
    from renderer.errors import UserError
    (tmp_path / "link.png").symlink_to(tmp_path / "img.png")
    for other in (tmp_path / "img.png", tmp_path / "." / "img.png", tmp_path / "link.png",
                  tmp_path / "sub" / ".." / "img.png"):
        with pytest.raises(UserError, match="the same file as"):
            with outputs() as out:
                out.png(tmp_path / "img.png", np.zeros((2, 2, 3), np.uint8))
                out.npy(other, np.zeros(2))
        assert not (tmp_path / "img.png").exists() and leftovers(tmp_path) == []


# -- the system refuses: status 1, nothing touched ------------------------------------------------

def _raising(err_no, real, when=lambda *args: True):
    def fake(*args, **kwargs):
        if when(*args):
            raise OSError(err_no, os.strerror(err_no), str(args[0]))
        return real(*args, **kwargs)
    return fake


@pytest.mark.parametrize("err_no, reason", [
    (errno.EROFS, "read-only file system"),
    (errno.EACCES, "permission denied"),
    (errno.ENOSPC, "no space left on device"),
    (errno.EIO, "input/output error"),
])
@pytest.mark.parametrize("where", ["open", "write", "replace"])
def test_a_refused_write_is_one_line_status_1_and_touches_nothing(err_no, reason, where, tmp_path,
                                                                  capsys, monkeypatch):
    image, depth = tmp_path / "img.png", tmp_path / "img.npy"
    image.write_bytes(OLD_PNG)
    if where == "open":           # the folder refuses a new file (read-only, EACCES)
        monkeypatch.setattr(imageio.os, "open", _raising(err_no, os.open,
                                                         lambda path, *a: str(path).endswith(".tmp")))
        failing = image
    elif where == "write":        # the second file's bytes do not fit (ENOSPC, EIO)
        real_save = np.save
        monkeypatch.setattr(np, "save", _raising(err_no, real_save))
        failing = depth
    else:                         # the rename is refused
        monkeypatch.setattr(imageio.os, "replace", _raising(err_no, os.replace))
        failing = image
    assert render(tmp_path, "-o", image, "--depth", depth) == 1
    assert one_line(capsys) == f"renderer: {failing}: cannot write: {reason}"
    assert image.read_bytes() == OLD_PNG and not depth.exists()
    assert leftovers(tmp_path) == []


@pytest.mark.slow                  # the full run's: the module's docstring says why
def test_a_real_full_disk(tmp_path, cli):
    """A 64 KiB tmpfs: the PNG fits, the depth (300 KiB) does not. Status 1, one line, the old
    files untouched, no temporary."""
    disk = tmp_path / "disk"
    disk.mkdir()
    mounted = subprocess.run(["mount", "-t", "tmpfs", "-o", "size=64k", "tmpfs", str(disk)],
                             capture_output=True, text=True)
    if mounted.returncode != 0:
        pytest.skip(f"cannot mount a small tmpfs here ({mounted.stderr.strip()}); "
                    f"the injected ENOSPC tests cover it")
    try:
        image, depth = disk / "img.png", disk / "img.npy"
        image.write_bytes(OLD_PNG)
        result = cli("render", "--size", "320x240", "--backend", "reference", "-o", image,
                     "--depth", depth)
        assert result.returncode == 1, result.stderr
        assert result.stderr == f"renderer: {depth}: cannot write: no space left on device\n"
        assert image.read_bytes() == OLD_PNG and not depth.exists()
        assert sorted(p.name for p in disk.iterdir()) == ["img.png"]
    finally:
        subprocess.run(["umount", str(disk)], check=True)


# -- all or none ----------------------------------------------------------------------------------

def test_a_failing_depth_leaves_the_old_png(tmp_path, capsys, monkeypatch):
    """The depth's write fails after the PNG's succeeded: the PNG is not renamed into place."""
    image, depth = tmp_path / "img.png", tmp_path / "img.npy"
    image.write_bytes(OLD_PNG)
    monkeypatch.setattr(np, "save", _raising(errno.ENOSPC, np.save))
    assert render(tmp_path, "-o", image, "--depth", depth) == 1
    assert image.read_bytes() == OLD_PNG and not depth.exists() and leftovers(tmp_path) == []


def test_a_rename_failing_midway_puts_back_what_was_renamed(tmp_path, monkeypatch):
    """The second rename fails: the first target gets its old bytes back, the second keeps its
    own, the third (new) is not there, and nothing else is left."""
    a, b, c = tmp_path / "a.png", tmp_path / "b.png", tmp_path / "c.png"
    a.write_bytes(b"old a")
    b.write_bytes(b"old b")
    real = os.replace
    monkeypatch.setattr(imageio.os, "replace", _raising(
        errno.EIO, real, lambda src, dst: str(dst) == str(b) and str(src).endswith(".tmp")))
    from renderer.errors import SystemFault
    with pytest.raises(SystemFault, match="input/output error"):
        with outputs(a, b, c) as out:
            for path in (a, b, c):
                out.png(path, np.zeros((2, 2, 3), np.uint8))
    assert a.read_bytes() == b"old a" and b.read_bytes() == b"old b" and not c.exists()
    assert sorted(p.name for p in tmp_path.iterdir()) == ["a.png", "b.png"]


def test_an_error_in_the_block_writes_nothing(tmp_path):
    with pytest.raises(KeyError):
        with outputs() as out:
            out.png(tmp_path / "new" / "a.png", np.zeros((2, 2, 3), np.uint8))
            raise KeyError("the command failed after its first file")
    assert list(tmp_path.iterdir()) == []          # not even the folder made for it


def test_compare_writes_its_three_images_or_none(tmp_path, capsys, monkeypatch, gpu_stand_in,
                                                 reference_frames):
    from renderer.cli import main
    gpu_stand_in(reference_frames("sphere", 16, 12))
    for name in ("gpu.png", "reference.png", "diff.png"):
        (tmp_path / name).write_bytes(OLD_PNG)
    real = os.replace
    monkeypatch.setattr(imageio.os, "replace", _raising(
        errno.ENOSPC, real, lambda src, dst: str(dst).endswith("diff.png")))
    assert main(["compare", "sphere", "--size", "16x12", "--out", str(tmp_path)]) == 1
    err = capsys.readouterr().err
    assert err == f"renderer: {tmp_path / 'diff.png'}: cannot write: no space left on device\n"
    for name in ("gpu.png", "reference.png", "diff.png"):
        assert (tmp_path / name).read_bytes() == OLD_PNG
    assert leftovers(tmp_path) == []


# -- a process killed mid-write -------------------------------------------------------------------

KILLED_WRITER = textwrap.dedent("""
    import os, signal, sys
    import numpy as np
    from renderer.core.imageio import outputs
    with outputs() as out:
        out.png(sys.argv[1], np.zeros((4, 4, 3), np.uint8))    # its temporary is written
        os.kill(os.getpid(), signal.SIGKILL)                    # and nothing runs after this
""")


@pytest.mark.slow                  # the full run's: the module's docstring says why
def test_a_temporary_left_by_a_killed_render_is_removed_by_the_next(tmp_path, cli):
    image = tmp_path / "img.png"
    killed = subprocess.run([sys.executable, "-c", KILLED_WRITER, str(image)], capture_output=True)
    assert killed.returncode == -signal.SIGKILL
    stale = leftovers(tmp_path)
    assert len(stale) == 1 and stale[0].startswith(".img.png.renderer-") and not image.exists()
    result = cli("render", "--size", "16x12", "--backend", "reference", "-o", image)
    assert result.returncode == 0, result.stderr
    assert read_png(image).shape == (12, 16, 4) and leftovers(tmp_path) == []


def test_a_temporary_of_a_live_process_is_left_alone(tmp_path):
    image = tmp_path / "img.png"
    sleeper = subprocess.Popen([sys.executable, "-c", "import time; time.sleep(60)"])
    try:
        theirs = tmp_path / f".img.png.renderer-{sleeper.pid}-0123abcd.tmp"
        theirs.write_bytes(b"being written")
        imageio.write_png(image, np.zeros((2, 2, 3), np.uint8))
        assert theirs.exists()
    finally:
        sleeper.kill()
        sleeper.wait()
    imageio.write_png(image, np.zeros((2, 2, 3), np.uint8))
    assert not theirs.exists()


@pytest.mark.parametrize("command", [["compare"], ["shaders"], ["extremes"], ["report", "--quick"]])
def test_an_output_folder_that_is_a_file_is_refused_before_any_work(command, tmp_path, capsys,
                                                                     monkeypatch):
    from renderer.cli import main
    monkeypatch.chdir(tmp_path)
    (tmp_path / "taken").write_text("keep me\n")
    assert main([*command, "--out", "taken"]) == 2
    assert one_line(capsys) == "renderer: taken: is not a folder, so nothing can be written in it"
    assert (tmp_path / "taken").read_text() == "keep me\n" and leftovers(tmp_path) == []


def test_view_refuses_a_screenshot_that_is_a_folder_before_opening_a_window(tmp_path, capsys,
                                                                             monkeypatch):
    from renderer.cli import main
    monkeypatch.delenv("DISPLAY", raising=False)
    monkeypatch.delenv("WAYLAND_DISPLAY", raising=False)
    shot = tmp_path / "shot.png"
    shot.mkdir()
    assert main(["view", "sphere", "--frames", "1", "--screenshot", str(shot)]) == 2
    assert one_line(capsys) == f"renderer: {shot}: is a folder; name a file in it, e.g. {shot}/out.png"
