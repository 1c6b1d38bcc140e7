"""GLSL sources from glsl/: `#include` expansion, `#define` injection, programs per variant.

Shaders exist only as files in glsl/. A source is prepared in two steps:
1. every line `#include "name.glsl"` is replaced by that file from the same folder, or else
   from glsl/ (so `#include "raytrace/random.glsl"` works from any folder, e.g. a test's
   shader) (recursively; each file at most once per shader, a cycle or a missing file is an
   error);
2. the variant's `#define`s go right after the `#version` line (GLSL allows nothing but
   comments before it).
A file that shares constants with Python (FILE_CONSTANTS: a value written once, in Python) gets
them as `#define`s right before its text, wherever it is compiled or included: it holds no
copy of its own.
`#line` directives keep compiler messages pointing at the right file and line: source-string
0 is the main file, 1, 2, ... the included files in order (`ShaderSource.files`).

A `ShaderVariant` names one combination of compile-time constants; `ProgramCache` compiles
each variant once per context (the geometry shader only in the flat variant).
"""

from __future__ import annotations

import functools
import math
import re
from dataclasses import dataclass
from pathlib import Path
from typing import Mapping

import moderngl
import numpy as np

from renderer.core.bvh import MAX_DEPTH as BVH_MAX_DEPTH
from renderer.core.facets import CREASE_CAP, FACES_PER_ROW
from renderer.core.hemicube import ITEM_BACK_SHIFT
from renderer.core.resources import glsl_dir
from renderer.core.shadow_settings import MAX_SLOPE, SQRT2, shared_kernel
from renderer.core.textures import MODULATED
from renderer.gpu.declarations import ShaderSourceError, selected_uniforms
from renderer.gpu.uniforms import SHADOW_MAPS_UNITS, set_shadow_sampler_units

# The samplers set_shadow_sampler_units points at their units when a program is linked.
SAMPLERS_SET_AT_LINK = frozenset(f"u_{kind}_shadow_maps" for kind in SHADOW_MAPS_UNITS)

_INCLUDE = re.compile(r'^\s*#\s*include\b(.*)$')
_INCLUDE_NAME = re.compile(r'^\s*"([^"]+)"\s*(//.*)?$')
_VERSION = re.compile(r'^\s*#\s*version\b')
_DEFINE_NAME = re.compile(r'^[A-Za-z_][A-Za-z0-9_]*$')


# The constants a file of glsl/ shares with Python, by its path under glsl/.
FILE_CONSTANTS: dict[str, dict[str, object]] = {
    # the slope term's cap on tan(theta), the normal offset's move across the map (sqrt 2 as
    # written), a crease's slope taken up to this
    "shadow/lookup.glsl": {"SHADOW_MAX_SLOPE": MAX_SLOPE, "SHADOW_SQRT2": SQRT2,
                           "SHADOW_CREASE_CAP": CREASE_CAP},
    "raytrace/bvh.glsl": {"BVH_STACK_SIZE": BVH_MAX_DEPTH},    # the builder keeps the depth below
    "radiosity/item_buffer.frag": {"ITEM_BACK_SHIFT": ITEM_BACK_SHIFT},   # a back face's bit
}


@dataclass(frozen=True)
class ShaderSource:
    text: str
    files: tuple[str, ...]           # files[i] is GLSL source-string number i in messages


def _display(path: Path) -> str:
    try:
        return str(path.relative_to(glsl_dir().parent))
    except ValueError:
        return str(path)


def _expand(path: Path, files: list[Path], stack: tuple[Path, ...]) -> list[str]:
    """The lines of `path` with includes replaced; `files` collects source-string numbers."""
    number = files.index(path)
    out = []
    lines = path.read_text(encoding="utf-8").splitlines()
    for line_number, line in enumerate(lines, start=1):
        match = _INCLUDE.match(line)
        if not match:
            out.append(line)
            continue
        where = f"{_display(path)}:{line_number}"
        name_match = _INCLUDE_NAME.match(match.group(1))
        if not name_match:
            raise ShaderSourceError(f'{where}: malformed include {line.strip()!r}; '
                                    'write #include "name.glsl"')
        target = (path.parent / name_match.group(1)).resolve()
        if not target.is_file():            # then from glsl/: "raytrace/random.glsl" anywhere
            beside_library = (glsl_dir() / name_match.group(1)).resolve()
            if beside_library.is_file():
                target = beside_library
        if target in stack:
            chain = " -> ".join(_display(p) for p in stack + (target,))
            raise ShaderSourceError(f"{where}: include cycle {chain}")
        if not target.is_file():
            raise ShaderSourceError(f'{where}: #include "{name_match.group(1)}": no such file '
                                    f"in {path.parent} or {glsl_dir()}")
        if target in files:             # already included once: include guard by default
            # The note names the file without the directive: moderngl expands any "#include"
            # it finds in the source text itself, comments too, and fails on it.
            out.append(f"// {name_match.group(1)}: already included")
            continue
        files.append(target)
        out.extend(_define_lines(file_constants(target)))
        out.append(f"#line 1 {len(files) - 1}")
        out.extend(_expand(target, files, stack + (target,)))
        out.append(f"#line {line_number + 1} {number}")
    return out


def file_constants(path: Path) -> dict[str, object]:
    """FILE_CONSTANTS of the file at `path` (none for a file outside glsl/)."""
    try:
        return FILE_CONSTANTS.get(path.resolve().relative_to(glsl_dir().resolve()).as_posix(), {})
    except ValueError:
        return {}


def _define_value(value) -> str:
    """A float as the shortest decimal that reads back as it (GLSL reads the nearest float32;
    a float32 value exactly), else an int."""
    if isinstance(value, (float, np.floating)):
        if not math.isfinite(value):
            raise ShaderSourceError(f"a #define must be finite, got {value}")
        return repr(float(value))
    return str(int(value))


def _define_lines(defines: Mapping[str, object]) -> list[str]:
    lines = []
    for name, value in defines.items():
        if not _DEFINE_NAME.match(name):
            raise ShaderSourceError(f"invalid #define name {name!r}")
        if value is None or value is False:
            continue
        lines.append(f"#define {name}" if value is True
                     else f"#define {name} {_define_value(value)}")
    return lines


def shader_source(filename: str, defines: Mapping[str, object] | None = None,
                  directory: Path | None = None) -> ShaderSource:
    """The text of glsl/`filename`, includes expanded and `defines` placed after `#version`.

    A define whose value is True is written as a bare `#define NAME`, a float as a decimal
    that reads back as it, anything else as an int (`#define NAME value`); False or None
    leaves it out. A define of one of FILE_CONSTANTS' names is an error: those come from Python
    once.
    """
    items = tuple(sorted((defines or {}).items()))
    return _shader_source(filename, items, str(directory or glsl_dir()))


def compute_program(ctx: moderngl.Context, filename: str,
                    defines: Mapping[str, object] | None = None) -> moderngl.ComputeShader:
    """glsl/`filename` with `defines` compiled as a compute shader on `ctx` (current), or a
    ShaderSourceError naming the file, the defines and which source string is which file."""
    source = shader_source(filename, defines)
    try:
        return ctx.compute_shader(source.text)
    except moderngl.Error as exc:
        files = ", ".join(f"{i}={name}" for i, name in enumerate(source.files))
        raise ShaderSourceError(f"{filename} with {dict(defines or {})} does not compile "
                                f"(source strings {files}):\n{exc}") from None


@functools.lru_cache(maxsize=256)
def _shader_source(filename: str, defines: tuple, directory: str) -> ShaderSource:
    path = (Path(directory) / filename).resolve()
    if not path.is_file():
        raise ShaderSourceError(f"shader file {filename!r} not found in {directory}")
    shared = {name for constants in FILE_CONSTANTS.values() for name in constants}
    if shared & dict(defines).keys():
        raise ShaderSourceError(f"{filename}: {', '.join(sorted(shared & dict(defines).keys()))} "
                                "come from renderer/gpu/shaders.py's FILE_CONSTANTS, not a define")
    files = [path]
    lines = _expand(path, files, (path,))
    version_at = next((i for i, line in enumerate(lines) if _VERSION.match(line)), None)
    if version_at is None:
        raise ShaderSourceError(f"{_display(path)}: no #version line")
    injected = _define_lines(dict(defines) | file_constants(path))
    # The original line after #version keeps its number in compiler messages.
    injected.append(f"#line {version_at + 2} 0")
    lines[version_at + 1:version_at + 1] = injected
    return ShaderSource("\n".join(lines) + "\n", tuple(_display(p) for p in files))


# The all-features build sizes its light arrays for this many lights of each kind.
ALL_FEATURES_LIGHTS = 8


@dataclass(frozen=True)
class ShaderVariant:
    """One combination of the shaders' compile-time constants.

    A specialised variant has only what its material and scene use: the shading mode's
    stages, the lights of each kind as constant-sized arrays, the specular term only when
    some k_s > 0, the back-face code only for a two-sided material. `all_features` is the
    same GLSL with everything compiled in (specular, both sides, arrays of
    ALL_FEATURES_LIGHTS lights of each kind) and the rest decided by uniforms at run time
    (how many lights, whether the material is two-sided): what a renderer that does not
    specialise runs. benchmarks/bench_specialisation.py compares the two.

    `shadows` (define SHADOW_MAPS) compiles the shadow-map lookup in (glsl/shadow/lookup.glsl):
    set, in either build, only for an object that receives shadows in a scene whose layout has
    maps (renderer/core/shadows.py); every other program has no shadow code at all. A flat or
    Gouraud receiver hands the lighting equation's terms to the fragment stage apart, a
    varying per light (`light_terms`): NUM_DIRECTIONAL_TERMS and NUM_POINT_TERMS size them
    with the scene's light counts in either build (the all-features build's 2 x 8 lights a
    side would not fit GL's guaranteed varyings: renderer/core/gl_rules.py, too_many_varyings).
    `shadow_kernel` (define SHADOW_KERNEL; specialised builds only) is the filter kernel when
    every light with shadows has the same filter (shadow_settings.shared_kernel): its taps'
    loops then have constant bounds; 0 reads each light's from its uniform. It is not in
    `name`: all the programs of a scene have the same.

    `texture` (define TEXTURED, and TEXTURE_KA / TEXTURE_KD / TEXTURE_KS for the coefficients
    named) is what a textured material's texel modulates, empty for a material without a
    texture, whose program has no texture code, sampler or UV at all (glsl/texture.glsl). It is
    a variant in the all-features build too: GL requires a texture behind every sampler a
    program reads, so a program cannot carry the lookup for materials that have none. Flat and
    Gouraud light a textured material in two parts (glsl/lighting.glsl), so a receiver of
    shadows hands each light's term on twice (TERM_PARTS rows a light).
    """
    shading: str                     # "flat", "gouraud" or "phong"
    two_sided: bool = False
    num_directional_lights: int = 0
    num_point_lights: int = 0
    linear_output: bool = False      # second fragment output: the unclamped float colour
    specular: bool = False           # the k_s term of the lighting equation
    all_features: bool = False
    shadows: bool = False            # the shadow-map lookup
    shadow_kernel: int = 0           # every map's filter kernel, compiled in (0: read per light)
    texture: tuple[str, ...] = ()    # the coefficients the texel modulates ("ka", "kd", "ks")
    # the tessellation stages' spacing (GL's word, renderer/core/tessellation.py) for a
    # tessellated sphere; "" for none
    tessellation: str = ""
    # what its evaluation stage places the points on (renderer/core/tessellation.py SURFACES)
    surface: str = "sphere"

    def __post_init__(self):
        if self.shading not in ("flat", "gouraud", "phong"):
            raise ValueError(f"unknown shading mode {self.shading!r}")
        if self.shadow_kernel and not self.shadows:
            raise ValueError("a shadow kernel is compiled in only with the shadow-map lookup")
        if not set(self.texture) <= set(MODULATED):
            raise ValueError(f"a texture modulates some of {MODULATED}, "
                             f"not {self.texture}")
        if self.tessellation and self.tessellation not in TESSELLATION_SPACING_DEFINES:
            raise ValueError(f"unknown tessellation spacing {self.tessellation!r}")
        if self.surface not in SURFACE_DEFINES:
            raise ValueError(f"unknown tessellated surface {self.surface!r}")

    @property
    def light_terms(self) -> bool:
        """Whether the lighting stage hands each light's term apart to the fragment stage
        (a flat or Gouraud receiver of shadows)."""
        return self.shadows and self.shading != "phong"

    def defines(self) -> dict[str, object]:
        parts = 2 if self.texture else 1           # glsl/lighting.glsl's TERM_PARTS
        terms = {"NUM_DIRECTIONAL_TERMS": parts * self.num_directional_lights,
                 "NUM_POINT_TERMS": parts * self.num_point_lights} if self.light_terms else {}
        terms |= {"TEXTURED": bool(self.texture)} | {
            f"TEXTURE_{k.upper()}": k in self.texture for k in MODULATED}
        if self.shadows:                           # glsl/fragment.glsl's face texture
            terms["FACES_PER_ROW"] = FACES_PER_ROW
        if self.tessellation:                      # through tess_control / tess_evaluation
            terms |= {"TESSELLATED": True, SURFACE_DEFINES[self.surface]: True,
                      TESSELLATION_SPACING_DEFINES[self.tessellation]: True}
        if self.all_features:
            return {
                f"SHADING_{self.shading.upper()}": True,
                "ALL_FEATURES": True,
                "TWO_SIDED": True,
                "SPECULAR": True,
                "NUM_DIRECTIONAL_LIGHTS": ALL_FEATURES_LIGHTS,
                "NUM_POINT_LIGHTS": ALL_FEATURES_LIGHTS,
                "LINEAR_OUTPUT": self.linear_output,
                "SHADOW_MAPS": self.shadows,
                **terms,
            }
        return {
            f"SHADING_{self.shading.upper()}": True,
            "TWO_SIDED": self.two_sided,
            "SPECULAR": self.specular,
            "NUM_DIRECTIONAL_LIGHTS": self.num_directional_lights,
            "NUM_POINT_LIGHTS": self.num_point_lights,
            "LINEAR_OUTPUT": self.linear_output,
            "SHADOW_MAPS": self.shadows,
            "SHADOW_KERNEL": self.shadow_kernel or None,
            **terms,
        }

    @property
    def name(self) -> str:
        """A file-name-safe label, e.g. "phong-two-sided-specular-1dir-2point-shadows"."""
        linear = "-linear" if self.linear_output else ""
        shadows = "-shadows" if self.shadows else ""
        shadows += "".join(f"-textured-{k}" for k in self.texture)
        if self.tessellation:
            shadows += f"-tessellated-{self.tessellation.removesuffix('_spacing')}"
            shadows += {"sphere": "", "pn_triangles": "-pn", "displaced": "-displaced"}[self.surface]
        if self.all_features:
            terms = (f"-{self.num_directional_lights}dir-{self.num_point_lights}point"
                     if self.light_terms else "")
            return f"{self.shading}-all-features{terms}{linear}{shadows}"
        sides = "-two-sided" if self.two_sided else ""
        specular = "-specular" if self.specular else ""
        return (f"{self.shading}{sides}{specular}-{self.num_directional_lights}dir-"
                f"{self.num_point_lights}point{linear}{shadows}")

    @property
    def uses_geometry_shader(self) -> bool:
        return self.shading == "flat"

    @classmethod
    def for_material(cls, scene, material, linear_output: bool = False,
                     all_features: bool = False, shadows: bool = False,
                     tessellation: str = "", surface: str = "sphere") -> "ShaderVariant":
        """The variant that draws `material` (a renderer.core.scene.Material) in `scene`:
        specialised to what they use, or the all-features build. `shadows`: the object
        receives shadows and the scene's layout has maps; `tessellation`: its spacing, for a
        tessellated object, `surface` what its points go on."""
        shadows = bool(shadows)
        texture = modulated_coefficients(material)
        if all_features:
            counts = ((len(scene.directional_lights), len(scene.point_lights))
                      if shadows and material.shading != "phong" else (0, 0))
            return cls(material.shading, False, *counts, linear_output=bool(linear_output),
                       all_features=True, shadows=shadows, texture=texture, tessellation=tessellation,
                       surface=surface)
        return cls(material.shading, bool(material.two_sided), len(scene.directional_lights),
                   len(scene.point_lights), bool(linear_output), material.has_specular,
                   shadows=shadows, shadow_kernel=shared_kernel(scene) if shadows else 0,
                   texture=texture, tessellation=tessellation, surface=surface)

    @classmethod
    def for_object(cls, scene, obj, *, maps: bool, linear_output: bool = False,
                   all_features: bool = False) -> "ShaderVariant":
        """The variant the camera pass draws scene object `obj` with (GpuRenderer's and
        `renderer shaders`'): its material's, looking the shadow maps up where the frame has
        `maps` and it receives them, through the tessellation stages where it asks for them."""
        return cls.for_material(scene, obj.material, linear_output, all_features=all_features,
                                shadows=maps and obj.receives_shadows,
                                tessellation="" if obj.tessellation is None else obj.tessellation.spacing,
                                surface="sphere" if obj.tessellation is None else obj.tessellation.surface)



def modulated_coefficients(material) -> tuple[str, ...]:
    """The coefficients `material`'s texel modulates, in MODULATED's order (ka, kd, ks);
    empty for a material without a texture."""
    if material.texture is None:
        return ()
    return tuple(k for k in MODULATED if k in material.texture.modulate)


STAGES = (("vertex_shader", "vertex.glsl"),
          ("tess_control_shader", "tess_control.glsl"),
          ("tess_evaluation_shader", "tess_evaluation.glsl"),
          ("geometry_shader", "geometry.glsl"),
          ("fragment_shader", "fragment.glsl"))
TESSELLATION_STAGES = ("tess_control_shader", "tess_evaluation_shader")
# glsl/tess_evaluation.glsl's layout: each spacing's define
SURFACE_DEFINES = {"sphere": "SURFACE_SPHERE", "pn_triangles": "SURFACE_PN", "displaced": "SURFACE_DISPLACED"}
TESSELLATION_SPACING_DEFINES = {"equal_spacing": "SPACING_EQUAL", "fractional_even_spacing": "SPACING_FRACTIONAL_EVEN",
                                "fractional_odd_spacing": "SPACING_FRACTIONAL_ODD"}


def program_sources(variant: ShaderVariant) -> dict[str, ShaderSource]:
    """Sources of the stages `variant` links, keyed by moderngl's program() argument names."""
    defines = variant.defines()
    sources = {stage: shader_source(filename, defines) for stage, filename in STAGES
               if (stage != "geometry_shader" or variant.uses_geometry_shader)
               and (stage not in TESSELLATION_STAGES or variant.tessellation)}
    if variant.tessellation:                       # the patch corners pass through unchanged
        sources["vertex_shader"] = shader_source("tess_vertex.glsl", defines)
    return sources


def program_source(scene, material, linear_output: bool = False) -> tuple[str, str | None, str]:
    """(vertex, geometry or None, fragment) source texts for `material` in `scene`."""
    sources = program_sources(ShaderVariant.for_material(scene, material, linear_output))
    geometry = sources.get("geometry_shader")
    return (sources["vertex_shader"].text, geometry.text if geometry else None,
            sources["fragment_shader"].text)


class ProgramCache:
    """Compiled programs of one context, one per variant, made on first use."""

    def __init__(self, ctx: moderngl.Context):
        self.ctx = ctx
        self._programs: dict[ShaderVariant, moderngl.Program] = {}
        self._declared: dict[ShaderVariant, frozenset[str]] = {}

    def get(self, variant: ShaderVariant) -> moderngl.Program:
        program = self._programs.get(variant)
        if program is None:
            program = self._programs[variant] = self._compile(variant)
        return program

    def _compile(self, variant: ShaderVariant) -> moderngl.Program:
        sources = program_sources(variant)
        try:
            program = self.ctx.program(**{stage: s.text for stage, s in sources.items()})
        except moderngl.Error as exc:
            legend = "; ".join(f"{stage.split('_')[0]}: " + ", ".join(
                f"{i}={name}" for i, name in enumerate(s.files)) for stage, s in sources.items())
            raise ShaderSourceError(f"{variant} does not compile (source strings {legend}):\n{exc}")
        set_shadow_sampler_units(self.ctx, program)
        self._declared[variant] = frozenset().union(*(selected_uniforms(s.text) for s in sources.values()))
        return program

    def check_values(self, variant: ShaderVariant, names) -> None:
        """ShaderSourceError naming the uniforms the variant's #defines declare that `names`
        (the values a renderer writes, and the samplers it points at units) leave without a
        value. Those the #defines leave out, or the compiler dropped, need none; a value for a
        name no GLSL file declares is the GLSL contract test's to catch."""
        missing = self._declared[variant] - set(names) - SAMPLERS_SET_AT_LINK
        if missing:
            raise ShaderSourceError(f"{variant}: no value for {', '.join(sorted(missing))}, which "
                                    "its GLSL declares")

    def items(self):
        return self._programs.items()

    def __len__(self) -> int:
        return len(self._programs)

    def release(self) -> None:
        for program in self._programs.values():
            program.release()
        self._programs.clear()
