"""The names the GLSL shaders share with their NumPy twin and with the GPU path.

The GLSL in glsl/ and the twin in reference/ use the same names on purpose (v_world_position,
u_ka, u_point_position, ...). Nothing else makes them agree: a renamed varying or uniform
still compiles, and GL drops a uniform that no program has. So the `in`, `out` and `uniform`
declarations of each GLSL file (every one in the file, whatever the #defines select; read by
renderer/gpu/declarations.py) are held against:

- the stage before: each `in` of geometry.glsl and fragment.glsl is an `out` of the stage
  before it (vertex -> geometry -> fragment), of the same type and interpolation, and each
  `out` of the vertex and geometry stages is read by a later stage (flat_varyings.glsl
  declares flat shading's for both ends, read with each includer's FLAT_VARYING);
- the twin: the vertex stage's `out`s are fields of reference.vertex.VertexOutputs, the
  geometry stage's of reference.geometry.TriangleOutputs, the fragment stage's `in`s are
  fields of either; the vertex attributes and matrices are the parameters of
  reference.vertex.shade_vertices; the material and light uniforms are the fields of
  reference.lighting.MaterialUniforms and Lights (a light array in GLSL is an array of one
  row per light in the twin); the material lookup's (texture.glsl) are the parameters of
  reference.texture.lookup_coordinates; the ray tracer's (glsl/raytrace/) and the output
  stage's (glsl/output/) are names the twin reads: a uniform of renderer/core's that the twin
  takes by that name, or the data it reads in its own names (RAYTRACE_TWIN_NAMES,
  OUTPUT_TWIN_NAMES);
- the GPU path: every declared uniform is uploaded by renderer/gpu/pipeline.py (the ray
  tracer's by renderer/gpu/raytracer.py, the output stage's by renderer/gpu/output.py and
  colour.py) and every uploaded name is declared; the vertex attributes are the ones
  GpuRenderer binds.

Every GLSL file with a twin is read here (test_every_twinned_glsl_file_is_held_here). Each
failure names the GLSL file, the line and the name that drifted.
"""
from __future__ import annotations

import inspect
import re
from pathlib import Path
from dataclasses import fields, replace

import moderngl
import numpy as np
import pytest

from reference.fragment import shade_fragments
from reference.geometry import TriangleOutputs, shade_triangles
from reference.lighting import Lights, MaterialUniforms
from renderer.core.camera_rays import camera_ray_uniforms, lens_uniforms
from renderer.core.light_areas import area_light_uniforms
from renderer.core.output_settings import Halftone, OutputSettings, Transfer
from reference.texture import lookup_coordinates
from reference.vertex import VertexOutputs, shade_vertices
from renderer.core.builtin import builtin_scenes
from renderer.core.resources import glsl_dir
from renderer.core.scene import SHADING_MODES, SceneObject
from renderer.core.scene_file import load_scene, scene_from_dict
from renderer.core.shadows import plan_shadows, shadow_layout
from renderer.core.textures import MaterialTexture, checkerboard
from renderer.core.uniforms import SHADOW_PASS_UNIFORMS, UNIFORM_TYPES
from renderer.gpu import GpuRenderer
from renderer.gpu.declarations import (Declaration, declarations, program_uniforms, selected,
                                       selected_uniforms, uniforms_to_write)
from renderer.gpu.shaders import ALL_FEATURES_LIGHTS, ShaderSourceError

STAGES = ("vertex.glsl", "geometry.glsl", "fragment.glsl")      # in pipeline order
# A tessellated object's first stages, in pipeline order (then geometry.glsl and fragment.glsl)
TESSELLATION_STAGES = ("tess_vertex.glsl", "tess_control.glsl", "tess_evaluation.glsl")
LIGHTING = "lighting.glsl"
TEXTURE = "texture.glsl"                 # the material lookup (TEXTURED)
FLAT_VARYINGS = "flat_varyings.glsl"     # geometry.glsl's outs and fragment.glsl's ins
SHADOW_FILES = ("shadow/lookup.glsl", "shadow/depth.vert", "shadow/depth.frag")   # lookup, depth pass
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
    """EVERY_FEATURE_SCENE with its first object's material textured (its primitives have UVs),
    and beside its objects a tessellated sphere, a PN-triangle mesh and a displaced plane."""
    from renderer.core.primitives import plane, torus
    from renderer.core.scene import Sphere
    from renderer.core.shapes import sphere_mesh
    from renderer.core.tessellation import Displacement, Tessellation
    scene = load_scene(builtin_scenes()[EVERY_FEATURE_SCENE])
    first = scene.objects[0]
    texture = MaterialTexture(checkerboard(2, ((1.0, 1.0, 1.0), (0.5, 0.5, 0.5)), 2))
    sphere = Sphere((0.0, 0.0, 0.0), 0.3)
    untextured = replace(first.material, texture=None)
    tessellated = SceneObject("tessellated", sphere_mesh(sphere), untextured,
                              shape=sphere, receives_shadows=False, tessellation=Tessellation())
    pn = SceneObject("pn", torus(0.3, 0.1, 8, 6), untextured, receives_shadows=False,
                     tessellation=Tessellation(surface="pn_triangles"))
    displaced = SceneObject("displaced", plane(1.0, 2), untextured, receives_shadows=False,
                            tessellation=Tessellation(surface="displaced",
                                                      displacement=Displacement(texture.texture, 0.2)))
    return replace(scene, objects=[replace(first, material=replace(first.material, texture=texture)),
                                   *scene.objects[1:], tessellated, pn, displaced])


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


# -- reading the declarations (renderer/gpu/declarations.py) -------------------------------------

# An include that declares a stage interface for both ends, and the macro each includer defines
# as its direction (in or out) before including it.
INTERFACES = {FLAT_VARYINGS: "FLAT_VARYING"}
# Included bodies: their declarations are the includer's as they stand (the vertex stage's
# work, which vertex.glsl and tess_evaluation.glsl both run).
VERTEX_STAGE = "vertex_stage.glsl"
BODIES = (VERTEX_STAGE,)


def read_glsl(names=(*STAGES, LIGHTING, TEXTURE, FLAT_VARYINGS, *SHADOW_FILES, *TESSELLATION_STAGES)) -> dict[str, str]:
    sources = {name: (glsl_dir() / name).read_text(encoding="utf-8") for name in names}
    for body in BODIES:                 # what they include, read (parse gives it no entry of its own)
        if any(f'#include "{body}"' in text for text in sources.values()):
            sources.setdefault(body, (glsl_dir() / body).read_text(encoding="utf-8"))
    return sources


def interface_declarations(file: str, sources: dict[str, str]) -> list[Declaration]:
    """The declarations of the INTERFACES `file` includes, read with its direction: each is
    the includer's as much as its own (its `where` names the include)."""
    found = []
    for include, macro in INTERFACES.items():
        if f'#include "{include}"' not in sources[file]:
            continue
        direction = re.search(rf"#define {macro} (in|out)\b", sources[file])
        if direction is None:
            raise ValueError(f"glsl/{file} includes {include} without #define {macro} in or out")
        found += declarations(include, sources[include].replace(macro, direction.group(1)))
    for include in BODIES:
        if f'#include "{include}"' in sources[file]:
            found += declarations(include, sources[include])
    return found


def parse(sources: dict[str, str]) -> dict[str, list[Declaration]]:
    """name -> its declarations and those of the interfaces it includes (an interface alone:
    none, its storage is its includer's)."""
    return {name: declarations(name, text) + interface_declarations(name, sources)
            for name, text in sources.items() if name not in BODIES}


def of(decls: list[Declaration], storage: str) -> dict[str, Declaration]:
    """name -> declaration (of a name declared in several #if branches, the last: they are
    checked to be alike: declared_differently_in_two_branches)."""
    return {d.name: d for d in decls if d.storage == storage}


def all_uniforms(parsed) -> dict[str, Declaration]:
    """The uniforms set by name: all but those a layout(binding = ...) binds (images)."""
    return {d.name: d for decls in parsed.values() for d in decls
            if d.storage == "uniform" and "binding" not in d.layout}


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


def uniforms_not_uploaded(parsed, uploaded: set[str], uploader: str = "the GPU path",
                          where: str = "renderer/gpu") -> list[str]:
    """Each uniform of `parsed` (but one bound by its layout's binding) is in `uploaded`."""
    return [f"{decl.where}: uniform {name} is not uploaded by {uploader} "
            f"({where}: {', '.join(sorted(uploaded))})"
            for name, decl in all_uniforms(parsed).items() if name not in uploaded]


def uploads_not_declared(parsed, uploaded: set[str], uploader: str = "renderer/gpu",
                         files: str = "glsl/") -> list[str]:
    declared = all_uniforms(parsed)
    return [f"{uploader} uploads {name}, which no file of {files} declares "
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


def test_selected_keeps_the_branches_the_defines_choose():
    """renderer/gpu/declarations.py's preprocessor: defined(), values, macros of macros,
    #elif, #else, #ifndef, #undef; every line keeps its number."""
    text = """#version 330 core
#define A 2
#define B
#if A > 1 && defined(B)
uniform float u_one;
#elif A
uniform float u_two;
#else
uniform float u_three;
#endif
#ifndef C
uniform float u_four;           // #if 0
#endif
#if !defined(B) || A == 0
uniform float u_five;
#endif
#define D (A * 3)
#if D >= 6
uniform float u_six;
#endif
#undef B
#ifdef B
uniform float u_seven;
#endif
"""
    assert selected_uniforms(text) == {"u_one", "u_four", "u_six"}
    assert selected(text).count("\n") == text.count("\n")


def test_uniforms_to_write_leaves_out_what_the_defines_and_the_compiler_leave_out():
    text = "#version 330 core\n#define LENS\nuniform float u_a;\n#ifdef LENS\nuniform float u_b;\n" \
           "#else\nuniform float u_c;\n#endif\n"
    assert uniforms_to_write(text, {"u_a", "u_b"}, {"u_a", "u_b", "u_c"}) == {"u_a", "u_b"}
    assert uniforms_to_write(text, {"u_b"}, {"u_a", "u_b"}) == {"u_b"}     # u_a: unused, dropped
    with pytest.raises(ShaderSourceError, match="values for u_d, which the GLSL declares nowhere"):
        uniforms_to_write(text, {"u_a", "u_b"}, {"u_a", "u_b", "u_d"})
    with pytest.raises(ShaderSourceError, match="no value for u_b, which the GLSL declares"):
        uniforms_to_write(text, {"u_a", "u_b"}, {"u_a"})
    with pytest.raises(ShaderSourceError, match="u_c kept by the compiler though the #defines"):
        uniforms_to_write(text, {"u_a", "u_b", "u_c"}, {"u_a", "u_b"})


def test_selected_agrees_with_the_compiler(gl_contexts):
    """What a linked rasteriser program kept is among the uniforms selected of its stages'
    prepared sources, in both builds, with shadow maps and textures."""
    from renderer.gpu.context import activate
    from renderer.gpu.shaders import ProgramCache, ShaderVariant, program_sources
    activate(gl_contexts["egl"])
    cache = ProgramCache(gl_contexts["egl"])
    try:
        for shading in SHADING_MODES:
            for shadows, texture, every in ((False, (), False), (True, ("kd",), False), (True, (), True)):
                variant = ShaderVariant(shading, True, 1, 2, specular=True, shadows=shadows,
                                        texture=texture, all_features=every)
                chosen = set().union(*(selected_uniforms(s.text)
                                       for s in program_sources(variant).values()))
                assert program_uniforms(cache.get(variant)) <= chosen, variant.name
    finally:
        cache.release()


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
    """glsl/vertex.glsl's and glsl/tess_vertex.glsl's (a tessellated object's patch corners:
    a PN patch's straight edges, a displaced one's UVs) together."""
    tessellated = declarations(TESSELLATION_STAGES[0], read_glsl(TESSELLATION_STAGES[:1])[TESSELLATION_STAGES[0]])
    attributes = set(of(parsed["vertex.glsl"], "in")) | set(of(tessellated, "in"))
    bound = bound_attribute_names(gl_contexts["egl"])
    assert attributes == bound, (f"glsl/vertex.glsl, tess_vertex.glsl: in {', '.join(sorted(attributes))}; "
                                 f"GpuRenderer binds {', '.join(sorted(bound))}")


# -- the checks catch a drift ---------------------------------------------------------------------

def renamed(sources: dict[str, str], file: str, old: str, new: str) -> dict[str, list[Declaration]]:
    """The declarations of `sources` with the word `old` replaced by `new` in `file`."""
    assert re.search(rf"\b{old}\b", sources[file])
    return parse(sources | {file: re.sub(rf"\b{old}\b", new, sources[file])})


def test_a_renamed_varying_is_caught_naming_the_file_and_the_name():
    """v_world_normal renamed in the vertex stage's body alone (its declaration and its use:
    vertex_stage.glsl, which vertex.glsl includes)."""
    drifted = renamed(read_glsl(), VERTEX_STAGE, "v_world_normal", "v_normal_world")
    # declared for Gouraud with shadow maps and for Phong: the checks name the last
    line = [d.line for d in drifted["vertex.glsl"] if d.name == "v_normal_world"][-1]
    stages = report(inputs_not_from_the_stage_before(drifted))
    assert "glsl/fragment.glsl:" in stages and "in v_world_normal is no out of" in stages
    assert report(outputs_nobody_reads(drifted)) == \
        f"glsl/{VERTEX_STAGE}:{line}: out v_normal_world is read by no later stage"
    twin = report(varyings_not_in_the_twin(drifted))
    assert (f"glsl/{VERTEX_STAGE}:{line}: out v_normal_world is not in "
            f"reference.vertex.VertexOutputs") in twin


def test_a_varying_changed_in_one_branch_only_is_caught():
    """v_world_position made a vec4 for flat shading only (the vertex stage declares it for
    each mode: flat, Gouraud with shadow maps, Phong)."""
    sources = read_glsl()
    text = sources[VERTEX_STAGE].replace("out vec3 v_world_position;",
                                         "out vec4 v_world_position;", 1)
    drifted = parse(sources | {VERTEX_STAGE: text})
    first, *others = [d for d in drifted["vertex.glsl"] if d.name == "v_world_position"]
    # (found in each stage that includes the body: vertex.glsl, tess_evaluation.glsl)
    assert others and set(declared_differently_in_two_branches(drifted)) == {
        f"{other.where}: out v_world_position is declared otherwise at {first.where}" for other in others}


def test_a_changed_interpolation_is_caught():
    """flat added to one of the fragment stage's inputs from vertex.glsl (flat shading's are
    declared once for both ends: glsl/flat_varyings.glsl)."""
    sources = read_glsl()
    drifted = parse(sources | {"fragment.glsl": sources["fragment.glsl"].replace(
        "in vec3 v_color_front;", "flat in vec3 v_color_front;")})
    assert f"in flat vec3 v_color_front differs from the out of glsl/{VERTEX_STAGE}" in \
        report(inputs_not_from_the_stage_before(drifted))


def test_the_flat_interface_is_read_with_each_includers_direction(parsed):
    """glsl/flat_varyings.glsl declares geometry.glsl's outs and fragment.glsl's ins; a
    renamed one in it is caught as any other (here: the twin has no field of the name)."""
    geometry_out, fragment_in = of(parsed["geometry.glsl"], "out"), of(parsed["fragment.glsl"], "in")
    assert {"f_color_front", "f_ambient", "f_point_terms_back", "f_uv"} <= set(geometry_out) & set(fragment_in)
    assert geometry_out["f_face_normal"].where.startswith(f"glsl/{FLAT_VARYINGS}:")
    assert geometry_out["f_face_normal"].interpolation == "flat" and not parsed[FLAT_VARYINGS]
    drifted = renamed(read_glsl(), FLAT_VARYINGS, "f_color_back", "f_colour_back")
    assert "flat_varyings.glsl" in report(varyings_not_in_the_twin(drifted))
    assert "out f_colour_back is not in reference.geometry.TriangleOutputs" in \
        report(varyings_not_in_the_twin(drifted))


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


# -- the ray tracer: glsl/raytrace/ against renderer/gpu/raytracer.py and reference/raytrace/ ----

RAYTRACE_FILES = tuple(sorted(path.relative_to(glsl_dir()).as_posix()
                              for path in (glsl_dir() / "raytrace").iterdir()))
REFERENCE = Path(__file__).resolve().parents[1] / "reference"
# lighting.glsl's uniforms that the ray tracer's program has not, and why.
NOT_IN_THE_TRACER = {
    "u_ka": "MATERIAL_VARIABLES: the hit's material, a variable the tracer sets per hit",
    "u_kd": "MATERIAL_VARIABLES, as u_ka", "u_ks": "MATERIAL_VARIABLES, as u_ka",
    "u_n": "MATERIAL_VARIABLES, as u_ka", "u_eye": "MATERIAL_VARIABLES: the ray's origin",
    "u_num_directional_lights": "ALL_FEATURES: the rasteriser's build that does not specialise",
    "u_num_point_lights": "ALL_FEATURES, as u_num_directional_lights",
}
# The ray tracer's uniforms that the twin does not take by the uniform's name, and the names it
# reads instead (each must occur in reference/raytrace/ or reference/lighting.py): the GPU path
# packs them (renderer/gpu/raytracer.py). The others are keys of the uniforms renderer/core
# builds, which the twin takes by name (twin_uniform_names).
RAYTRACE_TWIN_NAMES = {
    "u_near": ("near",), "u_far": ("far",), "u_background": ("background",),
    "u_seed": ("seed",), "u_sample_offsets": ("table",), "u_first_sample": ("first_sample",),
    "u_adaptive_threshold": ("threshold",),
    "u_spheres": ("sphere_centre", "sphere_radius"), "u_sphere_object": ("sphere_object",),
    "u_planes": ("plane_normal", "plane_offset"), "u_plane_object": ("plane_object",),
    "u_nodes": ("nodes",), "u_triangles": ("triangles",),
    "u_triangle_data": ("triangles", "triangle_normals", "triangle_object"),
    "u_materials": ("ka", "kd", "ks", "kr", "kt", "n", "two_sided", "ior", "gloss"),
    "u_shutter": ("shutter",), "u_sphere_motion": ("sphere_object", "rows"),
    "u_plane_motion": ("plane_object", "rows"), "u_mesh_motion": ("mesh_object", "rows"),
    "u_mesh_root": ("mesh_roots",), "u_mesh_object": ("mesh_object",),
    "u_textures": ("textures",), "u_texture_materials": ("slot", "modulate", "uv_transform"),
    "u_triangle_uvs": ("triangle_uvs",), "u_sphere_rotation": ("sphere_rotation",),
    "u_plane_uv": ("plane_map",),
    "u_emission": ("emission",), "u_emitters": ("triangles", "cdf", "density", "owner"),
    "u_emitter_count": ("count",), "u_sample": ("ks",),
}
# The tracer is made for every_ray_feature_scene with each of these: between them every #define
# that adds a uniform (test_the_configurations_compile_every_ray_tracer_uniform_in).
# {"path": True, ...}: the path tracer (PathTracer, its PathOptions), whose pathtrace.glsl adds
# the emitters' uniforms.
RAY_CONFIGURATIONS = ({"specialise": False, "pattern": "adaptive", "samples": 16},
                      {"pattern": "poisson", "samples": 4}, {"path": True, "samples": 4})


def ray_tracer(ctx, options: dict):
    """The RayTracer, or the PathTracer for {"path": True}, of every_ray_feature_scene."""
    from renderer.core.path_options import PathOptions
    from renderer.gpu.pathtracer import PathTracer
    from renderer.gpu.raytracer import RayTracer
    options = dict(options)
    if options.pop("path", False):
        return PathTracer(every_ray_feature_scene(), 8, 6, PathOptions(**options), context=ctx)
    return RayTracer(every_ray_feature_scene(), 8, 6, context=ctx, **options)


def every_ray_feature_scene():
    """A sphere, a plane and a mesh that move, a mesh that does not (emitting), all textured; a
    glossy mirror; a directional light and a point light with an area; a thin lens; a shutter."""
    scene = scene_from_dict({
        "camera": {"eye": [0, 1, 6], "look": [0, 0, 0], "aperture": 0.1, "shutter": [0, 1]},
        "materials": {"glossy": {"kd": [0.5, 0.5, 0.5], "ks": [0.3, 0.3, 0.3],
                                 "kr": [0.4, 0.4, 0.4], "gloss": 50},
                      "lamp": {"emission": [2.0, 2.0, 2.0]}},
        "lights": [{"type": "directional", "direction": [-1, -1, -1]},
                   {"type": "point", "position": [2, 3, 2], "area": "disc", "radius": 0.5}],
        "objects": [{"name": "ball", "shape": {"type": "sphere", "radius": 1.0},
                     "material": "glossy", "velocity": [1, 0, 0]},
                    {"name": "floor", "shape": {"type": "plane", "normal": [0, 1, 0], "offset": 1.0},
                     "velocity": [0, 0, 1]},
                    {"name": "box", "mesh": {"primitive": "cube"}, "translate": [2, 0, 0],
                     "angular_velocity": [0, 30, 0]},
                    {"name": "still", "mesh": {"primitive": "cube"}, "translate": [-2, 0, 0],
                     "material": "lamp"}]})
    texture = MaterialTexture(checkerboard(2, ((1.0, 1.0, 1.0), (0.5, 0.5, 0.5)), 2))
    return replace(scene, objects=[replace(obj, material=replace(obj.material, texture=texture))
                                   for obj in scene.objects])


def raytracer_uploads(ctx) -> tuple[set[str], list[str]]:
    """(every uniform name RayTracer has a value for, the prepared fragment sources) over
    RAY_CONFIGURATIONS: what it hands renderer/gpu/declarations.py's uniforms_to_write. A
    tracer that refuses its uniforms (a drift) is recorded as far as it got."""
    import renderer.gpu.raytracer as raytracer
    names, texts = set(), []
    original = raytracer.uniforms_to_write

    def recording(text, kept, values):
        names.update(values)
        texts.append(text)
        return original(text, kept, values)

    with pytest.MonkeyPatch.context() as patch:
        patch.setattr(raytracer, "uniforms_to_write", recording)
        for options in RAY_CONFIGURATIONS:
            try:
                with ray_tracer(ctx, options):
                    pass
            except ShaderSourceError:
                pass                # test_the_ray_tracer_sets_the_uniforms_its_defines_declare
    return names, texts


def raytrace_uniforms(parsed) -> dict[str, list[Declaration]]:
    """The ray tracer's files' declarations, lighting.glsl's without NOT_IN_THE_TRACER."""
    return {file: [d for d in decls if not (file == LIGHTING and d.name in NOT_IN_THE_TRACER)]
            for file, decls in parsed.items()}


def twin_uniform_names() -> set[str]:
    """The uniforms the ray tracer's twin takes by name: renderer/core builds them (the
    camera rays and the lens: reference/raytrace/camera.py; the area lights: pipeline.py,
    area_light_uniforms[AREA_UNIFORM]; the lights: reference.lighting.Lights)."""
    scene = every_ray_feature_scene()
    matrices = scene.matrices(8, 6)
    return (set(camera_ray_uniforms(matrices.view, matrices.projection, 8, 6))
            | set(lens_uniforms(matrices.view, 0.1, 1.0)) | set(area_light_uniforms(scene))
            | field_names(Lights))


def twin_text(*folders: str, files=()) -> str:
    return "\n".join(path.read_text(encoding="utf-8") for folder in folders
                     for path in sorted((REFERENCE / folder).glob("*.py"))) + \
        "\n".join((REFERENCE / f).read_text(encoding="utf-8") for f in files)


def uniforms_the_twin_does_not_read(parsed, by_name: set[str], twin_names: dict, text: str,
                                    twin: str) -> list[str]:
    """Each uniform is one the twin takes by name (`by_name`) or one of `twin_names` whose
    names occur in `text`, the twin's source (described by `twin`)."""
    problems = []
    for name, decl in sorted(all_uniforms(parsed).items()):
        if name in by_name:
            continue
        if name not in twin_names:
            problems.append(f"{decl.where}: uniform {name} is no name {twin} reads (a uniform "
                            "of renderer/core it takes by name, or one of this test's *_TWIN_NAMES)")
            continue
        problems += [f"{decl.where}: uniform {name}: {twin} reads no {word!r} "
                     f"(this test's *_TWIN_NAMES)" for word in twin_names[name]
                     if not re.search(rf"\b{word}\b", text)]
    problems += [f"*_TWIN_NAMES names {name}, which no file declares"
                 for name in sorted(set(twin_names) - set(all_uniforms(parsed)))]
    return problems


@pytest.fixture(scope="module")
def raytrace_parsed():
    return raytrace_uniforms(parse(read_glsl((*RAYTRACE_FILES, LIGHTING))))


@pytest.fixture(scope="module")
def ray_uploads(gl_contexts):
    return raytracer_uploads(gl_contexts["egl"])


def test_the_ray_tracer_sets_the_uniforms_its_defines_declare(gl_contexts):
    """RayTracer refuses a value for a uniform its GLSL declares nowhere and a uniform its
    #defines declare that gets no value (renderer/gpu/declarations.py, uniforms_to_write)."""
    for options in RAY_CONFIGURATIONS:
        with ray_tracer(gl_contexts["egl"], options) as rt:
            assert {"u_spheres", "u_nodes", "u_mesh_root", "u_point_area"} <= rt._uniforms_written


def test_every_ray_tracer_uniform_is_uploaded(raytrace_parsed, ray_uploads):
    problems = uniforms_not_uploaded(raytrace_parsed, ray_uploads[0], "renderer/gpu/raytracer.py",
                                     "RayTracer")
    assert not problems, report(problems)


def test_every_uniform_the_ray_tracer_uploads_is_declared(raytrace_parsed, ray_uploads):
    problems = uploads_not_declared(raytrace_parsed, ray_uploads[0], "renderer/gpu/raytracer.py",
                                    "glsl/raytrace/ (and lighting.glsl)")
    assert not problems, report(problems)


def test_the_ray_tracer_uniforms_are_names_its_twin_reads(raytrace_parsed):
    problems = uniforms_the_twin_does_not_read(
        raytrace_parsed, twin_uniform_names(), RAYTRACE_TWIN_NAMES,
        twin_text("raytrace", files=("lighting.py",)), "reference/raytrace/")
    assert not problems, report(problems)


def test_the_configurations_compile_every_ray_tracer_uniform_in(raytrace_parsed, ray_uploads):
    """Each uniform of glsl/raytrace/ is in some configuration's program (so the uploads above
    are all of them), and NOT_IN_THE_TRACER's are in none."""
    chosen = set().union(*(selected_uniforms(text) for text in ray_uploads[1]))
    assert set(all_uniforms(raytrace_parsed)) <= chosen
    assert not chosen & set(NOT_IN_THE_TRACER)
    assert set(NOT_IN_THE_TRACER) <= set(all_uniforms(parse(read_glsl((LIGHTING,)))))


def test_a_renamed_ray_tracer_uniform_is_caught(ray_uploads):
    """u_background renamed in trace.glsl alone: not uploaded, the upload goes nowhere, and
    the twin reads no such name."""
    drifted = raytrace_uniforms(renamed(read_glsl((*RAYTRACE_FILES, LIGHTING)),
                                        "raytrace/trace.glsl", "u_background", "u_backdrop"))
    line = next(d.line for d in drifted["raytrace/trace.glsl"] if d.name == "u_backdrop")
    assert report(uniforms_not_uploaded(drifted, ray_uploads[0], "renderer/gpu/raytracer.py",
                                        "RayTracer")).startswith(
        f"glsl/raytrace/trace.glsl:{line}: uniform u_backdrop is not uploaded by "
        "renderer/gpu/raytracer.py")
    assert report(uploads_not_declared(drifted, ray_uploads[0], "renderer/gpu/raytracer.py",
                                       "glsl/raytrace/")).startswith(
        "renderer/gpu/raytracer.py uploads u_background, which no file of glsl/raytrace/ declares")
    twin = report(uniforms_the_twin_does_not_read(drifted, twin_uniform_names(),
                                                  RAYTRACE_TWIN_NAMES, "", "reference/raytrace/"))
    assert f"glsl/raytrace/trace.glsl:{line}: uniform u_backdrop is no name reference/raytrace/ reads" in twin


# -- the output stage: glsl/output/ against renderer/gpu/output.py, colour.py, reference/output/ --

OUTPUT_FILES = tuple(sorted(path.relative_to(glsl_dir()).as_posix()
                            for path in (glsl_dir() / "output").iterdir()))
# What the twin (reference/output/) reads for each uniform: a name of renderer/core's that it
# calls or reads (each must occur in reference/output/), where the GPU path uploads it packed.
OUTPUT_TWIN_NAMES = {
    "u_exponent": ("encode",), "u_srgb": ("encode",),
    "u_tables": ("decision_points", "code_values"), "u_table_row_bits": ("decision_points",),
    "u_bits": ("code_bits",), "u_decision_points": ("decision_points",),
    "u_alpha_points": ("decision_points", "LINEAR"), "u_code_values": ("code_values",),
    "u_blue_noise_size": ("blue_noise_ranks",),
    "u_screen": ("screen_basis",), "u_grid_cell": ("grid_screens",),
    "u_grid_thresholds": ("grid_screens",),
    "u_tap_offset": ("pull_taps",), "u_taps": ("pull_taps",), "u_shares": ("sender_weights",),
    "u_skew": ("skew",), "u_reach": ("reach",), "u_wavefront": ("wavefronts",),
    "rgb_to_xyz_matrix": ("RGB_TO_XYZ",), "white_chromaticity": ("D65_CHROMATICITY",),
}
# The settings the output pass runs with: between them every program and method of glsl/output/.
OUTPUT_CONFIGURATIONS = (
    OutputSettings(format="exr"), OutputSettings(Transfer("gamma", 2.2), format="npy"),
    OutputSettings(Transfer("srgb")), OutputSettings(dither="bayer4"),
    OutputSettings(dither="blue-noise", format="png16"), OutputSettings(dither="floyd-steinberg"),
    OutputSettings(halftone=Halftone(4, 0)))


def output_uploads(ctx) -> set[str]:
    """Every uniform name the output pass and the colour pass set on their programs."""
    from renderer.gpu.colour import ColourPass
    from renderer.gpu.output import OutputPass
    names = set()
    getitem, get = moderngl.ComputeShader.__getitem__, moderngl.ComputeShader.get

    def recording_getitem(self, key):
        names.add(key)
        return getitem(self, key)

    def recording_get(self, key, default):
        names.add(key)
        return get(self, key, default)

    linear = np.random.default_rng(1).uniform(0, 1, (6, 8, 4)).astype(np.float32)
    with pytest.MonkeyPatch.context() as patch:
        patch.setattr(moderngl.ComputeShader, "__getitem__", recording_getitem)
        patch.setattr(moderngl.ComputeShader, "get", recording_get)
        stage = OutputPass(ctx)
        try:
            for settings in OUTPUT_CONFIGURATIONS:
                stage.apply(linear, settings)
        finally:
            stage.release()
        with ColourPass(ctx) as colour:
            colour.apply(linear)
    return names


@pytest.fixture(scope="module")
def output_parsed():
    return parse(read_glsl(OUTPUT_FILES))


def test_every_output_stage_uniform_is_uploaded_and_every_upload_declared(output_parsed, gl_contexts):
    uploaded = output_uploads(gl_contexts["egl"])
    problems = uniforms_not_uploaded(output_parsed, uploaded, "renderer/gpu/output.py or colour.py",
                                     "they set")
    problems += uploads_not_declared(output_parsed, uploaded, "renderer/gpu/output.py or colour.py",
                                     "glsl/output/")
    assert not problems, report(problems)


def test_the_output_stage_uniforms_are_names_its_twin_reads(output_parsed):
    problems = uniforms_the_twin_does_not_read(output_parsed, set(), OUTPUT_TWIN_NAMES,
                                               twin_text("output"), "reference/output/")
    assert not problems, report(problems)


def test_a_renamed_output_uniform_is_caught():
    drifted = renamed(read_glsl(OUTPUT_FILES), "output/quantise.glsl", "u_bits", "u_code_bits")
    assert "glsl/output/quantise.glsl:" in report(uniforms_the_twin_does_not_read(
        drifted, set(), OUTPUT_TWIN_NAMES, twin_text("output"), "reference/output/"))
    assert "uniform u_code_bits is no name reference/output/ reads" in report(
        uniforms_the_twin_does_not_read(drifted, set(), OUTPUT_TWIN_NAMES, twin_text("output"),
                                        "reference/output/"))


# -- radiosity's item buffers: glsl/radiosity/ against renderer/gpu/item_buffers.py, reference/radiosity/

RADIOSITY_FILES = tuple(sorted(path.relative_to(glsl_dir()).as_posix()
                               for path in (glsl_dir() / "radiosity").iterdir()))
# What the twin (reference/radiosity/) reads for each uniform.
RADIOSITY_TWIN_NAMES = {"u_clip_from_world": ("clip_from_world",), "u_horizon": ("horizon",),
                        "u_view": ("view",), "u_projection": ("projection",),
                        # the specular term's (renderer/core/radiosity.py SpecularDisplay)
                        "u_light_surfaces": ("surfaces",), "u_light_view": ("views",),
                        "u_source_where": ("where",), "u_source_intensity": ("intensity",),
                        "u_source_attenuation": ("attenuation",), "u_source_emitter": ("emitter",)}


def radiosity_uploads(ctx) -> set[str]:
    """Every uniform name ItemBuffers sets on its program while drawing a hemicube, and the
    radiosity renderer on its display's while drawing a frame, with and without the specular
    term (radiosity_specular, radiosity_plates)."""
    from renderer.core.builtin import builtin_scenes
    from renderer.core.radiosity_elements import Elements
    from renderer.core.radiosity_options import RadiosityOptions
    from renderer.core.scene_file import load_scene
    from renderer.gpu.item_buffers import ItemBuffers
    from renderer.gpu.radiosity import RadiosityRenderer
    names = set()
    getitem = moderngl.Program.__getitem__

    def recording_getitem(self, key):
        names.add(key)
        return getitem(self, key)

    corners = np.array([[[0, 0, 0], [1, 0, 0], [0, 1, 0]], [[0, 0, 1], [0, 1, 1], [1, 0, 1]]], float)
    elements = Elements(corners, np.zeros(2, np.int64), np.full((2, 3), 0.5), np.zeros((2, 3)))
    with pytest.MonkeyPatch.context() as patch:
        patch.setattr(moderngl.Program, "__getitem__", recording_getitem)
        buffers = ItemBuffers(ctx, elements, 4)
        try:
            buffers.draw([0])
        finally:
            buffers.release()
        for name in ("radiosity_plates", "radiosity_specular"):
            scene = load_scene(builtin_scenes()[name])
            with RadiosityRenderer(scene, 8, 6, RadiosityOptions(element_size=1.0, hemicube=4, light_buffer=16),
                                   context=ctx) as r:
                r.render()
    return names


def test_every_radiosity_uniform_is_uploaded_and_every_upload_declared(gl_contexts):
    parsed = parse(read_glsl(RADIOSITY_FILES))
    uploaded = radiosity_uploads(gl_contexts["egl"])
    problems = uniforms_not_uploaded(parsed, uploaded, "renderer/gpu/item_buffers.py or radiosity.py", "they set")
    problems += uploads_not_declared(parsed, uploaded, "renderer/gpu/item_buffers.py or radiosity.py", "glsl/radiosity/")
    assert not problems, report(problems)


def test_the_radiosity_uniforms_are_names_its_twin_reads():
    problems = uniforms_the_twin_does_not_read(parse(read_glsl(RADIOSITY_FILES)), set(),
                                               RADIOSITY_TWIN_NAMES, twin_text("radiosity"),
                                               "reference/radiosity/")
    assert not problems, report(problems)


# -- the tessellator's capture harness: glsl/tessellation/ against tests/tessellation_capture.py ---

TESSELLATION_FILES = tuple(sorted(path.relative_to(glsl_dir()).as_posix()
                                  for path in (glsl_dir() / "tessellation").iterdir()))


def test_the_tessellation_capture_takes_its_levels_from_vertices_not_uniforms():
    """Each patch's levels ride on its one vertex (capture.vert), so that one draw holds many
    sets: the harness declares no uniform for its Python side to upload."""
    assert TESSELLATION_FILES and not all_uniforms(parse(read_glsl(TESSELLATION_FILES)))


# -- the rasteriser's tessellation stages: glsl/tess_control.glsl, tess_evaluation.glsl against
# reference/tessellation/control.py, evaluation.py, surface.py (held to each other by
# tests/test_tessellation_stages.py, test_pn_triangles.py, test_displacement.py)

TESSELLATION_TWIN_NAMES = {"u_model": ("model",), "u_view": ("view",), "u_projection": ("projection",),
                           "u_viewport_height": ("viewport_height",), "u_target_error": ("target_error",),
                           "u_surface_radius": ("surface_radius",), "u_max_level": ("max_level",),
                           "u_fixed_level": ("fixed_level",), "u_sphere": ("sphere",),
                           # a displaced mesh's: the height image itself, and the uniforms the
                           # twin takes by name from renderer/core/uniforms.py
                           "u_height": ("texture",), "u_height_texel": ("u_height_texel",),
                           "u_height_size": ("u_height_size",), "u_height_slope": ("u_height_slope",),
                           "u_displacement_scale": ("u_displacement_scale",),
                           "u_height_uv_scale": ("u_height_uv_scale",), "u_height_uv_offset": ("u_height_uv_offset",)}


def test_the_tessellation_stages_uniforms_are_names_their_twins_read():
    """Their own (the vertex stage's work they include is vertex.glsl's, held above)."""
    stages = read_glsl(TESSELLATION_STAGES[1:])
    parsed = {name: declarations(name, text) for name, text in stages.items() if name not in BODIES}
    problems = uniforms_the_twin_does_not_read(parsed, set(), TESSELLATION_TWIN_NAMES, twin_text("tessellation"),
                                               "reference/tessellation/")
    assert not problems, report(problems)


# -- coverage ------------------------------------------------------------------------------------

def test_every_twinned_glsl_file_is_held_here():
    """Each file of glsl/ whose first line names its twin is one this test reads."""
    read = {*STAGES, LIGHTING, TEXTURE, FLAT_VARYINGS, *SHADOW_FILES, *RAYTRACE_FILES, *OUTPUT_FILES,
            *RADIOSITY_FILES, *TESSELLATION_FILES, *TESSELLATION_STAGES, *BODIES}
    twinned = {path.relative_to(glsl_dir()).as_posix() for path in glsl_dir().rglob("*")
               if path.is_file() and path.read_text(encoding="utf-8").startswith("// Twin:")}
    assert twinned <= read, f"not read by tests/test_glsl_contract.py: {sorted(twinned - read)}"
