"""Issue 13, "tracebacks on input": a bad scene file, mesh or path is one line on stderr
naming the file, the key and the reason, exit status 2, nothing written. Each case here is
one a fuzzer found raising instead (RecursionError, OSError, ValueError, a shader compiler's
error log) or writing where it should not; each goes through the command line in-process."""

from pathlib import Path

import numpy as np
import pytest

from renderer.cli import main
from renderer.core.scene_file import MAX_NESTING, load_scene

CUBE = 'mesh = { primitive = "cube" }\n'
TORUS = 'mesh = { primitive = "torus", major_segments = 12, minor_segments = 6 }\nrotate = [60, 0, 0]\n'


def refused(capsys, args, cwd: Path) -> str:
    """Run the command line; assert status 2, one stderr line, no traceback, nothing written
    in `cwd` (no image, no temporary file). Returns the line."""
    before = sorted(p.name for p in cwd.iterdir())
    status = main([str(a) for a in args])
    err = capsys.readouterr().err
    assert status == 2, err
    assert len(err.splitlines()) == 1, err
    assert "Traceback" not in err
    assert sorted(p.name for p in cwd.iterdir()) == before
    return err.strip()


@pytest.fixture
def work(tmp_path, monkeypatch):
    monkeypatch.chdir(tmp_path)
    return tmp_path


def render(*args):
    return ["render", "--backend", "reference", "--size", "16x12", *args]


# -- 1. deep nesting --------------------------------------------------------------------------

@pytest.mark.parametrize("value", ["[" * 1000 + "]" * 1000,
                                   "{a = " * 1000 + "1" + "}" * 1000],
                         ids=["arrays", "inline tables"])
def test_toml_nested_a_thousand_deep_is_one_line(capsys, work, value):
    (work / "deep.toml").write_text(f"x = {value}\n")
    line = refused(capsys, render("deep.toml"), work)
    assert line == (f"renderer: deep.toml: arrays or tables nested too deeply for the TOML "
                    f"parser; a scene file nests at most {MAX_NESTING} levels")


def test_nesting_over_the_limit_is_refused_at_its_key(capsys, work):
    # 40 levels: the parser copes, the reader refuses, naming where it is too deep.
    (work / "deep.toml").write_text("[camera]\neye = " + "[" * 40 + "]" * 40 + "\n")
    line = refused(capsys, render("deep.toml"), work)
    assert line.startswith("renderer: deep.toml: camera.eye[0][0]")
    assert line.endswith(f"arrays or tables nested more than {MAX_NESTING} levels deep")


def test_nesting_at_the_limit_is_the_usual_type_error(capsys, work):
    # camera (2) eye (3) and 29 more arrays: level 32, allowed; then eye is simply wrong.
    (work / "deep.toml").write_text("[camera]\neye = " + "[" * 30 + "]" * 30 + "\n")
    line = refused(capsys, render("deep.toml"), work)
    assert line == ("renderer: deep.toml: camera.eye: expected a list of 3 numbers, "
                    "got a list of 1 item")


# -- 2. deep parent chains and long cycles ----------------------------------------------------

def chain_scene(n: int, cycle: bool = False) -> str:
    """n objects, o{i} the parent of o{i+1}, listed children first; with `cycle`, o0's parent
    is the last one."""
    lines = []
    for i in reversed(range(n)):
        lines.append(f'[[objects]]\nname = "o{i}"\n{CUBE}translate = [0.001, 0, 0]\n')
        if i > 0:
            lines.append(f'parent = "o{i - 1}"\n')
        elif cycle:
            lines.append(f'parent = "o{n - 1}"\n')
    return "".join(lines)


@pytest.mark.slow           # a few seconds; the fuzz test's default run has parent chains too
def test_a_thousand_deep_parent_chain_renders(capsys, work):
    (work / "chain.toml").write_text(chain_scene(1000))
    scene = load_scene(work / "chain.toml")
    world = scene.world_matrices()
    # o999 is listed first and has the longest chain: 1000 translations of 0.001 along x.
    assert world[0][0, 3] == pytest.approx(1.0)
    assert main(render("chain.toml", "-o", "chain.png", "-q")) == 0
    assert (work / "chain.png").is_file()


def test_world_matrices_multiply_in_the_recursive_order():
    # M_world = M_parent_world @ M_local, bit for bit, for a chain with rotations and scales.
    scene = load_scene("hierarchy")
    by_name = {obj.name: obj for obj in scene.objects}

    def recursive(obj):
        local = obj.transform.matrix()
        return local if obj.parent is None else recursive(by_name[obj.parent]) @ local

    for obj, world in zip(scene.objects, scene.world_matrices()):
        assert np.array_equal(world, recursive(obj))
    assert any(obj.parent for obj in scene.objects)


def test_a_thousand_long_parent_cycle_is_one_short_line(capsys, work):
    (work / "cycle.toml").write_text(chain_scene(1000, cycle=True))
    line = refused(capsys, render("cycle.toml"), work)
    # objects[999] is o0, the first on the cycle in the order of the objects' list
    assert line == ("renderer: cycle.toml: objects[0].parent: parent cycle: o999 -> o998 -> "
                    "o997 -> o996 -> ... (1000 objects) ... -> o2 -> o1 -> o0 -> o999")


def test_a_chain_into_a_cycle_is_reported_at_the_cycle(capsys, work):
    (work / "cycle.toml").write_text(
        f'[[objects]]\nname = "tail"\nparent = "a"\n{CUBE}'
        f'[[objects]]\nname = "a"\nparent = "b"\n{CUBE}'
        f'[[objects]]\nname = "b"\nparent = "a"\n{CUBE}')
    line = refused(capsys, render("cycle.toml"), work)
    assert line == "renderer: cycle.toml: objects[1].parent: parent cycle: a -> b -> a"


# -- 4. paths the operating system cannot take ------------------------------------------------

LONG_NAME = "n" * 300                       # over NAME_MAX (255 bytes)
LONG_PATH = "d/" * 2100 + "s.toml"          # over PATH_MAX (4096 bytes), no name too long


@pytest.mark.parametrize("arg, reason", [
    ("a\0b.toml", "the path contains a null byte"),
    (LONG_NAME + ".toml", "a name in the path is 305 bytes long"),
    (LONG_PATH, "the path is 4206 bytes long; the longest a path can be is 4095 bytes (PATH_MAX)"),
], ids=["null byte", "name over NAME_MAX", "path over PATH_MAX"])
def test_a_scene_argument_the_system_cannot_take_is_one_line(capsys, work, arg, reason):
    line = refused(capsys, render(arg), work)
    assert line.startswith("renderer: ")
    assert reason in line


@pytest.mark.parametrize("mesh, reason", [
    ("m\\u0000.obj", "the path contains a null byte"),
    (LONG_NAME + ".obj", "a name in the path is 304 bytes long"),
    (LONG_PATH[:-6] + "m.obj", "the path is 4205 bytes long"),
], ids=["null byte", "name over NAME_MAX", "path over PATH_MAX"])
def test_a_mesh_path_the_system_cannot_take_is_one_line(capsys, work, mesh, reason):
    (work / "s.toml").write_text(f'[[objects]]\nmesh = {{ file = "{mesh}" }}\n')
    line = refused(capsys, render("s.toml"), work)
    assert line.startswith("renderer: s.toml: objects[0].mesh.file: ")
    assert reason in line


@pytest.mark.parametrize("option", ["-o", "--depth"])
@pytest.mark.parametrize("value, reason", [
    ("o\0.png", "the path contains a null byte"),
    (LONG_NAME + ".png", "a name in the path is 304 bytes long"),
    (LONG_PATH[:-6] + "o.png", "the path is 4205 bytes long"),
], ids=["null byte", "name over NAME_MAX", "path over PATH_MAX"])
def test_an_output_path_the_system_cannot_take_is_one_line(capsys, work, option, value, reason):
    if option == "--depth":
        value = value[:-4] + ".npy"
    line = refused(capsys, render("sphere", option, value), work)
    assert reason in line


@pytest.mark.parametrize("args", [
    ["compare", "sphere", "--out", "x\0"],
    ["shaders", "sphere", "--out", LONG_NAME],
    ["report", "sphere", "--out", "r", "--cache", "c\0"],
    ["extremes", "--out", LONG_PATH],
    ["view", "sphere", "--frames", "1", "--screenshot", "s\0.png"],
    ["view", "sphere", "--frames", "1", "--stats", LONG_NAME + ".json"],
], ids=["compare --out", "shaders --out", "report --cache", "extremes --out",
        "view --screenshot", "view --stats"])
def test_every_path_option_is_checked(capsys, work, args):
    line = refused(capsys, args, work)
    assert "null byte" in line or "bytes long" in line


def test_a_folder_that_cannot_be_searched_is_one_line(capsys, work, monkeypatch):
    # The tests run as root, whom chmod 000 does not stop: the probe says permission denied
    # as stat() does for anyone else in a folder without search (x) permission.
    from renderer.core import paths
    locked = work / "locked"
    locked.mkdir()
    (work / "s.toml").write_text('[[objects]]\nmesh = { file = "locked/m.obj" }\n')
    real = paths._stat

    def probe(path):
        if str(locked) in str(Path(path).absolute()):
            raise PermissionError(13, "Permission denied", str(path))
        return real(path)

    monkeypatch.setattr(paths, "_stat", probe)
    denied = "permission denied: a folder on the way cannot be searched"
    line = refused(capsys, render("locked/s.toml"), work)
    assert line == f"renderer: locked/s.toml: {denied}"
    line = refused(capsys, render("s.toml"), work)
    assert line == f"renderer: s.toml: objects[0].mesh.file: locked/m.obj: {denied}"
    line = refused(capsys, render("sphere", "-o", "locked/out.png"), work)
    assert line == f"renderer: locked/out.png: {denied}"


def test_an_unsearchable_folder_for_real(capsys, work):
    import os
    if os.geteuid() == 0:
        pytest.skip("root may search any folder; the probe's seam is tested above")
    locked = work / "locked"
    locked.mkdir()
    locked.chmod(0)
    try:
        line = refused(capsys, render("locked/s.toml"), work)
        assert "permission denied" in line
    finally:
        locked.chmod(0o755)


# -- 5. default output names come from the file's name, not the scene's `name` ---------------

@pytest.mark.parametrize("name", ["../../x", "/tmp/abs", "", "n" * 300, "a\\u0000b", ".hidden"])
def test_the_scene_name_never_decides_where_render_writes(capsys, tmp_path, monkeypatch, name):
    work = tmp_path / "a" / "b"
    work.mkdir(parents=True)
    monkeypatch.chdir(work)
    (work / "my scene.toml").write_text(f'name = "{name}"\n[[objects]]\n{CUBE}')
    assert main(render("my scene.toml", "-q")) == 0, capsys.readouterr().err
    assert sorted(p.name for p in tmp_path.rglob("*") if p.is_file()) == ["my scene.toml",
                                                                          "my_scene.png"]


def test_default_names_of_compare_and_shaders_come_from_the_file(capsys, work):
    (work / "s.toml").write_text(f'name = "../evil"\n[[objects]]\n{CUBE}')
    assert main(["shaders", "s.toml"]) == 0
    assert (work / "out" / "shaders-s").is_dir()
    assert not (work.parent / "evil").exists() and not list(work.glob("**/shaders-.*"))


def test_a_built_in_scene_writes_under_its_name(capsys, work):
    assert main(render("-q")) == 0
    assert [p.relative_to(work).as_posix() for p in work.rglob("*")] == ["out", "out/sphere.png"]


# -- 3. more lights than GL guarantees uniform storage for ------------------------------------

def lights_scene(directional: int, point: int, shading: str = "phong") -> str:
    lights = ['[[lights]]\ntype = "directional"\ndirection = [0, 0, -1]\nintensity = 0.01\n'] * directional
    lights += ['[[lights]]\ntype = "point"\nposition = [0, 0, 3]\nintensity = 0.01\n'] * point
    return ("".join(lights) + f'[[objects]]\n{TORUS}'
            f'material = {{ shading = "{shading}", ks = 0.5 }}\n')


# The torus casts and receives and can shadow itself (it is not convex: a convex solid lit
# from outside could not, and its lights would get no map: renderer/core/shadow_casting.py),
# so that each light has a shadow map (24 more components for a directional light, 36 for a
# point light: renderer/core/gl_rules.py).
# 3000 point lights through the reference is the full run's (--all): the GPU holds that count
# in the default run, the reference the three counts at the limit (the same check, one line).
@pytest.mark.parametrize("backend, directional, point, used", [
    pytest.param(backend, *counts, marks=[pytest.mark.slow] if (backend, counts[1]) == ("reference", 3000) else [],
                 id=f"{counts[0]}-{counts[1]}-{counts[2]}-{backend}")
    for counts in [(0, 3000, 144000), (29, 0, 928), (0, 19, 912), (14, 10, 928)]
    for backend in ("gpu", "reference")])
def test_more_lights_than_the_limit_is_one_line(capsys, work, backend, directional, point, used):
    (work / "lights.toml").write_text(lights_scene(directional, point))
    line = refused(capsys, ["render", "lights.toml", "--size", "16x12", "--backend", backend], work)
    assert line == (f"renderer: lights.toml: lights: too many lights: {directional} directional "
                    f"and {point} point lights take {used} uniform components (8 per directional "
                    f"light, 12 per point light, 24 and 36 more for the shadows of each; "
                    f"{directional} directional and {point} point lights have shadows); the "
                    f"limit is 896 (GL's guaranteed 1024 per shader stage less 128 for the other "
                    f"uniforms), e.g. 112 directional or 74 point lights without shadows, 28 or "
                    f"18 with; set `shadows = false` on some lights")


@pytest.mark.parametrize("backend", ["gpu", "reference"])
def test_a_gouraud_receiver_with_too_many_lights_is_one_line(capsys, work, backend):
    """Its varyings (renderer/core/gl_rules.py, too_many_varyings): 7 lights, two-sided, take
    (1 + 7) x 2 + 2 = 18 vec4 slots, over GL's guaranteed 16."""
    scene = lights_scene(7, 0, "gouraud").replace('shading = "gouraud"', 'shading = "gouraud", two_sided = true')
    (work / "lights.toml").write_text(scene)
    line = refused(capsys, ["render", "lights.toml", "--size", "16x12", "--backend", backend], work)
    assert line == ("renderer: lights.toml: objects[0]: too many lights for a two-sided gouraud object "
                    "that receives shadows: with 7 directional and 0 point lights its varyings take "
                    "18 vec4 slots ((1 + 7) terms x 2 sides + position and normal), the limit is 16 "
                    "(GL's guaranteed 64 vertex output components); set `shadows = false` on the "
                    "lights, `receives_shadows = false` on the object, or use phong shading")


def test_a_scene_made_in_python_is_held_to_the_same_limit(gl_contexts):
    import reference
    from renderer.core.scene import PointLight
    from renderer.core.shadow_settings import Shadow
    from renderer.errors import SceneError
    from renderer.gpu.pipeline import GpuRenderer
    scene = load_scene("sphere")
    scene.point_lights = [PointLight(shadow=Shadow(enabled=False))] * 75
    with pytest.raises(SceneError, match="too many lights"):
        reference.render(scene, 8, 6)
    with pytest.raises(SceneError, match="too many lights"):
        GpuRenderer(scene, 8, 6, context=gl_contexts["egl"])


@pytest.mark.parametrize("shading", ["flat", "gouraud", "phong"])
@pytest.mark.parametrize("directional, point", [(112, 0), (0, 74), (56, 37)])
def test_lights_up_to_the_limit_compile_and_render(gl_contexts, work, shading, directional, point):
    """The limits without shadows: the lights, made in Python, have them off."""
    from renderer.core.scene import DirectionalLight, PointLight
    from renderer.core.shadow_settings import Shadow
    from renderer.gpu.pipeline import GpuRenderer
    (work / "lights.toml").write_text(lights_scene(0, 0, shading))
    scene = load_scene(work / "lights.toml")
    off, dim = Shadow(enabled=False), (0.01, 0.01, 0.01)
    scene.directional_lights = [DirectionalLight((0, 0, -1), dim, off)] * directional
    scene.point_lights = [PointLight((0, 0, 3), dim, shadow=off)] * point
    for ctx in gl_contexts.values():
        with GpuRenderer(scene, 16, 12, context=ctx) as gpu:
            assert gpu.render().rgba8[..., 3].any()


@pytest.mark.slow                       # 108 cube faces drawn: about 1 s a case
@pytest.mark.parametrize("directional, point", [(28, 0), (0, 18), (14, 9)])
def test_lights_with_shadows_up_to_the_limit_compile_and_render(gl_contexts, work, directional, point):
    from renderer.gpu.pipeline import GpuRenderer
    (work / "lights.toml").write_text(lights_scene(directional, point, "phong"))
    scene = load_scene(work / "lights.toml")
    for ctx in gl_contexts.values():
        with GpuRenderer(scene, 16, 12, context=ctx) as gpu:
            assert gpu.render().rgba8[..., 3].any()
            assert all(variant.shadows for variant in gpu.programs)


# -- the ray tracer's inputs (issue 14, "Bad input") -------------------------------------------

RAYTRACE = ["--method", "raytrace"]
ENERGY_RULE = ("the energy rule is kr + kt <= 1 in each channel (the reflected and refracted "
               "rays together carry at most the light that arrives)")


@pytest.mark.parametrize("shape, material, key, reason", [
    ('{ type = "sphere", radius = -1.0 }', "{}", "objects[0].shape.radius", "must be > 0, got -1"),
    ('{ type = "plane", normal = [0, 0, 0] }', "{}", "objects[0].shape.normal",
     "must not be zero length: the plane is P·N + d = 0"),
    ('{ type = "sphere" }', "{ kt = 0.5, ior = 0 }", "objects[0].material.ior", "must be > 0, got 0"),
    ('{ type = "sphere" }', "{ kt = 0.5, ior = -1.33 }", "objects[0].material.ior", "must be > 0, got -1.33"),
    ('{ type = "sphere" }', "{ kr = 0.6, kt = [0.3, 0.5, 0.3] }", "objects[0].material.kt",
     f"kr + kt is 1.1 in channel g; {ENERGY_RULE}"),
    ('{ type = "sphere" }', "{ kr = 0.5, gloss = -10 }", "objects[0].material.gloss",
     "must be a number >= 0 or inf (a mirror), got -10"),
    ('{ type = "sphere" }', "{ kr = 0.5, gloss = nan }", "objects[0].material.gloss",
     "must be a number >= 0 or inf (a mirror), got nan"),
], ids=["negative radius", "zero normal", "ior 0", "ior negative", "kr + kt > 1", "gloss negative",
        "gloss nan"])
def test_a_bad_ray_traced_scene_is_one_line_naming_file_key_and_reason(capsys, work, shape, material,
                                                                      key, reason):
    (work / "rt.toml").write_text(f"[[objects]]\nshape = {shape}\nmaterial = {material}\n")
    assert refused(capsys, render("rt.toml", *RAYTRACE), work) == f"renderer: rt.toml: {key}: {reason}"


@pytest.mark.parametrize("command", ["render", "compare"])
@pytest.mark.parametrize("option, reason", [
    (["--spp", "0"], "--spp 0: samples per pixel must be between 1 and 256, got 0"),
    (["--max-depth", "-1"], "--max-depth -1: must be between 0 and 64, got -1"),
    (["--max-depth", "65"], "--max-depth 65: must be between 0 and 64, got 65"),
    (["--pattern", "hexagonal"], "--pattern hexagonal: sample pattern must be one of regular, random, "
                                 "jittered, poisson, adaptive, got 'hexagonal'"),
    (["--light-samples", "0"], "--light-samples 0: light samples per hit must be a whole number "
                               "from 1 to 64, got 0"),
    (["--light-samples", "65"], "--light-samples 65: light samples per hit must be a whole number "
                                "from 1 to 64, got 65"),
    (["--light-samples", "two"], "argument --light-samples: invalid int value: 'two'"),
], ids=["spp 0", "max depth -1", "max depth 65", "unknown pattern", "light samples 0",
        "light samples 65", "light samples not a number"])
def test_a_bad_ray_tracer_option_is_its_reason_then_the_usage(capsys, work, command, option, reason):
    """Argument errors print the reason on one line (the option named), then the usage line
    (tests/test_cli.py); status 2, nothing written. 65 is absurd: renderer/core/ray_depth.py's
    MAX_DEPTH_LIMIT is 64."""
    args = [command, "sphere", "--method", "raytrace", "--size", "16x12", *option]
    before = sorted(p.name for p in work.iterdir())
    assert main(args) == 2
    first, usage = capsys.readouterr().err.splitlines()
    assert first.startswith(f"renderer {command}: {reason}") and usage.startswith(f"usage: renderer {command}")
    assert sorted(p.name for p in work.iterdir()) == before


@pytest.mark.parametrize("command", ["render", "compare"])
def test_light_samples_are_for_the_ray_tracer(capsys, work, command):
    """--light-samples without --method raytrace (the rasteriser lights from each area light's
    centre): its reason, then the usage; status 2, nothing written."""
    before = sorted(p.name for p in work.iterdir())
    assert main([command, "sphere", "--size", "16x12", "--light-samples", "4"]) == 2
    first, usage = capsys.readouterr().err.splitlines()
    assert first.startswith(f"renderer {command}: --light-samples 4: is for method raytrace, not raster")
    assert usage.startswith(f"usage: renderer {command}")
    assert sorted(p.name for p in work.iterdir()) == before
