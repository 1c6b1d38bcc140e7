"""Issue 13: nothing a user gives the command line yields a traceback, library noise or a
crash. Each refusal is exit status 2 and exactly one line on stderr, naming the file, the
key and the reason, whatever the input holds (line breaks in keys, corrupt mesh files,
numbers float32 cannot hold, a GL driver that crashes)."""


import pytest

from renderer.errors import SceneError, UserError

CUBE = '[[objects]]\nmesh = { primitive = "cube" }\n'


def refused(result) -> str:
    """The one stderr line of a refusal (exit 2, nothing else printed)."""
    assert result.returncode == 2, result.stderr
    lines = result.stderr.splitlines()
    assert len(lines) == 1, result.stderr
    assert "Traceback" not in result.stderr and "Warning" not in result.stderr
    assert result.stdout == ""
    return lines[0]


def render(cli, tmp_path, scene_text, files=()):
    for name, content in files:
        (tmp_path / name).write_bytes(content if isinstance(content, bytes) else content.encode())
    (tmp_path / "scene.toml").write_text(scene_text)
    return cli("render", "scene.toml", "-o", tmp_path / "out.png", cwd=tmp_path)


# --- every message is one line ---------------------------------------------------------------

@pytest.mark.parametrize("control", ["\n", "\r", "\x0b", "\x0c", "\x1b", "\x85", "\u2028", "\u2029"])
def test_a_message_is_one_line_whatever_its_key_file_and_reason_hold(control):
    error = SceneError(f"bad {control} value", file=f"a{control}.toml", key=f"objects[0].k{control}")
    line = error.line()
    assert len(line.splitlines()) == 1
    # File and key repr-quoted, the reason's control character escaped.
    assert line == f"{repr(f'a{control}.toml')}: {repr(f'objects[0].k{control}')}: " \
                   f"bad {repr(control)[1:-1]} value"


def test_a_plain_message_is_unchanged():
    assert UserError("reason", file="scene.toml", key="camera.eye").line() == \
        "scene.toml: camera.eye: reason"


def test_a_key_with_a_newline_is_quoted_on_one_line(cli_here, tmp_path):
    line = refused(render(cli_here, tmp_path, '"a\\nb" = 1\n'))
    assert line.startswith("renderer: scene.toml: 'a\\nb': unknown key;")


# --- library noise ---------------------------------------------------------------------------

# A process each (library noise shows only in a real one). The STL case is the full run's
# (--all): the same path as the OBJ case (trimesh's loader failing, kept quiet by
# meshio._quiet_libraries, the same one line), about 1.3 s.
@pytest.mark.parametrize("name, content, reason", [
    ("bad.obj", b"v 0 0 0\n" + bytes(range(128, 256)) * 2,
     "could not be read as OBJ: not a valid OBJ file (neither binary OBJ nor text)"),
    pytest.param("bad.stl", bytes(range(256)) + bytes(range(255, -1, -1)),
                 "could not be read as STL: not a valid STL file (neither binary STL nor text)",
                 marks=pytest.mark.slow),
])
def test_a_corrupt_mesh_file_is_refused_in_words(cli, tmp_path, name, content, reason):
    line = refused(render(cli, tmp_path, f'[[objects]]\nmesh = {{ file = "{name}" }}\n',
                          [(name, content)]))
    assert line == f"renderer: scene.toml: objects[0].mesh.file: {name}: {reason}"


@pytest.mark.slow                  # a process each (library noise shows only in a real one)
@pytest.mark.parametrize("coordinate, reason", [
    ("inf", "vertex 3 is not finite (inf, 0, 0); 1 of 4 vertices are NaN or Inf"),
    ("1e300", "vertex 3 (1e+300, 0, 0) is too large for the GPU's float32 arithmetic; "
              "coordinates must satisfy |x| <= 1e+18 (1 of 4 vertices do not)"),
])
def test_huge_or_infinite_mesh_coordinates_are_refused_without_library_warnings(cli, tmp_path,
                                                                                coordinate, reason):
    obj = f"v 0 0 0\nv 1 0 0\nv 0 1 0\nv {coordinate} 0 0\nf 1 2 3\nf 1 2 4\nf 2 3 4\n"
    line = refused(render(cli, tmp_path, '[[objects]]\nmesh = { file = "big.obj" }\n',
                          [("big.obj", obj)]))
    assert line == f"renderer: scene.toml: objects[0].mesh.file: big.obj: {reason}"


@pytest.mark.slow                  # a process of its own, as the cases above
def test_a_ply_index_beyond_int32_is_reported_as_written(cli, tmp_path):
    ply = ("ply\nformat ascii 1.0\nelement vertex 3\nproperty float x\nproperty float y\n"
           "property float z\nelement face 1\nproperty list uchar int vertex_indices\n"
           f"end_header\n0 0 0\n1 0 0\n0 1 0\n3 0 1 {2**31 + 10}\n")
    line = refused(render(cli, tmp_path, '[[objects]]\nmesh = { file = "big.ply" }\n',
                          [("big.ply", ply)]))
    assert line == ("renderer: scene.toml: objects[0].mesh.file: big.ply: face 0 has vertex index "
                    "2147483658 out of range (the mesh has 3 vertices, indices 0 to 2)")


# --- numbers float32 cannot hold -------------------------------------------------------------

LIMIT = "too large for the GPU's float32 arithmetic; numbers must satisfy |x| <= 1e+18"


@pytest.mark.parametrize("scene, key, reason", [
    (CUBE + "translate = [1e300, 0, 0]\n", "objects[0].translate", f"item 0 is 1e+300, {LIMIT}"),
    ("[camera]\neye = [0, 1e300, 5]\n" + CUBE, "camera.eye", f"item 1 is 1e+300, {LIMIT}"),
    (CUBE + "scale = 1e19\n", "objects[0].scale", f"item 0 is 1e+19, {LIMIT}"),
    ("[camera]\nfar = 1e19\n" + CUBE, "camera.far", f"1e+19 is {LIMIT}"),
    # Each number within the limit, their product not: scale 1e18 of a parent and a child.
    ('[[objects]]\nname = "p"\nmesh = { primitive = "cube" }\nscale = 1e18\n'
     '[[objects]]\nparent = "p"\nmesh = { primitive = "cube" }\nscale = 1e18\n', "objects[1]",
     "its transform (with its parents') takes it beyond 1e+30 in the GPU's float32 coordinates; "
     "scale, translate or the camera put it too far away or make it too large"),
])
def test_numbers_float32_cannot_hold_are_refused_with_the_limit(cli_here, tmp_path, scene, key,
                                                               reason):
    assert refused(render(cli_here, tmp_path, scene)) == f"renderer: scene.toml: {key}: {reason}"


# --- a GL driver that crashes ----------------------------------------------------------------

@pytest.mark.parametrize("kind", ["auto", pytest.param("osmesa", marks=pytest.mark.slow),
                                  pytest.param("egl", marks=pytest.mark.slow)])
def test_a_driver_mesa_lacks_is_one_line_not_a_crash(cli, tmp_path, monkeypatch, kind):
    """OSMesa dies of SIGSEGV with this; the context is probed in a child process first.
    EGL refuses politely (eglInitialize fails), but its libEGL warnings stay off the terminal."""
    monkeypatch.setenv("GALLIUM_DRIVER", "nonexistent")
    line = refused(cli("render", "sphere", "--context", kind, "-o", tmp_path / "x.png"))
    assert line.startswith("renderer: no headless OpenGL 3.3 context could be made (")
    assert line.endswith("is GALLIUM_DRIVER=nonexistent a driver Mesa has? (unset it, or set it "
                         "to llvmpipe or softpipe)")
    if kind != "egl":
        assert "osmesa: OSMesa context failed in a probe (the process died of SIGSEGV)" in line
    if kind != "osmesa":
        assert "egl: eglInitialize failed" in line
    assert not (tmp_path / "x.png").exists()


def test_the_probe_is_cached_per_kind_and_environment(monkeypatch):
    from renderer.gpu import context
    calls = []
    monkeypatch.setattr(context, "_probed", {})
    monkeypatch.setattr(context, "_run_probe", lambda kind: calls.append(kind))
    monkeypatch.delenv("GALLIUM_DRIVER", raising=False)
    context.probe("osmesa"), context.probe("osmesa"), context.probe("egl")
    monkeypatch.setenv("GALLIUM_DRIVER", "softpipe")
    context.probe("osmesa")
    assert calls == ["osmesa", "egl", "osmesa"]
