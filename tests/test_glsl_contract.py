"""The names the GLSL shaders share with their NumPy twin and with the GPU path.

The GLSL in glsl/ and the twin in reference/ use the same names on purpose (v_world_position,
u_ka, u_point_position, ...). Nothing else makes them agree: a renamed varying or uniform
still compiles, GL drops a uniform that no program has, and moderngl skips uploading a
name a program lacks. So the `in`, `out` and `uniform` declarations of each GLSL file
(every one in the file, whatever the #defines select) are held against:

- the stage before: each `in` of geometry.glsl and fragment.glsl is an `out` of the stage
  before it (vertex -> geometry -> fragment), of the same type and interpolation, and each
  `out` of the vertex and geometry stages is read by a later stage;
- the twin: the vertex stage's `out`s are fields of reference.vertex.VertexOutputs, the
  geometry stage's of reference.geometry.TriangleOutputs, the fragment stage's `in`s are
  fields of either; the vertex attributes and matrices are the parameters of
  reference.vertex.shade_vertices; the material and light uniforms are the fields of
  reference.lighting.MaterialUniforms and Lights (a light array in GLSL is an array of one
  row per light in the twin); the material lookup's (texture.glsl) are the parameters of
  reference.texture.lookup_coordinates;
- the GPU path: every declared uniform is uploaded by renderer/gpu/pipeline.py and every
  uploaded name is declared; the vertex attributes are the ones GpuRenderer binds.

Each failure names the GLSL file, the line and the name that drifted.
"""

from __future__ import annotations

import inspect
import re
from dataclasses import dataclass, fields, replace

import moderngl
import numpy as np
import pytest

from reference.fragment import shade_fragments
from reference.geometry import TriangleOutputs, shade_triangles
from reference.lighting import Lights, MaterialUniforms
from reference.texture import lookup_coordinates
from reference.vertex import VertexOutputs, shade_vertices
from renderer.core.builtin import builtin_scenes
from renderer.core.resources import glsl_dir
from renderer.core.scene import SHADING_MODES
from renderer.core.scene_file import load_scene
from renderer.core.shadows import plan_shadows, shadow_layout
from renderer.core.textures import MaterialTexture, checkerboard
from renderer.core.uniforms import SHADOW_PASS_UNIFORMS, UNIFORM_TYPES
from renderer.gpu import GpuRenderer
from renderer.gpu.shaders import ALL_FEATURES_LIGHTS

STAGES = ("vertex.glsl", "geometry.glsl", "fragment.glsl")      # in pipeline order
LIGHTING = "lighting.glsl"
TEXTURE = "texture.glsl"                 # the material lookup (TEXTURED)
SHADOW_FILES = ("shadow/lookup.glsl", "shadow/depth.vert")   # the lookup and the depth pass
# A scene with both kinds of light, specular materials and all three shading modes (the GPU
# path's checks give one of its materials a texture: every_feature_scene).
EVERY_FEATURE_SCENE = "hierarchy"
# Uniforms of the GPU path alone, and why the twin has no field for them.
GPU_ONLY_UNIFORMS = {
    "u_num_directional_lights": "all-features build: the light count at run time; the twin's "
                                "Lights arrays have one row per light",
    "u_num_point_lights": "all-features build: as u_num_directional_lights",
    "u_two_sided": "all-features build: two-sidedness at run time; the twin reads "
                   "Material.two_sided",
    "u_directional_shadow_maps": "the directional maps' texture unit; the twin reads its "
                                 "array of layers",
    "u_point_shadow_maps": "the point lights' maps' texture unit; the twin reads its array of layers",
    "u_texture": "the material texture's unit; the twin reads the MaterialTexture",
    "u_face_normals": "the facet normals' texture unit; the twin reads renderer.core.facets."
                      "face_normals of the mesh",
    "u_shadow_facets": "whether the object is a mesh (1) or an analytic shape (0); the twin "
                       "leaves a shape's ObjectVaryings.facet_normals out",
}


def every_feature_scene():
    """EVERY_FEATURE_SCENE with its first object's material textured (its primitives have UVs)."""
    scene = load_scene(builtin_scenes()[EVERY_FEATURE_SCENE])
    first = scene.objects[0]
    texture = MaterialTexture(checkerboard(2, ((1.0, 1.0, 1.0), (0.5, 0.5, 0.5)), 2))
    return replace(scene, objects=[replace(first, material=replace(first.material, texture=texture)),
                                   *scene.objects[1:]])


# -- what the GPU path uses (change here if renderer/gpu moves them) ------------------------------

def uploaded_uniform_names() -> set[str]:
    """Every uniform name the GPU path uploads for a scene with every feature, in the
    specialised and in the all-features build."""
    from renderer.gpu.uniforms import SHADOW_MAPS_UNITS, frame_uniform_values, object_uniform_values
    scene = every_feature_scene()
    matrices = scene.matrices(64, 48)
    shadows = plan_shadows(scene, matrices, shadow_layout(scene, 64, 48)).uniforms
    names = set(frame_uniform_values(scene, matrices, shadows=shadows))
    names |= set(frame_uniform_values(scene, matrices, light_slots=ALL_FEATURES_LIGHTS))
    names |= set(SHADOW_PASS_UNIFORMS)          # renderer/gpu/shadow_maps.py, per pass and object
    # the stacks' samplers, pointed at their units once at link (set_shadow_sampler_units)
    names |= {f"u_{kind}_shadow_maps" for kind in SHADOW_MAPS_UNITS}
    plan = plan_shadows(scene, matrices, shadow_layout(scene, 64, 48))
    for index, (obj, object_matrices) in enumerate(zip(scene.objects, matrices.objects)):
        names |= set(object_uniform_values(obj, object_matrices, plan.self_masks(index)))
    return names


def bound_attribute_names(ctx) -> set[str]:
    """The vertex attributes GpuRenderer binds (the names it gives ctx.vertex_array) when it
    draws a scene in every shading mode."""
    bound = set()
    original = moderngl.Context.vertex_array

    def recording(self, program, content, *args, **kwargs):
        for _buffer, _format, *names in content:
            bound.update(names)
        return original(self, program, content, *args, **kwargs)

    scene = every_feature_scene()
    with pytest.MonkeyPatch.context() as patch:
        patch.setattr(moderngl.Context, "vertex_array", recording)
        for mode in SHADING_MODES:
            with GpuRenderer(scene.with_shading(mode), 16, 16, context=ctx) as gpu:
                gpu.render()
    return bound


# -- reading the declarations ---------------------------------------------------------------------

@dataclass(frozen=True)
class Declaration:
    file: str
    line: int
    storage: str                 # "in", "out" or "uniform"
    type: str                    # "vec3", "mat4", ...
    name: str
    array: str | None            # None: not an array; "" for name[]; else the size as written
    interpolation: str = "smooth"     # of an in or out: GLSL's default, "flat" or "noperspective"
    layout: str = ""             # the layout( ) qualifier's contents, if any

    @property
    def where(self) -> str:
        return f"glsl/{self.file}:{self.line}"


STORAGE = {"in", "out", "uniform"}
INTERPOLATION = {"smooth", "flat", "noperspective"}
OTHER_QUALIFIERS = {"centroid", "sample", "invariant", "highp", "mediump", "lowp"}
_LAYOUT = re.compile(r"^layout\s*\(([^)]*)\)\s*")
_DECLARATOR = re.compile(r"^(\w+)\s*(?:\[\s*([\w\s*]*?)\s*\])?$")     # [6 * N] too


def without_comments_and_directives(text: str) -> str:
    """The text with comments and preprocessor lines blanked out, newlines kept (so line
    numbers hold): every declaration counts, whichever #if branch it is in."""
    text = re.sub(r"/\*.*?\*/", lambda m: re.sub(r"[^\n]", " ", m.group()), text, flags=re.S)
    text = re.sub(r"//[^\n]*", "", text)
    return re.sub(r"(?m)^[ \t]*#[^\n]*", "", text)


def top_level_statements(text: str):
    """(line, statement) for each `;`-terminated statement outside any braces."""
    depth, start = 0, 0
    for index, char in enumerate(text):
        if char in "{}":
            depth += 1 if char == "{" else -1
            start = index + 1
        elif char == ";" and depth == 0:
            statement = text[start:index]
            if statement.strip():
                leading = len(statement) - len(statement.lstrip())
                yield text.count("\n", 0, start + leading) + 1, " ".join(statement.split())
            start = index + 1


def declarations(file: str, text: str) -> list[Declaration]:
    """The `in`, `out` and `uniform` variables declared in one GLSL file."""
    found = []
    for line, statement in top_level_statements(without_comments_and_directives(text)):
        layout = ""
        match = _LAYOUT.match(statement)
        if match:
            layout, statement = " ".join(match.group(1).split()), statement[match.end():]
        words = statement.split(" ", 1)
        qualifiers = []
        while words[0] in STORAGE | INTERPOLATION | OTHER_QUALIFIERS and len(words) > 1:
            qualifiers.append(words[0])
            words = words[1].split(" ", 1)
        storage = [q for q in qualifiers if q in STORAGE]
        if not storage:                      # layout(triangles) in; a constant; a prototype
            continue
        if len(words) < 2:
            raise ValueError(f"glsl/{file}:{line}: cannot read the declaration {statement!r}")
        type_, declarators = words
        interpolation = ("" if storage[0] == "uniform"
                         else next((q for q in qualifiers if q in INTERPOLATION), "smooth"))
        for declarator in declarators.split(","):
            parsed = _DECLARATOR.match(declarator.strip())
            if not parsed:
                raise ValueError(f"glsl/{file}:{line}: cannot read the declaration {statement!r}")
            name, size = parsed.groups()
            array = None if "[" not in declarator else (size or "")
            found.append(Declaration(file, line, storage[0], type_, name, array, interpolation,
                                     layout))
    return found


def read_glsl() -> dict[str, str]:
    return {name: (glsl_dir() / name).read_text(encoding="utf-8")
            for name in (*STAGES, LIGHTING, TEXTURE, *SHADOW_FILES)}


def parse(sources: dict[str, str]) -> dict[str, list[Declaration]]:
    return {name: declarations(name, text) for name, text in sources.items()}


def of(decls: list[Declaration], storage: str) -> dict[str, Declaration]:
    """name -> declaration (of a name declared in several #if branches, the last: they are
    checked to be alike: declared_differently_in_two_branches)."""
    return {d.name: d for d in decls if d.storage == storage}


def all_uniforms(parsed) -> dict[str, Declaration]:
    return {d.name: d for decls in parsed.values() for d in decls if d.storage == "uniform"}


# -- the checks, each a list of what drifted ------------------------------------------------------

def declared_differently_in_two_branches(parsed) -> list[str]:
    """A name declared more than once in a file (in #if branches) is declared alike."""
    problems = []
    for decls in parsed.values():
        first = {}
        for decl in decls:
            seen = first.setdefault((decl.storage, decl.name), decl)
            alike = (seen.type, seen.array, seen.interpolation) == \
                (decl.type, decl.array, decl.interpolation)
            if not alike:
                problems.append(f"{decl.where}: {decl.storage} {decl.name} is declared otherwise "
                                f"at {seen.where}")
    return problems


def inputs_not_from_the_stage_before(parsed) -> list[str]:
    """Each `in` of geometry.glsl is an `out` of vertex.glsl, as an interface array; each `in`
    of fragment.glsl is an `out` of geometry.glsl (flat shading) or vertex.glsl (the others),
    of the same type and interpolation."""
    vertex_out = of(parsed["vertex.glsl"], "out")
    geometry_out = of(parsed["geometry.glsl"], "out")
    problems = []
    for name, decl in of(parsed["geometry.glsl"], "in").items():
        source = vertex_out.get(name)
        if source is None:
            problems.append(f"{decl.where}: in {name} is no out of glsl/vertex.glsl "
                            f"({', '.join(sorted(vertex_out))})")
        elif decl.array != "" or decl.type != source.type:
            brackets = "[]" if decl.array == "" else ""
            problems.append(f"{decl.where}: in {decl.type} {name}{brackets} should be "
                            f"{source.type} {name}[] (the out of {source.where})")
    for name, decl in of(parsed["fragment.glsl"], "in").items():
        source = geometry_out.get(name) or vertex_out.get(name)
        if source is None:
            problems.append(f"{decl.where}: in {name} is no out of glsl/geometry.glsl or "
                            f"glsl/vertex.glsl ({', '.join(sorted(geometry_out | vertex_out))})")
        elif (decl.type, decl.interpolation) != (source.type, source.interpolation):
            problems.append(f"{decl.where}: in {decl.interpolation} {decl.type} {name} differs "
                            f"from the out of {source.where}: {source.interpolation} {source.type}")
    return problems


def outputs_nobody_reads(parsed) -> list[str]:
    """Each `out` of vertex.glsl and geometry.glsl is an `in` of a later stage."""
    geometry_in = set(of(parsed["geometry.glsl"], "in"))
    fragment_in = set(of(parsed["fragment.glsl"], "in"))
    read_by = {"vertex.glsl": geometry_in | fragment_in, "geometry.glsl": fragment_in}
    return [f"{decl.where}: out {name} is read by no later stage"
            for stage, readers in read_by.items()
            for name, decl in of(parsed[stage], "out").items() if name not in readers]


def names_missing_from(decls, names: set[str], twin: str) -> list[str]:
    """Each declaration's name is one of `names` (the twin's, described by `twin`)."""
    return [f"{decl.where}: {decl.storage} {decl.name} is not in {twin} "
            f"({', '.join(sorted(names))})" for decl in decls if decl.name not in names]


def field_names(cls) -> set[str]:
    return {field.name for field in fields(cls)}


def parameters(function) -> set[str]:
    return set(inspect.signature(function).parameters)


def varyings_not_in_the_twin(parsed) -> list[str]:
    problems = names_missing_from(of(parsed["vertex.glsl"], "out").values(),
                                  field_names(VertexOutputs), "reference.vertex.VertexOutputs")
    problems += names_missing_from(of(parsed["geometry.glsl"], "in").values(),
                                   parameters(shade_triangles),
                                   "the parameters of reference.geometry.shade_triangles")
    problems += names_missing_from(of(parsed["geometry.glsl"], "out").values(),
                                   field_names(TriangleOutputs),
                                   "reference.geometry.TriangleOutputs")
    problems += names_missing_from(of(parsed["fragment.glsl"], "in").values(),
                                   field_names(VertexOutputs) | field_names(TriangleOutputs),
                                   "the fields of VertexOutputs or TriangleOutputs that "
                                   "reference/fragment.py reads")
    return problems


def uniforms_not_in_the_twin(parsed) -> list[str]:
    """vertex.glsl's own uniforms are parameters of shade_vertices; lighting.glsl's are
    fields of Lights or MaterialUniforms, or u_eye (a parameter of every stage of the twin
    that lights); fragment.glsl's are the GPU path's alone (GPU_ONLY_UNIFORMS); texture.glsl's
    are parameters of lookup_coordinates, but its texture unit."""
    vertex_parameters = parameters(shade_vertices)
    every_lighting_stage = parameters(shade_vertices) & parameters(shade_triangles) & \
        parameters(shade_fragments)                             # u_eye (and lights)
    lighting_names = field_names(Lights) | field_names(MaterialUniforms) | every_lighting_stage
    problems = names_missing_from(of(parsed["vertex.glsl"], "uniform").values(), vertex_parameters,
                                  "the parameters of reference.vertex.shade_vertices")
    problems += names_missing_from(
        [d for d in of(parsed[LIGHTING], "uniform").values() if d.name not in GPU_ONLY_UNIFORMS],
        lighting_names, "reference.lighting.Lights or MaterialUniforms, nor a parameter of "
                        "every stage of the twin that lights")
    problems += names_missing_from(
        of(parsed["fragment.glsl"], "uniform").values(), set(GPU_ONLY_UNIFORMS) | vertex_parameters,
        "GPU_ONLY_UNIFORMS of this test or the parameters of reference.vertex.shade_vertices")
    problems += names_missing_from(
        of(parsed[TEXTURE], "uniform").values(), parameters(lookup_coordinates) | set(GPU_ONLY_UNIFORMS),
        "the parameters of reference.texture.lookup_coordinates or GPU_ONLY_UNIFORMS")
    scene = load_scene(builtin_scenes()[EVERY_FEATURE_SCENE])
    plan = plan_shadows(scene, scene.matrices(64, 48), shadow_layout(scene, 64, 48))
    problems += names_missing_from(
        of(parsed["shadow/lookup.glsl"], "uniform").values(),
        set(plan.uniforms) | set(plan.self_masks(0)) | set(GPU_ONLY_UNIFORMS),
        "renderer.core.shadows.ShadowPlan.uniforms or self_masks (what reference/shadow/lookup.py "
        "reads) or GPU_ONLY_UNIFORMS")
    return problems


def twin_fields_not_declared(parsed) -> list[str]:
    """Every field of Lights, and every array field of MaterialUniforms, is a uniform of
    lighting.glsl; a light array in GLSL is one row per light in the twin, and the rest are
    single values."""
    uniforms = of(parsed[LIGHTING], "uniform")
    scene = load_scene(builtin_scenes()[EVERY_FEATURE_SCENE])
    lights = Lights.from_scene(scene)
    material = MaterialUniforms.from_material(scene.objects[0].material)
    problems = []
    for twin, values in (("reference.lighting.Lights", lights),
                         ("reference.lighting.MaterialUniforms", material)):
        for field in fields(values):
            value = getattr(values, field.name)
            if not isinstance(value, np.ndarray):
                continue                    # MaterialUniforms.specular: the SPECULAR define
            decl = uniforms.get(field.name)
            if decl is None:
                problems.append(f"{twin}.{field.name} is no uniform of glsl/{LIGHTING} "
                                f"({', '.join(sorted(uniforms))})")
            elif (decl.array is not None) != (value.ndim == 2):
                problems.append(f"{decl.where}: uniform {field.name} is "
                                f"{'an array' if decl.array is not None else 'not an array'} but "
                                f"{twin}.{field.name} has shape {value.shape}")
    return problems


def uniforms_not_uploaded(parsed, uploaded: set[str]) -> list[str]:
    return [f"{decl.where}: uniform {name} is not uploaded by the GPU path "
            f"(renderer/gpu: {', '.join(sorted(uploaded))})"
            for name, decl in all_uniforms(parsed).items() if name not in uploaded]


def uploads_not_declared(parsed, uploaded: set[str]) -> list[str]:
    declared = all_uniforms(parsed)
    return [f"renderer/gpu uploads {name}, which no file of glsl/ declares "
            f"({', '.join(sorted(declared))})" for name in sorted(uploaded - set(declared))]


def report(problems: list[str]) -> str:
    return "\n".join(problems)


@pytest.fixture(scope="module")
def parsed():
    return parse(read_glsl())


# -- the parser -----------------------------------------------------------------------------------

def test_the_parser_reads_every_kind_of_declaration_and_nothing_else():
    text = """// Twin: nothing
#version 330 core
#include "lighting.glsl"
layout(triangles) in;
layout(triangle_strip, max_vertices = 3) out;
uniform mat4 u_a;                       // uniform vec3 u_in_a_comment;
/* uniform vec3 u_in_a_block;
   out vec3 v_in_a_block; */
#ifdef SOMETHING
uniform vec3 u_b[NUM_POINT_LIGHTS], u_c;
#else
in vec3 v_d[];
#endif
flat out vec3 f_e;
noperspective centroid in vec2 v_f;
layout(location = 1) out vec4 out_g;
const float K = 1.0;
vec3 helper(vec3 v) { vec3 not_a_declaration; return v; }
void main() {
    out_g = vec4(1.0);
}
"""
    found = [(d.line, d.storage, d.type, d.name, d.array, d.interpolation, d.layout)
             for d in declarations("t.glsl", text)]
    assert found == [
        (6, "uniform", "mat4", "u_a", None, "", ""),
        (10, "uniform", "vec3", "u_b", "NUM_POINT_LIGHTS", "", ""),
        (10, "uniform", "vec3", "u_c", None, "", ""),
        (12, "in", "vec3", "v_d", "", "smooth", ""),
        (14, "out", "vec3", "f_e", None, "flat", ""),
        (15, "in", "vec2", "v_f", None, "noperspective", ""),
        (16, "out", "vec4", "out_g", None, "smooth", "location = 1"),
    ]


def test_the_shaders_declare_what_the_pipeline_is_made_of(parsed):
    """The parser reads the real files: a few declarations each must have."""
    names = {file: {(d.storage, d.name) for d in decls} for file, decls in parsed.items()}
    assert {("in", "in_position"), ("in", "in_normal"), ("out", "v_world_position"),
            ("uniform", "u_model")} <= names["vertex.glsl"]
    assert {("in", "v_world_position"), ("out", "f_color_front")} <= names["geometry.glsl"]
    assert {("in", "v_world_normal"), ("in", "f_color_front"),
            ("out", "out_color")} <= names["fragment.glsl"]
    assert {("uniform", "u_ka"), ("uniform", "u_point_position")} <= names[LIGHTING]


# -- stage to stage -------------------------------------------------------------------------------

def test_a_name_declared_in_several_branches_is_declared_alike(parsed):
    """vertex.glsl declares v_world_position for flat and for Phong shading."""
    problems = declared_differently_in_two_branches(parsed)
    assert not problems, report(problems)


def test_each_stage_reads_what_the_stage_before_writes(parsed):
    problems = inputs_not_from_the_stage_before(parsed)
    assert not problems, report(problems)


def test_each_varying_written_is_read_by_a_later_stage(parsed):
    problems = outputs_nobody_reads(parsed)
    assert not problems, report(problems)


# -- GLSL and the twin ----------------------------------------------------------------------------

def test_the_varyings_are_the_twins_stage_outputs(parsed):
    problems = varyings_not_in_the_twin(parsed)
    assert not problems, report(problems)


def test_the_vertex_attributes_are_the_twins_inputs(parsed):
    attributes = of(parsed["vertex.glsl"], "in")
    positional = [name for name, parameter in inspect.signature(shade_vertices).parameters.items()
                  if parameter.kind is inspect.Parameter.POSITIONAL_OR_KEYWORD]
    assert set(attributes) == set(positional), (
        f"glsl/vertex.glsl: in {', '.join(sorted(attributes))}; "
        f"reference.vertex.shade_vertices takes {', '.join(positional)}")


def test_the_uniforms_are_the_twins_names(parsed):
    problems = uniforms_not_in_the_twin(parsed) + twin_fields_not_declared(parsed)
    assert not problems, report(problems)


# -- GLSL and the GPU path ------------------------------------------------------------------------

def test_every_declared_uniform_is_uploaded(parsed):
    problems = uniforms_not_uploaded(parsed, uploaded_uniform_names())
    assert not problems, report(problems)


def test_every_uploaded_uniform_is_declared(parsed):
    problems = uploads_not_declared(parsed, uploaded_uniform_names())
    assert not problems, report(problems)


def uniform_types_unlike_the_layout(parsed, layout=UNIFORM_TYPES) -> list[str]:
    """Each declared uniform has the GLSL type the one layout (renderer/core/uniforms.py) gives
    it, "vec3[]" for an array of vec3; and the layout names nothing the shaders lack."""
    problems = []
    declared = all_uniforms(parsed)
    for name, d in sorted(declared.items()):
        glsl_type = d.type + ("[]" if d.array is not None else "")
        if layout.get(name) != glsl_type:
            problems.append(f"{d.where}: uniform {name} is {glsl_type}; the layout "
                            f"(renderer/core/uniforms.py) says {layout.get(name, 'nothing')}")
    problems += [f"renderer/core/uniforms.py: {name} is in the layout but no shader declares it"
                 for name in sorted(set(layout) - set(declared))]
    return problems


def test_the_uniform_types_are_the_layouts(parsed):
    problems = uniform_types_unlike_the_layout(parsed)
    assert not problems, report(problems)


def test_a_uniform_of_another_type_is_caught(parsed):
    layout = UNIFORM_TYPES | {"u_n": "vec3", "u_gone": "float"}
    problems = uniform_types_unlike_the_layout(parsed, layout)
    assert len(problems) == 2 and "uniform u_n is float; the layout (renderer/core/uniforms.py) says vec3" in problems[0]
    assert problems[1] == "renderer/core/uniforms.py: u_gone is in the layout but no shader declares it"


def test_the_gpu_only_uniforms_are_declared(parsed):
    """GPU_ONLY_UNIFORMS names no uniform that is gone."""
    assert set(GPU_ONLY_UNIFORMS) <= set(all_uniforms(parsed))


def test_the_vertex_attributes_are_the_ones_the_gpu_path_binds(parsed, gl_contexts):
    attributes = set(of(parsed["vertex.glsl"], "in"))
    bound = bound_attribute_names(gl_contexts["egl"])
    assert attributes == bound, (f"glsl/vertex.glsl: in {', '.join(sorted(attributes))}; "
                                 f"GpuRenderer binds {', '.join(sorted(bound))}")


# -- the checks catch a drift ---------------------------------------------------------------------

def renamed(sources: dict[str, str], file: str, old: str, new: str) -> dict[str, list[Declaration]]:
    """The declarations of `sources` with the word `old` replaced by `new` in `file`."""
    assert re.search(rf"\b{old}\b", sources[file])
    return parse(sources | {file: re.sub(rf"\b{old}\b", new, sources[file])})


def test_a_renamed_varying_is_caught_naming_the_file_and_the_name():
    """v_world_normal renamed in vertex.glsl alone (its declaration and its use)."""
    drifted = renamed(read_glsl(), "vertex.glsl", "v_world_normal", "v_normal_world")
    # declared for Gouraud with shadow maps and for Phong: the checks name the last
    line = [d.line for d in drifted["vertex.glsl"] if d.name == "v_normal_world"][-1]
    stages = report(inputs_not_from_the_stage_before(drifted))
    assert "glsl/fragment.glsl:" in stages and "in v_world_normal is no out of" in stages
    assert report(outputs_nobody_reads(drifted)) == \
        f"glsl/vertex.glsl:{line}: out v_normal_world is read by no later stage"
    twin = report(varyings_not_in_the_twin(drifted))
    assert (f"glsl/vertex.glsl:{line}: out v_normal_world is not in "
            f"reference.vertex.VertexOutputs") in twin


def test_a_varying_changed_in_one_branch_only_is_caught():
    """v_world_position made a vec4 for flat shading only (vertex.glsl declares it for each
    mode: flat, Gouraud with shadow maps, Phong)."""
    sources = read_glsl()
    text = sources["vertex.glsl"].replace("out vec3 v_world_position;",
                                          "out vec4 v_world_position;", 1)
    drifted = parse(sources | {"vertex.glsl": text})
    first, *others = [d for d in drifted["vertex.glsl"] if d.name == "v_world_position"]
    assert others and report(declared_differently_in_two_branches(drifted)) == report(
        [f"{other.where}: out v_world_position is declared otherwise at {first.where}" for other in others])


def test_a_changed_interpolation_is_caught():
    """flat dropped from one of the fragment stage's inputs."""
    sources = read_glsl()
    drifted = parse(sources | {"fragment.glsl": sources["fragment.glsl"].replace(
        "flat in vec3 f_color_front;", "in vec3 f_color_front;")})
    assert "in smooth vec3 f_color_front differs from the out of glsl/geometry.glsl" in \
        report(inputs_not_from_the_stage_before(drifted))


def test_a_renamed_uniform_is_caught_against_the_twin_and_the_gpu_path():
    drifted = renamed(read_glsl(), LIGHTING, "u_point_intensity", "u_point_colour")
    line = next(d.line for d in drifted[LIGHTING] if d.name == "u_point_colour")
    uploaded = uploaded_uniform_names()
    assert report(uniforms_not_uploaded(drifted, uploaded)).startswith(
        f"glsl/lighting.glsl:{line}: uniform u_point_colour is not uploaded by the GPU path")
    assert report(uploads_not_declared(drifted, uploaded)).startswith(
        "renderer/gpu uploads u_point_intensity, which no file of glsl/ declares")
    twin = report(uniforms_not_in_the_twin(drifted) + twin_fields_not_declared(drifted))
    assert f"glsl/lighting.glsl:{line}: uniform u_point_colour is not in reference.lighting" in twin
    assert "reference.lighting.Lights.u_point_intensity is no uniform of glsl/lighting.glsl" in twin
