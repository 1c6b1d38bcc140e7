"""renderer/gpu/shaders.py: include expansion, #define placement, variants; the glsl/ files' headers."""

import re

import numpy as np
import pytest

from renderer.core.resources import assets_dir, glsl_dir
from renderer.core.scene import DirectionalLight, Material, PointLight, Scene
from renderer.gpu.shaders import (FILE_CONSTANTS, ProgramCache, ShaderSourceError, ShaderVariant,
                                  program_source, program_sources, shader_source)

TWINS = {"vertex.glsl": "reference/vertex.py", "geometry.glsl": "reference/geometry.py",
         "fragment.glsl": "reference/fragment.py", "lighting.glsl": "reference/lighting.py"}
# The ray tracer's stages (includes: no #version of their own).
RAYTRACE_TWINS = {"raytrace/random.glsl": "reference/raytrace/random.py",
                  "raytrace/pathtrace.glsl": "reference/raytrace/pathtrace.py",
                  "raytrace/intersect.glsl": "reference/raytrace/intersect.py",
                  "raytrace/camera.glsl": "reference/raytrace/camera.py",
                  "raytrace/optics.glsl": "reference/raytrace/optics.py",
                  "raytrace/bvh.glsl": "reference/raytrace/bvh.py",
                  "raytrace/sampling.glsl": "reference/raytrace/sampling.py",
                  "raytrace/warp.glsl": "reference/raytrace/warp.py",
                  "raytrace/area_lights.glsl": "reference/raytrace/area_lights.py",
                  "raytrace/glossy.glsl": "reference/raytrace/glossy.py",
                  "raytrace/motion.glsl": "reference/raytrace/motion.py",
                  "raytrace/textures.glsl": "reference/raytrace/textures.py",
                  "raytrace/trace.glsl": "reference/raytrace/trace.py"}


def write(folder, files):
    for name, text in files.items():
        (folder / name).write_text(text)
    return folder


def code_lines(text):
    """The lines that are not #line directives (what the author wrote, plus our defines)."""
    return [line for line in text.splitlines() if not line.startswith("#line")]


def test_include_is_replaced_by_the_file(tmp_path):
    write(tmp_path, {"main.glsl": '// main\n#version 330 core\n#include "lib.glsl"\nvoid main() {}\n',
                     "lib.glsl": "// lib\nfloat helper() { return 1.0; }\n"})
    source = shader_source("main.glsl", directory=tmp_path)
    assert code_lines(source.text) == ["// main", "#version 330 core", "// lib",
                                       "float helper() { return 1.0; }", "void main() {}"]
    assert "#include" not in source.text
    assert [name.rsplit("/", 1)[-1] for name in source.files] == ["main.glsl", "lib.glsl"]


def test_line_directives_point_back_at_the_files(tmp_path):
    write(tmp_path, {"main.glsl": '#version 330 core\n#include "lib.glsl"\nvoid main() {}\n',
                     "lib.glsl": "float helper() { return 1.0; }\n"})
    lines = shader_source("main.glsl", directory=tmp_path).text.splitlines()
    # lib.glsl is source string 1 from its line 1; main.glsl resumes at its line 3.
    assert lines[lines.index("float helper() { return 1.0; }") - 1] == "#line 1 1"
    assert lines[lines.index("void main() {}") - 1] == "#line 3 0"


def test_nested_and_repeated_includes_expand_once(tmp_path):
    write(tmp_path, {"main.glsl": '#version 330 core\n#include "a.glsl"\n#include "b.glsl"\n',
                     "a.glsl": '#include "b.glsl"\nfloat a;\n',
                     "b.glsl": "float b;\n"})
    text = shader_source("main.glsl", directory=tmp_path).text
    assert text.count("float b;") == 1
    assert text.index("float b;") < text.index("float a;")


def test_unknown_include_names_file_line_and_target(tmp_path):
    write(tmp_path, {"main.glsl": '#version 330 core\n\n#include "missing.glsl"\n'})
    with pytest.raises(ShaderSourceError) as error:
        shader_source("main.glsl", directory=tmp_path)
    message = str(error.value)
    assert "main.glsl:3" in message and '"missing.glsl"' in message and "no such file" in message


def test_include_cycle_is_an_error(tmp_path):
    write(tmp_path, {"main.glsl": '#version 330 core\n#include "a.glsl"\n',
                     "a.glsl": '#include "b.glsl"\n', "b.glsl": '#include "a.glsl"\n'})
    with pytest.raises(ShaderSourceError, match="include cycle"):
        shader_source("main.glsl", directory=tmp_path)


def test_malformed_include_is_an_error(tmp_path):
    write(tmp_path, {"main.glsl": "#version 330 core\n#include <lib.glsl>\n"})
    with pytest.raises(ShaderSourceError, match="malformed include"):
        shader_source("main.glsl", directory=tmp_path)


def test_defines_go_right_after_the_version_line(tmp_path):
    write(tmp_path, {"main.glsl": "// a comment first\n#version 330 core\nvoid main() {}\n"})
    text = shader_source("main.glsl", {"TWO_SIDED": True, "NUM_POINT_LIGHTS": 2,
                                       "LINEAR_OUTPUT": False}, directory=tmp_path).text
    lines = text.splitlines()
    assert lines[:2] == ["// a comment first", "#version 330 core"]
    assert set(lines[2:4]) == {"#define TWO_SIDED", "#define NUM_POINT_LIGHTS 2"}
    assert lines[4] == "#line 3 0"                    # the author's line 3 keeps its number
    assert "LINEAR_OUTPUT" not in text                # False leaves a flag out


def test_a_files_python_constants_are_defined_before_it_wherever_it_is_included(tmp_path):
    """FILE_CONSTANTS: shadow/lookup.glsl's, right before its text (its line numbers kept),
    in a test's shader that includes it too; a float as a decimal that reads back as it."""
    write(tmp_path, {"main.frag": '#version 330 core\n#include "shadow/lookup.glsl"\nvoid main() {}\n'})
    lines = shader_source("main.frag", directory=tmp_path).text.splitlines()
    first = lines.index("#define SHADOW_MAX_SLOPE 16.0")
    assert lines[first:first + 4] == ["#define SHADOW_MAX_SLOPE 16.0", "#define SHADOW_SQRT2 1.41421356",
                                      "#define SHADOW_CREASE_CAP 1.0", "#line 1 1"]
    with pytest.raises(ShaderSourceError, match="FILE_CONSTANTS"):
        shader_source("main.frag", {"SHADOW_MAX_SLOPE": 8.0}, directory=tmp_path)
    write(tmp_path, {"floats.frag": "#version 330 core\nvoid main() {}\n"})
    text = shader_source("floats.frag", {"X": np.float32(0.1), "N": 3}, directory=tmp_path).text
    assert f"#define X {float(np.float32(0.1))!r}" in text and "#define N 3" in text


def test_the_shared_constants_are_written_only_in_python():
    """Each FILE_CONSTANTS name and the output pass's (PASS_CONSTANTS, colour.comp's
    GROUP_SIZE) is used in its file and #defined by no file of glsl/."""
    from renderer.gpu.output import PASS_CONSTANTS
    everything = "\n".join(p.read_text() for p in glsl_dir().rglob("*") if p.is_file())
    for file, constants in FILE_CONSTANTS.items():
        assert all(re.search(rf"\b{name}\b", (glsl_dir() / file).read_text()) for name in constants)
    for name in {*PASS_CONSTANTS, *(n for c in FILE_CONSTANTS.values() for n in c)}:
        assert re.search(rf"\b{name}\b", everything) and not re.search(rf"#\s*define\s+{name}\b", everything)


def test_missing_version_line_is_an_error(tmp_path):
    write(tmp_path, {"main.glsl": "void main() {}\n"})
    with pytest.raises(ShaderSourceError, match="no #version"):
        shader_source("main.glsl", {"X": 1}, directory=tmp_path)


def test_glsl_files_name_their_numpy_twin_and_version():
    for name, twin in TWINS.items():
        lines = (glsl_dir() / name).read_text().splitlines()
        assert lines[0] == f"// Twin: {twin}", name
        if name != "lighting.glsl":                   # the include has no #version of its own
            assert re.fullmatch(r"#version (330|4[0-6]0) core", lines[1]), name


def test_real_sources_expand_the_lighting_include():
    variant = ShaderVariant("phong", two_sided=True, num_directional_lights=2, num_point_lights=0)
    sources = program_sources(variant)
    assert set(sources) == {"vertex_shader", "fragment_shader"}    # no geometry stage
    fragment = sources["fragment_shader"].text
    assert "vec3 lighting(vec3 P, vec3 N)" in fragment and "#include" not in fragment
    assert "#define NUM_DIRECTIONAL_LIGHTS 2" in fragment and "#define TWO_SIDED" in fragment


def test_only_flat_links_a_geometry_shader():
    assert "geometry_shader" in program_sources(ShaderVariant("flat"))
    for shading in ("gouraud", "phong"):
        assert "geometry_shader" not in program_sources(ShaderVariant(shading))


def test_variant_from_scene_and_program_source():
    scene = Scene(directional_lights=[DirectionalLight()], point_lights=[PointLight(), PointLight()])
    material = Material(shading="gouraud", two_sided=True)
    variant = ShaderVariant.for_material(scene, material)
    assert variant == ShaderVariant("gouraud", True, 1, 2, False)
    vertex, geometry, fragment = program_source(scene, material)
    assert geometry is None and "#define SHADING_GOURAUD" in vertex and "#define NUM_POINT_LIGHTS 2" in fragment


def test_unknown_shading_mode_is_rejected():
    with pytest.raises(ValueError, match="shading"):
        ShaderVariant("toon")


def test_every_variant_compiles_and_is_cached(gl_contexts):
    from renderer.gpu.context import activate
    ctx = gl_contexts["egl"]
    activate(ctx)
    cache = ProgramCache(ctx)
    try:
        for shading in ("flat", "gouraud", "phong"):
            for two_sided in (False, True):
                for lights in ((0, 0), (1, 0), (0, 2), (3, 1)):
                    for linear in (False, True):
                        variant = ShaderVariant(shading, two_sided, *lights, linear)
                        program = cache.get(variant)
                        assert cache.get(variant) is program
                        assert bool(program.geometry_vertices) == (shading == "flat")
        assert len(cache) == 3 * 2 * 4 * 2
    finally:
        cache.release()


def test_a_uniform_the_variant_declares_is_given_a_value_or_the_draw_is_refused(gl_contexts):
    """The rasteriser writes every uniform a program's #defines declare (GpuRenderer._plan asks
    ProgramCache.check_values): one left without a value would read zero, silently."""
    from renderer.core.builtin import resolve_scene
    from renderer.core.scene_file import load_scene
    from renderer.gpu.context import activate
    from renderer.gpu.uniforms import frame_uniform_values, object_uniform_values
    ctx = gl_contexts["egl"]
    activate(ctx)
    scene = load_scene(resolve_scene("sphere"))
    matrices = scene.matrices(16, 12)
    obj = scene.objects[0]
    names = (frame_uniform_values(scene, matrices).keys()
             | object_uniform_values(obj, matrices.objects[0]).keys())
    cache = ProgramCache(ctx)
    try:
        variant = ShaderVariant.for_material(scene, obj.material, False)
        cache.get(variant)
        cache.check_values(variant, names)                      # every one has its value
        with pytest.raises(ShaderSourceError, match="no value for u_ambient, which its GLSL declares"):
            cache.check_values(variant, names - {"u_ambient"})
    finally:
        cache.release()


def test_resource_folders_are_found():
    assert (glsl_dir() / "vertex.glsl").is_file()
    assert assets_dir().is_dir() and assets_dir().name == "assets"


def test_raytrace_stages_and_their_twins_name_each_other():
    root = glsl_dir().parent
    for name, twin in RAYTRACE_TWINS.items():
        assert (glsl_dir() / name).read_text().splitlines()[0] == f"// Twin: {twin}", name
        assert (root / twin).read_text().splitlines()[0] == f'"""# Twin: glsl/{name}', twin
    assert sorted(p.relative_to(glsl_dir()).as_posix()
                  for p in (glsl_dir() / "raytrace").glob("*.glsl")) == sorted(RAYTRACE_TWINS)


def test_include_from_a_subfolder_and_from_glsl_anywhere(tmp_path):
    """A file in a subfolder includes its neighbours by name; a file elsewhere (a test's shader)
    reaches glsl/'s files by their path under glsl/; the folder beside the file comes first."""
    (tmp_path / "sub").mkdir()
    write(tmp_path, {"main.glsl": '#version 330 core\n#include "sub/a.glsl"\nvoid main() {}\n',
                     "sub/a.glsl": '#include "b.glsl"\nfloat a() { return b(); }\n',
                     "sub/b.glsl": "float b() { return 2.0; }\n"})
    source = shader_source("main.glsl", directory=tmp_path)
    assert code_lines(source.text) == ["#version 330 core", "float b() { return 2.0; }",
                                       "float a() { return b(); }", "void main() {}"]
    write(tmp_path, {"test.frag": '#version 330 core\n#include "raytrace/random.glsl"\n'
                                  'void main() {}\n'})
    source = shader_source("test.frag", directory=tmp_path)
    assert "uint pcg_hash(uint v)" in source.text
    assert source.files[1] == "glsl/raytrace/random.glsl"
    (tmp_path / "raytrace").mkdir()
    write(tmp_path, {"raytrace/random.glsl": "float mine() { return 1.0; }\n",
                     "other.frag": '#version 330 core\n#include "raytrace/random.glsl"\n'})
    source = shader_source("other.frag", directory=tmp_path)     # the neighbour wins
    assert "float mine()" in source.text and "pcg_hash" not in source.text
