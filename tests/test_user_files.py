"""Issue 30, "one way to open a file a user names" (renderer/core/user_files.py): a FIFO, a
device, a folder is refused in one line before it is opened; a file over its kind's cap before
it is read; an image's or array's declared size before it is decoded; a glTF's resources stay
in its folder; the half-tone's cell and angle have a range. Each case goes through the command
line in this process under an alarm (a hang fails the test in seconds), and asserts one line
on stderr, exit status 2, nothing written, no traceback, no file contents echoed."""

from __future__ import annotations

import ast
import base64
import contextlib
import json
import os
import signal
import struct
import time
import zlib
from pathlib import Path

import numpy as np
import pytest
from numpy.lib import format as npy_format

from renderer.core import memory, user_files
from renderer.core.user_files import (FileRefused, USER_FILE_CAPS, open_image, open_user_file,
                                      read_user_file)

ROOT = Path(__file__).resolve().parents[1]
SECRET = "canary-7f3a"                    # in files outside; never in a message
SECONDS = 10                              # each refusal is milliseconds; a hang fails here


# --------------------------------------------------------------------------- helpers

def png_header(width: int, height: int, rows: bytes = b"\0" * 64) -> bytes:
    """A few bytes of PNG whose header declares width x height, 1-bit grey (IHDR, a short
    IDAT of `rows`, IEND): a bomb of 300 bytes a row had it been real."""
    def chunk(kind, data):
        return (struct.pack(">I", len(data)) + kind + data
                + struct.pack(">I", zlib.crc32(kind + data) & 0xFFFFFFFF))
    header = struct.pack(">IIBBBBB", width, height, 1, 0, 0, 0, 0)
    return (b"\x89PNG\r\n\x1a\n" + chunk(b"IHDR", header)
            + chunk(b"IDAT", zlib.compress(rows)) + chunk(b"IEND", b""))


def jpeg_header(width: int, height: int) -> bytes:
    """A JPEG of a start, a baseline frame header declaring width x height, and an end."""
    frame = b"\xff\xc0" + struct.pack(">HBHHB", 11, 8, height, width, 1) + b"\x01\x11\x00"
    return b"\xff\xd8" + frame + b"\xff\xd9"


def npy_header_only(path: Path, shape, descr="<f4") -> None:
    with open(path, "wb") as handle:
        npy_format.write_array_header_1_0(handle, {"descr": descr, "fortran_order": False,
                                                   "shape": tuple(shape)})


@contextlib.contextmanager
def bounded(what):
    """A TimeoutError after SECONDS instead of a hang (SIGALRM)."""
    def hung(*_):
        raise TimeoutError(f"no answer in {SECONDS} s: {what}")
    previous = signal.signal(signal.SIGALRM, hung)
    signal.alarm(SECONDS)
    try:
        yield
    finally:
        signal.alarm(0)
        signal.signal(signal.SIGALRM, previous)


def special(folder: Path, kind: str, name: str) -> str:
    """A file of `kind` ("fifo", "folder"; "device" is /dev/zero) named `name` in `folder`;
    returns what a scene or command line names it by."""
    if kind == "device":
        return "/dev/zero"
    if kind == "fifo":
        os.mkfifo(folder / name)
    elif kind == "folder":
        (folder / name).mkdir()
    return name


@pytest.fixture
def work(tmp_path, monkeypatch):
    monkeypatch.chdir(tmp_path)
    outside = tmp_path.parent / f"{tmp_path.name}-outside"
    outside.mkdir(exist_ok=True)
    (outside / "secret.png").write_text(SECRET)
    return tmp_path


@pytest.fixture
def refused(cli_here):
    """refused(*args, cwd) -> the one line: status 2, one line on stderr, no traceback, no
    warning, nothing new in `cwd`, no secret echoed, within SECONDS (an alarm ends a hang)."""
    def run(*args, cwd: Path) -> str:
        before = sorted(p.name for p in cwd.iterdir())
        start = time.monotonic()
        with bounded(args):
            result = cli_here(*args)
        assert time.monotonic() - start < SECONDS
        err = result.stderr
        assert result.returncode == 2, err
        assert len(err.splitlines()) == 1, err
        assert "Traceback" not in err and "Warning" not in err and SECRET not in err
        assert sorted(p.name for p in cwd.iterdir()) == before
        return err.strip()
    return run


def render(*args):
    return ["render", "--backend", "reference", "--size", "16x12", "-o", "out.png", *args]


SCENE = """[camera]
eye = [0.0, 0.0, 3.0]
look = [0.0, 0.0, 0.0]

[materials.m]
kd = [0.8, 0.8, 0.8]
{texture}

[[objects]]
mesh = {mesh}
material = "m"
"""


def scene(folder: Path, *, mesh='{ primitive = "cube" }', image=None, name="s.toml") -> Path:
    texture = f'texture = {{ image = "{image}" }}' if image is not None else ""
    path = folder / name
    path.write_text(SCENE.format(mesh=mesh, texture=texture))
    return path


# --------------------------------------------------------------------------- the opener

def test_special_files_are_refused_by_what_they_are(tmp_path):
    os.mkfifo(tmp_path / "pipe.toml")
    (tmp_path / "folder.toml").mkdir()
    cases = {tmp_path / "pipe.toml": "is a named pipe (FIFO), not a regular file",
             Path("/dev/zero"): "is a character device, not a regular file",
             tmp_path / "folder.toml": "is a directory, not a regular file",
             tmp_path / "missing.toml": "scene file not found"}
    for path, reason in cases.items():
        with pytest.raises(FileRefused) as info:
            open_user_file(path, user_files.SCENE_FILE)
        assert info.value.reason.startswith(reason)


def test_a_fifo_swapped_in_after_the_stat_neither_hangs_nor_is_read(tmp_path, monkeypatch):
    """The stat saw a regular file; a FIFO is there when the file is opened: the open does not
    wait for a writer (O_NONBLOCK), and the open file's own fstat refuses it."""
    regular, pipe = tmp_path / "regular.toml", tmp_path / "pipe.toml"
    regular.write_text("a = 1\n")
    os.mkfifo(pipe)
    real_stat = os.stat
    monkeypatch.setattr(os, "stat", lambda path, *a, **k: real_stat(regular if Path(path) == pipe
                                                                    else path, *a, **k))
    with bounded(pipe), pytest.raises(FileRefused, match="is a named pipe"):
        open_user_file(pipe, user_files.SCENE_FILE)


def test_a_file_over_its_kinds_cap_is_refused_before_it_is_read(tmp_path, monkeypatch):
    monkeypatch.setitem(USER_FILE_CAPS, user_files.SCENE_FILE, 2048)
    (tmp_path / "big.toml").write_text("# " + "x" * 3070)
    with pytest.raises(FileRefused) as info:
        read_user_file(tmp_path / "big.toml", user_files.SCENE_FILE)
    assert info.value.reason == "is 3 kB; a scene file is at most 2 kB"
    (tmp_path / "small.toml").write_text("a = 1\n")
    assert read_user_file(tmp_path / "small.toml", user_files.SCENE_FILE) == b"a = 1\n"


def test_a_read_asks_for_the_files_size_not_its_kinds_cap(tmp_path, monkeypatch):
    """A read of n bytes takes n bytes before it reads one: asked for a mesh file's 4 GiB cap,
    every mesh read failed under an address-space limit (test_fuzz.py's 1 GiB guard: a
    MemoryError for a 100-byte OBJ). A file that grows after its stat is read on, to the cap."""
    asked = []

    class Recording:
        def __init__(self, handle):
            self.handle = handle

        def __getattr__(self, name):
            return getattr(self.handle, name)

        def read(self, n=-1):
            asked.append(n)
            return self.handle.read(n)

    (tmp_path / "m.obj").write_bytes(b"v 0 0 0\n" * 10)
    with open_user_file(tmp_path / "m.obj", user_files.MESH_FILE) as handle:
        assert user_files.read_capped(Recording(handle), user_files.MESH_FILE) == b"v 0 0 0\n" * 10
    assert max(asked) <= 81
    monkeypatch.setitem(USER_FILE_CAPS, user_files.SCENE_FILE, 2048)
    (tmp_path / "s.toml").write_text("a = 1\n")
    with open_user_file(tmp_path / "s.toml", user_files.SCENE_FILE) as handle:
        (tmp_path / "s.toml").write_text("# " + "x" * 3070)           # grew after the stat
        with pytest.raises(FileRefused, match="grew past 2 kB while read"):
            user_files.read_capped(handle, user_files.SCENE_FILE)


def test_every_kind_states_its_cap():
    source = (ROOT / "renderer/core/user_files.py").read_text()
    assert set(USER_FILE_CAPS) == {user_files.SCENE_FILE, user_files.JOB_FILE, user_files.MESH_FILE,
                                   user_files.GLTF_RESOURCE, user_files.IMAGE_FILE,
                                   user_files.ARRAY_FILE, user_files.MANIFEST_FILE}
    block = source[source.index("USER_FILE_CAPS = {"):source.index("\n}\n")]
    for kind in ("SCENE_FILE", "JOB_FILE", "MESH_FILE", "GLTF_RESOURCE", "IMAGE_FILE",
                 "ARRAY_FILE", "MANIFEST_FILE"):
        line = block.index(f"    {kind}:")
        assert block.rfind("    # ", 0, line) > block.rfind(",\n", 0, line) - 200, kind


def test_pillow_does_not_refuse_a_side_the_docs_allow():
    """16384 x 16384 (docs/scene-format.md, GL_MAX_TEXTURE_SIZE) is past Pillow's own bomb
    limit (2 x 89.5 Mpixels): the header opens without Pillow's warning or error, and
    Pillow's setting is as it was afterwards."""
    from PIL import Image
    before = Image.MAX_IMAGE_PIXELS
    whole = png_header(16384, 16384, rows=b"\0" * (16384 * (1 + 16384 // 8)))   # every row there
    with memory.limit_set(1 << 40):
        with open_image(whole, max_side=16384, bytes_per_pixel=1) as image:
            assert image.size == (16384, 16384)
        with pytest.raises(FileRefused, match="at most 16384 pixels on a side"):
            open_image(png_header(16385, 4), max_side=16384, bytes_per_pixel=1)
    assert Image.MAX_IMAGE_PIXELS == before


# --------------------------------------------------------------------------- scene and job files

def test_a_scene_that_is_a_fifo_a_device_or_a_folder_is_one_line(refused, work):
    os.mkfifo(work / "pipe.toml")
    (work / "folder.toml").mkdir()
    assert refused(*render("pipe.toml"), cwd=work) == (
        "renderer: pipe.toml: is a named pipe (FIFO), not a regular file; a scene file must be one")
    assert refused(*render("folder.toml"), cwd=work) == (
        "renderer: folder.toml: is a directory, not a regular file; a scene file must be one")


def test_a_scene_over_its_cap_is_refused_before_it_is_parsed(refused, work, monkeypatch):
    monkeypatch.setitem(USER_FILE_CAPS, user_files.SCENE_FILE, 1024)
    scene(work)
    (work / "s.toml").write_text((work / "s.toml").read_text() + "# padding\n" * 200)
    assert refused(*render("s.toml"), cwd=work) == \
        "renderer: s.toml: is 2 kB; a scene file is at most 1 kB"


@pytest.mark.parametrize("scene_value", ["pipe.toml", "/dev/zero"])
def test_a_job_file_or_its_scene_that_is_special_is_one_line(refused, work, scene_value):
    os.mkfifo(work / "pipe.toml")
    (work / "job.toml").write_text(f'[[scenes]]\nscene = "{scene_value}"\n')
    line = refused("batch", "job.toml", "--out", "out", cwd=work)
    assert line.startswith("renderer: job.toml: scenes[0].scene: ")
    assert "not a regular file; a scene file must be one" in line
    for job in ("pipe.toml", "/dev/zero"):
        line = refused("batch", job, "--out", "out", cwd=work)
        assert "not a regular file; a job file must be one" in line


# --------------------------------------------------------------------------- meshes

@pytest.mark.parametrize("kind", ["fifo", "device", "folder"])
def test_a_mesh_that_is_special_is_one_line(refused, work, kind):
    target = special(work, kind, f"{kind}.obj")
    scene(work, mesh=f'{{ file = "{target}" }}')
    line = refused(*render("s.toml"), cwd=work)
    assert line.startswith("renderer: s.toml: objects[0].mesh.file: ")
    assert "not a regular file; a mesh file must be one" in line


# --------------------------------------------------------------------------- textures

def test_a_texture_whose_header_is_a_bomb_is_one_line_without_pillows_warning(refused, work):
    (work / "bomb.png").write_bytes(png_header(10000, 10000))
    scene(work, image="bomb.png")
    line = refused(*render("s.toml", "--max-memory", "1G"), cwd=work)
    assert line.startswith("renderer: s.toml: materials.m.texture.image: bomb.png: "
                           "a 10000 x 10000 texture needs about")
    (work / "wide.png").write_bytes(png_header(20000, 4))
    scene(work, image="wide.png")
    assert refused(*render("s.toml"), cwd=work).endswith(
        "wide.png: image is 20000 x 4; a texture is at most 16384 texels on a side "
        "(GL_MAX_TEXTURE_SIZE)")


def short_png(rows_written: int, width: int = 16, height: int = 16, interlace: int = 0) -> bytes:
    """An RGB PNG whose header says width x height and whose compressed data ends, properly,
    after `rows_written` rows (no interlace) or short of its last pass's final 4 bytes."""
    import struct
    import zlib

    def chunk(kind: bytes, data: bytes) -> bytes:
        return struct.pack(">I", len(data)) + kind + data + struct.pack(">I", zlib.crc32(kind + data))

    row = b"\x00" + bytes([200, 10, 10]) * width
    if interlace:
        passes = ((0, 0, 8, 8), (4, 0, 8, 8), (0, 4, 4, 8), (2, 0, 4, 4), (0, 2, 2, 4), (1, 0, 2, 2), (0, 1, 1, 2))
        data = b"".join((b"\x00" + bytes(3 * -(-(width - x0) // dx))) * -(-(height - y0) // dy)
                        for x0, y0, dx, dy in passes if width > x0 and height > y0)
        data = data[:len(data) - 4 * (rows_written < height)]
    else:
        data = row * rows_written
    header = struct.pack(">IIBBBBB", width, height, 8, 2, 0, 0, interlace)
    return (b"\x89PNG\r\n\x1a\n" + chunk(b"IHDR", header) + chunk(b"IDAT", zlib.compress(data))
            + chunk(b"IEND", b""))


def test_a_png_with_rows_missing_is_refused_not_drawn_black(refused, work):
    """Pillow decodes such a file without a word, the missing rows black."""
    (work / "short.png").write_bytes(short_png(8))
    scene(work, image="short.png")
    assert refused(*render("s.toml"), cwd=work).endswith(
        "short.png: is truncated: its image data holds 392 of the 784 bytes its header's "
        "16 x 16 pixels need (rows are missing)")
    line = refused("colour", "short.png", "--backend", "reference", "--out", "o", cwd=work)
    assert line == ("renderer: short.png: is truncated: its image data holds 392 of the 784 bytes "
                    "its header's 16 x 16 pixels need (rows are missing)")


def test_whole_pngs_pass_the_row_count_interlaced_or_not():
    import io

    from renderer.core.user_files import png_data_problem
    assert png_data_problem(io.BytesIO(short_png(16))) is None
    for width, height in ((1, 1), (3, 5), (13, 9)):               # Adam7's empty passes too
        assert png_data_problem(io.BytesIO(short_png(height, width, height, interlace=1))) is None
        assert "is truncated" in png_data_problem(io.BytesIO(short_png(0, width, height, interlace=1)))


def test_a_jpeg_cut_short_is_one_line(refused, work):
    import io

    from PIL import Image
    noise = np.random.default_rng(0).integers(0, 255, (64, 64, 3), dtype=np.uint8)
    encoded = io.BytesIO()
    Image.fromarray(noise).save(encoded, "JPEG")
    (work / "cut.jpg").write_bytes(encoded.getvalue()[:len(encoded.getvalue()) // 2])
    scene(work, image="cut.jpg")
    assert "cut.jpg: could not be read as an image (PNG or JPEG): image file is truncated" in \
        refused(*render("s.toml"), cwd=work)


@pytest.mark.parametrize("kind", ["fifo", "device"])
def test_a_texture_that_is_special_is_one_line(refused, work, kind):
    scene(work, image=special(work, kind, "pipe.png"))
    line = refused(*render("s.toml"), cwd=work)
    assert "not a regular file; an image file must be one" in line


# --------------------------------------------------------------------------- glTF

def triangle_gltf(folder: Path, image_uri: str) -> Path:
    """A .gltf of one textured triangle, its geometry in a data: URI, its image `image_uri`."""
    positions = np.array([[0, 0, 0], [1, 0, 0], [0, 1, 0]], np.float32).tobytes()
    uvs = np.array([[0, 0], [1, 0], [0, 1]], np.float32).tobytes()
    indices = np.array([0, 1, 2, 0], np.uint16).tobytes()
    data = positions + uvs + indices
    gltf = {
        "asset": {"version": "2.0"}, "scene": 0, "scenes": [{"nodes": [0]}], "nodes": [{"mesh": 0}],
        "meshes": [{"primitives": [{"attributes": {"POSITION": 0, "TEXCOORD_0": 1},
                                    "indices": 2, "material": 0}]}],
        "materials": [{"pbrMetallicRoughness": {"baseColorTexture": {"index": 0}}}],
        "textures": [{"source": 0}], "images": [{"uri": image_uri}],
        "buffers": [{"byteLength": len(data),
                     "uri": "data:application/octet-stream;base64,"
                            + base64.b64encode(data).decode()}],
        "bufferViews": [{"buffer": 0, "byteOffset": 0, "byteLength": 36},
                        {"buffer": 0, "byteOffset": 36, "byteLength": 24},
                        {"buffer": 0, "byteOffset": 60, "byteLength": 6}],
        "accessors": [{"bufferView": 0, "componentType": 5126, "count": 3, "type": "VEC3",
                       "min": [0, 0, 0], "max": [1, 1, 0]},
                      {"bufferView": 1, "componentType": 5126, "count": 3, "type": "VEC2"},
                      {"bufferView": 2, "componentType": 5123, "count": 3, "type": "SCALAR"}],
    }
    folder.mkdir(exist_ok=True)
    path = folder / "model.gltf"
    path.write_text(json.dumps(gltf))
    return path


@pytest.mark.parametrize("uri", ["OUTSIDE", "ABSOLUTE", "../../etc/passwd", "link.png"])
def test_a_gltf_image_outside_its_folder_is_refused(refused, work, uri):
    outside = work.parent / f"{work.name}-outside" / "secret.png"
    if uri == "OUTSIDE":
        uri = f"../../{outside.parent.name}/secret.png"
    elif uri == "ABSOLUTE":
        uri = str(outside)
    elif uri == "link.png":
        (work / "model").mkdir()
        (work / "model" / "link.png").symlink_to(outside)
    triangle_gltf(work / "model", uri)
    scene(work, mesh='{ file = "model/model.gltf" }')
    line = refused(*render("s.toml"), cwd=work)
    assert line.startswith("renderer: s.toml: objects[0].mesh.file: ")
    assert ("leaves the glTF's folder" in line or "is not a relative path" in line), line
    assert line.endswith("a glTF's resources are data: URIs or files in its own folder")


@pytest.mark.parametrize("uri", ["t.png\0x", "t.png%00x"])
def test_a_gltf_image_uri_with_a_null_byte_is_one_line(refused, work, uri):
    """Found by tests/test_fuzz.py (gen_gltf): Path.resolve raised ValueError (embedded null
    byte), a traceback."""
    triangle_gltf(work / "model", uri)
    scene(work, mesh='{ file = "model/model.gltf" }')
    line = refused(*render("s.toml"), cwd=work)
    assert line == ("renderer: s.toml: objects[0].mesh.file: model/model.gltf: uri 't.png\\\\x00x' "
                    "contains a null byte, which no file name holds"), line


@pytest.mark.parametrize("uri, reason", [
    ("OUTSIDE", "leaves the glTF's folder; a glTF's resources are data: URIs or files in its "
                "own folder"),
    ("pipe.bin", "uri 'pipe.bin': is a named pipe (FIFO), not a regular file"),
])
def test_a_gltf_buffer_outside_its_folder_or_special_is_refused(refused, work, uri, reason):
    """trimesh reads the buffers (meshio's _ConfinedResolver); the same rule as the images."""
    path = triangle_gltf(work / "model", "tex.png")
    if uri == "OUTSIDE":
        uri = f"../../{work.name}-outside/secret.png"
    else:
        os.mkfifo(work / "model" / uri)
    gltf = json.loads(path.read_text())
    gltf["buffers"][0]["uri"] = uri
    path.write_text(json.dumps(gltf))
    scene(work, mesh='{ file = "model/model.gltf" }')
    line = refused(*render("s.toml"), cwd=work)
    assert line.startswith("renderer: s.toml: objects[0].mesh.file: ")
    assert reason in line, line


def test_a_gltf_image_beside_it_is_read(work):
    from PIL import Image

    from renderer.core.gltf_texture import base_colour_texture
    path = triangle_gltf(work / "model", "tex%20ture.png")
    Image.fromarray(np.full((2, 2, 3), 255, np.uint8)).save(work / "model" / "tex ture.png")
    texture = base_colour_texture(path)
    assert texture.texture.width == 2


def test_a_gltf_image_that_is_a_fifo_is_one_line(refused, work):
    triangle_gltf(work / "model", "pipe.png")
    os.mkfifo(work / "model" / "pipe.png")
    scene(work, mesh='{ file = "model/model.gltf" }')
    line = refused(*render("s.toml"), cwd=work)
    assert "uri 'pipe.png': is a named pipe (FIFO), not a regular file" in line


# --------------------------------------------------------------------------- renderer colour

@pytest.mark.parametrize("name, content, declared", [
    ("bomb.png", png_header(50000, 50000), "50000 x 50000"),
    ("bomb.jpg", jpeg_header(65000, 65000), "65000 x 65000"),
    ("bomb.npy", None, "50000 x 50000"),
])
def test_colour_refuses_a_declared_size_over_the_limit_before_decoding(refused, work, name,
                                                                      content, declared):
    if content is None:
        npy_header_only(work / name, (50000, 50000, 4))
    else:
        (work / name).write_bytes(content)
    line = refused("colour", name, "--backend", "reference", "--out", "o", cwd=work)
    assert line.startswith(f"renderer: {name}: a {declared} image needs about ")
    assert "over the limit of" in line


@pytest.mark.parametrize("header, says", [
    # an unclosed bracket: NumPy's retry as a Python 2 header raised tokenize.TokenError
    (b"{'descr': '<f4', 'fortran_order': False, 'shape': (500\x8f4, 0}\x00 ( \n",
     "could not be read as a .npy array: "),
    # a newline inside the header: read on the retry, with NumPy's UserWarning on stderr
    (b"{'descr': '<f4', 'fortran_order': False, 'shape': (50000, 50000, 4)}  \n" + b" " * 36
     + b"\n", "a 50000 x 50000 image needs about "),
])
def test_colour_refuses_a_mangled_npy_header_in_one_line(refused, work, header, says):
    """Found by tests/test_fuzz.py (gen_textures, a .npy's bytes mutated)."""
    (work / "a.npy").write_bytes(b"\x93NUMPY\x01\x00" + struct.pack("<H", len(header)) + header)
    line = refused("colour", "a.npy", "--backend", "reference", "--out", "o", cwd=work)
    assert line.startswith(f"renderer: a.npy: {says}"), line


@pytest.mark.parametrize("kind", ["fifo", "folder", "npy objects"])
def test_colour_refuses_special_files_in_one_line(refused, work, kind):
    if kind == "npy objects":
        name = "obj.npy"
        npy_header_only(work / name, (2, 2), descr="|O")
    else:
        name = special(work, kind, f"{kind}.png")
    line = refused("colour", name, "--backend", "reference", "--out", "o", cwd=work)
    expected = {"fifo": "is a named pipe (FIFO), not a regular file; an image file must be one",
                "folder": "is a directory, not a regular file; an image file must be one",
                "npy objects": "holds Python objects"}[kind]
    assert expected in line


# --------------------------------------------------------------------------- half-tone

@pytest.mark.parametrize("value, reason", [
    ("100000", "the cell must be 2 to 256 pixels wide, got 100000"),
    ("1e300", "the cell must be 2 to 256 pixels wide, got 1e300"),
    ("8:1e300", "the angle must be -360 to 360 degrees, got 1e300"),
    ("8:nan", "the angle must be -360 to 360 degrees, got nan"),
])
def test_halftone_out_of_range_is_refused_with_the_range(refused, work, value, reason):
    assert refused(*render("sphere", "--halftone", value), cwd=work) == \
        f"renderer: --halftone {value}: {reason}"


# --------------------------------------------------------------------------- the walk

# Calls that open or read a file by name, and where renderer/ may make them without
# renderer/core/user_files.py: the project's own files (GLSL, built-in assets, goldens,
# caches), files the command itself writes, and the opener itself. (file, function): reason.
READS = {"open", "read_bytes", "read_text", "Image.open", "np.load", "numpy.load", "os.open",
         "OpenEXR.File", "trimesh.load", "trimesh.load_scene", "trimesh.load_mesh",
         "tomllib.load", "json.load", "png.Reader"}
ALLOWED = {
    ("renderer/core/user_files.py", "open_user_file"): "the opener itself",
    ("renderer/core/user_files.py", "open_image"): "Pillow on a stream the opener gave",
    ("renderer/gpu/shaders.py", "*"): "the project's GLSL files",
    ("renderer/checks/goldens.py", "*"): "the committed goldens and their notes",
    ("renderer/study/ground_truth.py", "*"): "the study's own cache of ground truths",
    ("renderer/core/imageio.py", "*"): "files the command writes (temporary names, read-back)",
    ("renderer/core/image_formats.py", "*"): "PNG and OpenEXR codecs: given bytes or a checked "
                                             "file's /dev/fd name (colour_source) or our outputs",
    ("renderer/study/colour_source.py", "_read_exr"): "OpenEXR opens by name: the checked file's "
                                                      "/dev/fd name",
    ("renderer/study/colour_source.py", "_read_npy"): "np.load of the handle the opener gave",
    ("renderer/study/colour_source.py", "_read_pixels"): "pypng's header from the opener's handle",
    ("renderer/core/meshio.py", "_read_with_trimesh"): "trimesh on the bytes the opener read",
    ("renderer/cli/__init__.py", "*"): "os.devnull",
    ("renderer/cluster/ray_executor.py", "*"): "os.devnull",
    ("renderer/viewer/virtual_display.py", "*"): "a pipe the viewer made",
    ("renderer/batch/folder.py", "*"): "the batch's own --out folder, opened without following "
                                       "links (issue 30's batch part)",
    ("renderer/batch/manifest.py", "*"): "the batch's own manifest in --out",
    ("renderer/study/peak_memory.py", "*"): "the files its measurements make in their own "
                                            "temporary folders",
}


def _call_name(node: ast.Call) -> str | None:
    """"open" for the built-in, "MODULE.NAME" for a module's reader (os.open, Image.open),
    the method's name for a method (path.read_text -> "read_text"); None for the rest."""
    func = node.func
    if isinstance(func, ast.Name):
        return func.id
    if isinstance(func, ast.Attribute):
        if isinstance(func.value, ast.Name) and f"{func.value.id}.{func.attr}" in READS:
            return f"{func.value.id}.{func.attr}"
        return func.attr if func.attr in ("read_bytes", "read_text") else None
    return None


class _Reads(ast.NodeVisitor):
    """Each read call with the innermost function it is in."""

    def __init__(self):
        self.stack, self.found = ["<module>"], []

    def visit_FunctionDef(self, node):
        self.stack.append(node.name)
        self.generic_visit(node)
        self.stack.pop()

    visit_AsyncFunctionDef = visit_FunctionDef

    def visit_Call(self, node):
        if _call_name(node) in READS:
            self.found.append((self.stack[-1], node.lineno, _call_name(node)))
        self.generic_visit(node)


def test_no_other_code_reads_a_file_by_name():
    """Every open or read of a file in renderer/ is the opener's, or allowed above with its
    reason: a new reader of a user's file goes through renderer/core/user_files.py."""
    found = []
    for path in sorted((ROOT / "renderer").rglob("*.py")):
        rel = path.relative_to(ROOT).as_posix()
        reads = _Reads()
        reads.visit(ast.parse(path.read_text(encoding="utf-8")))
        for function, line, call in reads.found:
            if (rel, function) not in ALLOWED and (rel, "*") not in ALLOWED:
                found.append(f"{rel}:{line} in {function}: {call}")
    assert not found, "\n".join(found)
