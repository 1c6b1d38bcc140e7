"""What a GLSL source declares: its `in`, `out` and `uniform` variables, every one written
(`declarations`, whatever its #if branches select) or those its #defines select (`selected`
on a prepared source, renderer/gpu/shaders.py's shader_source: its includes expanded and its
#defines in it).

tests/test_glsl_contract.py holds every declaration of glsl/ against the stage before, the
twin and the GPU path. A renderer holds the uniforms it has values for against the ones its
program's #defines select (`uniforms_to_write`): a name the GLSL and the Python spell apart is
an error, not a value that silently goes nowhere.

`selected` evaluates the conditions as the GLSL preprocessor does, for what glsl/ writes:
#if, #ifdef, #ifndef, #elif, #else and #endif over defined(NAME), integer constants, object-like
macros (#define and #undef in the branches taken), arithmetic, comparisons, !, && and ||; a
name that is no macro is 0.
"""

from __future__ import annotations

import functools
import re
from dataclasses import dataclass
from typing import Iterable

import moderngl


class ShaderSourceError(Exception):
    """A GLSL file that cannot be assembled (missing include, include cycle, no #version),
    a program that does not compile, or uniforms that do not match a renderer's values; the
    message names the file and line, or the uniforms. (renderer/gpu/shaders.py raises it too.)"""


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
OTHER_QUALIFIERS = {"centroid", "sample", "invariant", "highp", "mediump", "lowp",
                    "readonly", "writeonly", "coherent", "volatile", "restrict"}
_LAYOUT = re.compile(r"^layout\s*\(([^)]*)\)\s*")
_DECLARATOR = re.compile(r"^(\w+)\s*(?:\[\s*([\w\s*]*?)\s*\])?$")     # [6 * N] too
_DIRECTIVE = re.compile(r"^[ \t]*#[ \t]*(\w*)[ \t]*(.*)$")


def without_comments(text: str) -> str:
    """The text with its comments blanked out, newlines kept (so line numbers hold)."""
    text = re.sub(r"/\*.*?\*/", lambda m: re.sub(r"[^\n]", " ", m.group()), text, flags=re.S)
    return re.sub(r"//[^\n]*", "", text)


def without_comments_and_directives(text: str) -> str:
    """The text with comments and preprocessor lines blanked out, newlines kept: every
    declaration counts, whichever #if branch it is in."""
    return re.sub(r"(?m)^[ \t]*#[^\n]*", "", without_comments(text))


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
    """The `in`, `out` and `uniform` variables declared in one GLSL text (`file` names it in
    messages), in every #if branch."""
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


# -- the branches a source's #defines select -----------------------------------------------------

_TOKEN = re.compile(r"0[xX][0-9a-fA-F]+[uU]?|\d+[uU]?|\w+|&&|\|\||[=!<>]=|<<|>>|\S")
_OPERATORS = {"&&": "and", "||": "or", "!": "not", "/": "//"}


def _value(expression: str, macros: dict[str, str | None], depth: int = 0) -> int:
    """The integer value of a #if expression with `macros` (name -> replacement text; None for
    a function-like macro)."""
    if depth > 32:
        raise ShaderSourceError(f"#if {expression}: macros nested too deep")
    tokens, python = _TOKEN.findall(expression), []
    while tokens:
        token = tokens.pop(0)
        if token == "defined":
            name = tokens[1] if tokens[0] == "(" else tokens[0]
            del tokens[:3 if tokens[0] == "(" else 1]
            python.append(str(int(name in macros)))
        elif token[0].isdigit():
            digits = token.rstrip("uU")
            python.append(str(int(digits, 16 if digits[:2].lower() == "0x" else 10)))
        elif token[0].isalpha() or token[0] == "_":
            replacement = macros.get(token)
            python.append(f"({_value(replacement, macros, depth + 1)})" if replacement else "0")
        else:
            python.append(_OPERATORS.get(token, token))
    try:
        return int(eval(" ".join(python) or "0", {"__builtins__": {}}, {}))
    except Exception as exc:                    # a form this evaluator does not know
        raise ShaderSourceError(f"#if {expression}: cannot evaluate ({exc})") from None


def selected(text: str) -> str:
    """`text` with its comments, its preprocessor lines and the lines its #if branches leave
    out blanked, line numbers kept (the module docstring says which conditions are known)."""
    macros: dict[str, str | None] = {}
    branches: list[tuple[bool, bool]] = []       # (the enclosing text is kept, a branch taken)
    kept, lines = True, []
    for line in without_comments(text).split("\n"):
        match = _DIRECTIVE.match(line)
        lines.append("" if match or not kept else line)
        if not match:
            continue
        directive, argument = match.group(1), match.group(2).strip()
        if directive in ("if", "ifdef", "ifndef"):
            name = argument.split()[0] if directive != "if" else ""
            take = kept and (_value(argument, macros) != 0 if directive == "if"
                             else (name in macros) == (directive == "ifdef"))
            branches.append((kept, take))
            kept = take
        elif directive == "elif":
            outer, taken = branches[-1]
            kept = outer and not taken and _value(argument, macros) != 0
            branches[-1] = (outer, taken or kept)
        elif directive == "else":
            outer, taken = branches[-1]
            kept, branches[-1] = outer and not taken, (outer, True)
        elif directive == "endif":
            kept = branches.pop()[0]
        elif kept and directive == "define":
            name, rest = re.match(r"(\w+)(.*)", argument).groups()
            macros[name] = None if rest.startswith("(") else rest.strip()
        elif kept and directive == "undef":
            macros.pop(argument.split()[0], None)
    return "\n".join(lines)


def selected_uniforms(text: str) -> set[str]:
    """The names of the uniforms a prepared source declares under its #defines."""
    return {d.name for d in declarations("", selected(text)) if d.storage == "uniform"}


# -- a renderer's uniforms against its program -----------------------------------------------------

def program_uniforms(program: moderngl.Program) -> set[str]:
    """The names of the uniforms a linked program kept (the compiler drops the unused)."""
    return {name for name in program if isinstance(program[name], moderngl.Uniform)}


@functools.lru_cache(maxsize=32)
def _uniform_names(text: str) -> tuple[frozenset[str], frozenset[str]]:
    """(the uniforms a prepared source declares in any branch, those its #defines select):
    read once per source (a viewer's update writes the uniforms every frame)."""
    return (frozenset(d.name for d in declarations("", text) if d.storage == "uniform"),
            frozenset(selected_uniforms(text)))


def uniforms_to_write(text: str, kept: Iterable[str], names: Iterable[str]) -> set[str]:
    """Of `names` (the uniforms a renderer has values for), those to write to a program that
    the prepared source `text` compiled to, which kept the uniforms `kept` (program_uniforms):
    the ones the source's #defines select and the compiler kept. A uniform declared only in a
    branch the #defines leave out is not written (the scene's specialisation left it out), nor
    one the #defines select that the compiler dropped (unused). ShaderSourceError, naming
    them, for a name of `names` that the source declares in no branch (the GLSL and the
    Python spell it apart), for a uniform the #defines select that `names` gives no value,
    and for a kept uniform the #defines do not select (this module and the compiler
    disagree)."""
    names, kept = set(names), set(kept)
    declared, chosen = _uniform_names(text)
    problems = [f"values for {', '.join(sorted(names - declared))}, which the GLSL declares "
                "nowhere" if names - declared else "",
                f"no value for {', '.join(sorted(chosen - names))}, which the GLSL declares"
                if chosen - names else "",
                f"{', '.join(sorted(kept - chosen))} kept by the compiler though the #defines "
                "leave it out" if kept - chosen else ""]
    if any(problems):
        raise ShaderSourceError("the uniforms do not match the program's: "
                                + "; ".join(p for p in problems if p))
    return names & chosen & kept
