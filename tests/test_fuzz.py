"""Issue 13: nothing a user does gives a traceback, a wrong file or a runaway.

A seeded fuzzer of our own (deterministic, no extra dependency): each seed makes one case,
a scene file and mesh files written into a fresh folder and a command line, run in-process
through `renderer.cli.main(argv)`. What must hold for every case (`check_outcome`):

- exit 0: every requested output complete (the image opens with Pillow and has the size, the
  depth .npy loads with the shape, compare's/shaders'/colour's folders hold their files, a
  batch's manifest a record for each item with its files whole), nothing else
  written anywhere in the case's folder; stderr only "renderer: warning: ..." and "wrote ..."
  lines; a default-named output is one image directly in the working folder, never a name
  taken from the scene's `name`;
- exit 1 or 2: exactly one line on stderr starting "renderer: " (or "renderer CMD: "); a
  command line argparse refuses may add its usage line (the documented contract of
  renderer/cli/); nothing written, changed or left (no hidden `.*.tmp` either);
- never: an exception out of main() (printed with the seed and the input to reproduce it),
  a Python warning (in a real process it is two lines on stderr), "Traceback" anywhere, more
  than RUNAWAY_SECONDS of the process's CPU time or RUNAWAY_WAIT_SECONDS of wall-clock time,
  or RUNAWAY_BYTES of address space over what the process had.

Every class of issue 13 is a generator in CLASSES (`make_case` picks one per seed), and since
issue 30 the files a user names besides scenes and meshes: textures and `renderer colour`'s
images (declared sizes, bombs, cut-short and corrupt streams, .npy headers), glTF JSON and its
URIs, job files and tampered `renderer batch` folders (run in this process, without Ray),
special files (FIFO, folder, socket, /dev/zero, links) where a file is expected. No output
may quote CANARY, which such cases leave in the files they must not read.
The generated cases are the full run's (--all, what CI runs): the default run holds each class
by its hand-written cases (docs/bad-input.md names their files) and this checker by its own
tests below, in under a second instead of the cases' 4 s.
Running:

    pytest tests/test_fuzz.py                    # the checker's own tests only
    pytest --all tests/test_fuzz.py -k default   # DEFAULT_CASES seeds from BASE_SEED (4 s)
    pytest --all tests/test_fuzz.py              # and SLOW_CASES more seeds
    FUZZ_SEEDS=1234,99 pytest tests/test_fuzz.py -k seeds   # given seeds only
    FUZZ_CLASS=output_faults pytest ...          # only cases of one class (seeds still fixed)
    FUZZ_MAX_MEMORY=1 pytest ...                 # also generate --max-memory (once it exists)
    python tests/test_fuzz.py SEED               # print one case (files and argv)
"""

from __future__ import annotations

import contextlib
import io
import math
import os
import random
import resource
import shutil
import signal
import stat
import struct
import sys
import time
import tomllib
import traceback
import warnings
from dataclasses import dataclass, field
from pathlib import Path

import numpy as np
import pytest

from renderer.core import memory

REPO = Path(__file__).resolve().parents[1]
SCENES_DIR = REPO / "assets" / "scenes"

BASE_SEED = 13_000                  # issue 13
DEFAULT_CASES = 100                 # the full run (--all) adds SLOW_CASES after them
SLOW_CASES = 3000
# A case working longer than RUNAWAY_SECONDS of CPU time (this process's, every thread's: user
# and system) is a runaway; CPU time is the work done whatever else loads the machine (CI runs
# two workers on two cores, where the same case took twice the wall-clock time). A case waiting
# longer than RUNAWAY_WAIT_SECONDS of wall-clock time is one too (a wait spends no CPU).
RUNAWAY_SECONDS = 5.0
RUNAWAY_WAIT_SECONDS = 20.0
RUNAWAY_BYTES = 1 << 30             # address space a case may add (RLIMIT_AS): more is a runaway
# The renderer's own memory limit during a case (renderer/core/memory.py), well inside the
# runaway cap: a case asking for more must be refused with one line, not run out of memory.
# (The default limit is half the machine's memory, which the cap would cut short.) The limit
# counts the process's own PROCESS_BYTES too: a case may add 384 MiB.
FUZZ_MEMORY_LIMIT = memory.PROCESS_BYTES + (384 << 20)
GPU_FRACTION = 0.04                 # cases run through the GL backend (render --backend gpu, compare)
# --max-memory is being added on another branch; switch this on (or FUZZ_MAX_MEMORY=1) when it is in.
WITH_MAX_MEMORY = os.environ.get("FUZZ_MAX_MEMORY", "") not in ("", "0")
TINY_SIZES = ("8x6", "6x8", "4x4", "9x7", "1x1", "16x2")
NAME_MAX, PATH_MAX = 255, 4096


# =========================================================================== cases

class Raw(str):
    """TOML text put into a value's place as it stands (deep nesting, bad syntax)."""


@dataclass
class Case:
    seed: int
    kind: str                                   # the class (CLASSES key) and what in it
    argv: list[str]                             # "{D}" stands for the case's folder
    files: dict[str, bytes] = field(default_factory=dict)     # relative path -> content
    dirs: list[str] = field(default_factory=list)
    unreadable: list[str] = field(default_factory=list)       # folders chmod 000
    cwd: str = "w"                              # relative working folder (made)
    name_class: bool = False                    # a scene `name` case: exit 2 only if it names `name`
    # relative path -> "fifo", "dir", "socket", "dangling link", "link:fifo" or "link:TARGET"
    # (TARGET relative to the case's folder, or absolute): made by `materialise`
    specials: dict[str, str] = field(default_factory=dict)
    finished: str | None = None                 # a finished batch of MANIFEST_JOB copied here
    tamper: list = field(default_factory=list)  # then these changes (gen_manifests) made to it

    def describe(self) -> str:
        lines = [f"seed {self.seed}: {self.kind}", f"argv: {self.argv!r}", f"cwd: {self.cwd}"]
        for path, data in self.files.items():
            shown = data[:600]
            more = f" ... ({len(data)} bytes)" if len(data) > 600 else ""
            lines.append(f"--- {path}:\n{shown!r}{more}")
        if self.specials or self.finished:
            lines.append(f"specials: {self.specials} finished: {self.finished} tamper: {self.tamper}")
        if self.dirs or self.unreadable:
            lines.append(f"dirs: {self.dirs} unreadable: {self.unreadable}")
        return "\n".join(lines)


def _toml_key(key: str) -> str:
    return _toml_string(key)


def _toml_string(text: str) -> str:
    out = []
    for ch in text:
        code = ord(ch)
        if ch == '"':
            out.append('\\"')
        elif ch == "\\":
            out.append("\\\\")
        elif ch == "\n":
            out.append("\\n")
        elif ch == "\t":
            out.append("\\t")
        elif code < 0x20 or code == 0x7F or 0xD800 <= code <= 0xDFFF:
            out.append(f"\\u{code if code < 0xD800 else 0xFFFD:04X}")
        else:
            out.append(ch)
    return '"' + "".join(out) + '"'


def toml_value(value) -> str:
    if isinstance(value, Raw):
        return str(value)
    if isinstance(value, bool):
        return "true" if value else "false"
    if isinstance(value, int):
        return str(max(-(1 << 63), min((1 << 63) - 1, value)))
    if isinstance(value, float):
        if math.isnan(value):
            return "nan"
        if math.isinf(value):
            return "inf" if value > 0 else "-inf"
        text = repr(value)
        return text if any(c in text for c in ".en") else text + ".0"
    if isinstance(value, str):
        return _toml_string(value)
    if isinstance(value, (list, tuple)):
        return "[" + ", ".join(toml_value(v) for v in value) + "]"
    if isinstance(value, dict):
        return "{" + ", ".join(f"{_toml_key(k)} = {toml_value(v)}" for k, v in value.items()) + "}"
    raise TypeError(type(value))


def toml_document(data: dict) -> bytes:
    """Every top-level key as `key = inline value` (inline tables are one line, so keys and
    strings with newlines are escaped)."""
    return "".join(f"{_toml_key(k)} = {toml_value(v)}\n" for k, v in data.items()).encode()


_BUILTIN: dict[str, dict] = {}


def builtin_scene_data() -> dict[str, dict]:
    if not _BUILTIN:
        for path in sorted(SCENES_DIR.glob("*.toml")):
            _BUILTIN[path.stem] = tomllib.loads(path.read_text(encoding="utf-8"))
    return _BUILTIN


def _copy(data):
    if isinstance(data, dict):
        return {k: _copy(v) for k, v in data.items()}
    if isinstance(data, list):
        return [_copy(v) for v in data]
    return data


def small_scene(objects=None, lights=None, **top) -> dict:
    scene = {"camera": {"eye": [0.0, 1.0, 5.0]},
             "lights": lights if lights is not None else [{"type": "directional",
                                                           "direction": [-1.0, -1.0, -1.0]}],
             "objects": objects if objects is not None else [{"name": "a",
                                                              "mesh": {"primitive": "cube"}}]}
    scene.update(top)
    return scene


# ---- mesh files

TETRA_V = [(0.0, 0.0, 0.0), (1.0, 0.0, 0.0), (0.0, 1.0, 0.0), (0.0, 0.0, 1.0)]
TETRA_F = [(0, 2, 1), (0, 1, 3), (0, 3, 2), (1, 2, 3)]


def _num(x: float) -> str:
    return "inf" if x == math.inf else "-inf" if x == -math.inf else "nan" if x != x else repr(x)


def obj_bytes(vertices=TETRA_V, faces=TETRA_F, normals=False) -> bytes:
    lines = [f"v {_num(x)} {_num(y)} {_num(z)}" for x, y, z in vertices]
    if normals:
        lines += [f"vn {x} {y} {z}" for x, y, z in vertices]
        lines += [f"f {a + 1}//{a + 1} {b + 1}//{b + 1} {c + 1}//{c + 1}" for a, b, c in faces]
    else:
        lines += [f"f {a + 1} {b + 1} {c + 1}" for a, b, c in faces]
    return ("\n".join(lines) + "\n").encode()


def ply_bytes(vertices=TETRA_V, faces=TETRA_F, binary=False, vertex_count=None,
              face_count=None) -> bytes:
    fmt = "binary_little_endian" if binary else "ascii"
    header = (f"ply\nformat {fmt} 1.0\nelement vertex {vertex_count or len(vertices)}\n"
              "property float x\nproperty float y\nproperty float z\n"
              f"element face {face_count or len(faces)}\nproperty list uchar int vertex_indices\n"
              "end_header\n").encode()
    if binary:
        body = b"".join(struct.pack("<3f", *v) for v in vertices)
        body += b"".join(struct.pack("<B3i", 3, *[((i + (1 << 31)) % (1 << 32)) - (1 << 31)
                                                  for i in f]) for f in faces)
    else:
        body = "".join(f"{_num(x)} {_num(y)} {_num(z)}\n" for x, y, z in vertices).encode()
        body += "".join(f"3 {a} {b} {c}\n" for a, b, c in faces).encode()
    return header + body


def stl_bytes(vertices=TETRA_V, faces=TETRA_F, count=None, ascii=False) -> bytes:
    if ascii:
        out = ["solid t"]
        for f in faces:
            out.append(" facet normal 0 0 0\n  outer loop")
            out += [f"   vertex {' '.join(_num(c) for c in vertices[i])}" for i in f]
            out.append("  endloop\n endfacet")
        return ("\n".join(out) + "\nendsolid t\n").encode()
    body = b"".join(struct.pack("<12fH", 0, 0, 0, *[c for i in f for c in vertices[i]], 0)
                    for f in faces)
    return b"\0" * 80 + struct.pack("<I", len(faces) if count is None else count) + body


def valid_mesh(rng: random.Random) -> tuple[str, bytes]:
    kind = rng.choice(("obj", "objn", "ply", "plyb", "stl", "stla"))
    return {"obj": (".obj", obj_bytes()), "objn": (".obj", obj_bytes(normals=True)),
            "ply": (".ply", ply_bytes()), "plyb": (".ply", ply_bytes(binary=True)),
            "stl": (".stl", stl_bytes()), "stla": (".stl", stl_bytes(ascii=True))}[kind]


def mutate_bytes(rng: random.Random, data: bytes) -> bytes:
    data = bytearray(data)
    for _ in range(rng.randint(1, 3)):
        op = rng.randrange(5)
        if op == 0 and data:
            del data[rng.randrange(len(data)):]                       # truncate
        elif op == 1 and data:
            for _ in range(rng.randint(1, 8)):                        # flip bytes
                data[rng.randrange(len(data))] ^= 1 << rng.randrange(8)
        elif op == 2:
            at = rng.randint(0, len(data))                            # insert garbage
            data[at:at] = bytes(rng.randrange(256) for _ in range(rng.randint(1, 64)))
        elif op == 3:
            at = rng.randint(0, len(data))
            data[at:at] = rng.choice([b"\n", b"\0", b" 99999999999999999999", b"-1", b"nan",
                                      b"\xff\xfe", b"f 0 0 0\n", b"v 1e999 0 0\n"])
        else:                                                          # huge counts
            text = bytes(data)
            for old, new in ((b"element vertex 4", b"element vertex 2147483658"),
                             (b"element face 4", b"element face 4294967295")):
                text = text.replace(old, new)
            if text[:5] != b"solid" and len(text) >= 84 and text[:3] != b"ply" and b"v " not in text[:3]:
                text = text[:80] + struct.pack("<I", rng.choice([0, 1 << 31, 0xFFFFFFFF])) + text[84:]
            data = bytearray(text)
    return bytes(data)


# ---- the command line

def render_argv(rng: random.Random, scene: str, *, output="{D}/w/out.png", size=None,
                gpu=False) -> list[str]:
    argv = ["render", scene, "--backend", "gpu" if gpu else "reference",
            "--size", size or rng.choice(TINY_SIZES)]
    if output is not None:
        argv += ["-o", output]
    if rng.random() < 0.3:
        argv += ["--depth", "{D}/w/depth.npy"]
    if rng.random() < 0.2:
        argv += ["--background", "transparent"]
    if rng.random() < 0.7:
        argv.append("-q")
    if gpu:
        argv += ["--context", "egl"]
    return argv


def command_for(rng: random.Random, scene: str) -> list[str]:
    """Mostly the reference render; now and then shaders, or the GL backend / compare."""
    r = rng.random()
    if r < GPU_FRACTION / 2:
        return render_argv(rng, scene, gpu=True)
    if r < GPU_FRACTION:
        return ["compare", scene, "--size", rng.choice(TINY_SIZES), "--out", "{D}/w/cmp",
                "--context", "egl"]
    if r < GPU_FRACTION + 0.04:
        return ["shaders", scene, "--out", "{D}/w/sh"]
    return render_argv(rng, scene)


def scene_case(rng, seed, kind, data, files=None, **extra) -> Case:
    files = dict(files or {})
    files["s/scene.toml"] = data if isinstance(data, bytes) else toml_document(data)
    return Case(seed, kind, command_for(rng, "{D}/s/scene.toml"), files, **extra)


# =========================================================================== the classes

EXTREME_NUMBERS = (0, 0.0, -0.0, 1, -1, 1e300, -1e300, 1e-300, 5e-324, math.inf, -math.inf,
                   math.nan, (1 << 63) - 1, -(1 << 63), 3.4e38, 3.5e38, 1e39, 1 << 31, 16.0)


def random_value(rng: random.Random, depth=0):
    r = rng.randrange(12)
    if r < 4:
        return rng.choice(EXTREME_NUMBERS)
    if r == 4:
        return rng.choice((True, False))
    if r == 5:
        return rng.choice(("", "x", "phong", "uv_sphere", "directional", "a\nb", "\0",
                           "\x1b[31m", "é" * 10, "x" * rng.choice((300, 5000)), "../../x",
                           "meshes/torus_knot.obj", "C:\\x", "a\rb"))
    if r == 6 or depth > 2:
        return [rng.choice(EXTREME_NUMBERS) for _ in range(rng.choice((0, 1, 2, 3, 3, 3, 4)))]
    if r == 7:
        return {}
    if r == 8:
        return {rng.choice(("primitive", "file", "x", "type", "kd")): random_value(rng, depth + 1)}
    if r == 9:
        return [random_value(rng, depth + 1) for _ in range(rng.randint(1, 3))]
    if r == 10:
        return Raw("[" * 1000 + "]" * 1000) if rng.random() < 0.5 else \
            Raw("{a = " * 1000 + "1" + "}" * 1000)
    return rng.uniform(-10, 10)


def _nodes(data, path=()):
    """(container, key) of every value in the structure."""
    if isinstance(data, dict):
        for k, v in list(data.items()):
            yield data, k
            yield from _nodes(v, path + (k,))
    elif isinstance(data, list):
        for i, v in enumerate(data):
            yield data, i
            yield from _nodes(v, path + (i,))


def mutate_scene(rng: random.Random, data: dict) -> dict:
    for _ in range(rng.randint(1, 3)):
        nodes = list(_nodes(data))
        if not nodes:
            data["camera"] = random_value(rng)
            continue
        container, key = rng.choice(nodes)
        op = rng.randrange(6)
        if op == 0:                                                   # delete
            del container[key]
        elif op == 1 and isinstance(container, dict):                 # duplicate under a new key
            new = rng.choice((f"{key}_", f"{key}\n", str(key).upper(), "name", "parent", "mesh"))
            container[new] = _copy(container[key])
        elif op == 1:
            container.append(_copy(container[key]))
        elif op in (2, 3):                                            # replace / change type
            container[key] = random_value(rng)
        elif op == 4 and isinstance(container[key], (int, float)) and not isinstance(container[key], bool):
            container[key] = rng.choice((str(container[key]), [container[key]], -container[key],
                                         container[key] * 1e300, int(container[key]) if
                                         math.isfinite(container[key]) else 0))
        elif isinstance(container, dict):                             # rename the key
            value = container.pop(key)
            container[rng.choice((f"{key}\n", f" {key}", f"{key}\0", f"{str(key)[:-1]}",
                                  "x" * 300))] = value
    return data


def gen_valid(rng, seed) -> Case:
    name = rng.choice(sorted(builtin_scene_data()))
    if rng.random() < 0.5:
        return Case(seed, f"valid: built-in {name}", command_for(rng, name))
    return scene_case(rng, seed, f"valid: copy of {name}", _copy(builtin_scene_data()[name]))


def gen_mutated_scene(rng, seed) -> Case:
    name = rng.choice(sorted(builtin_scene_data()))
    return scene_case(rng, seed, f"mutated scene from {name}",
                      mutate_scene(rng, _copy(builtin_scene_data()[name])))


def gen_deep_nesting(rng, seed) -> Case:
    depth = rng.choice((500, 1000, 1000, 3000))
    raw = rng.choice(("[" * depth + "]" * depth, "{a = " * depth + "1" + "}" * depth,
                      "[{a = " * depth + "1" + "}]" * depth))
    data = small_scene()
    where = rng.randrange(4)
    if where == 0:
        data["deep"] = Raw(raw)
    elif where == 1:
        data["camera"]["eye"] = Raw(raw)
    elif where == 2:
        data["objects"][0]["mesh"] = Raw(raw)
    else:
        data["lights"][0]["intensity"] = Raw(raw)
    return scene_case(rng, seed, f"deep nesting ({depth}, at {where})", data)


def gen_parents(rng, seed) -> Case:
    n = rng.choice((3, 200, 1000, 1000, 2000))
    kind = rng.randrange(3)
    objects = []
    for i in range(n):
        obj = {"name": f"o{i}", "mesh": {"primitive": "cube", "size": 0.1},
               "translate": [0.001, 0.0, 0.0]}
        if kind == 0 and i + 1 < n:                 # children first: o0 -> o1 -> ... -> o(n-1)
            obj["parent"] = f"o{i + 1}"
        elif kind == 1:                             # one big cycle
            obj["parent"] = f"o{(i + 1) % n}"
        elif kind == 2 and i > 0:                   # a chain and a 2-cycle at its end
            obj["parent"] = f"o{i - 1}" if i < n - 1 else f"o{n - 2}"
        objects.append(obj)
    if kind == 2:
        objects[n - 2]["parent"] = f"o{n - 1}"
    label = ("chain, children first", "cycle", "chain into a 2-cycle")[kind]
    return scene_case(rng, seed, f"parents: {label} of {n}", small_scene(objects))


def gen_many_lights(rng, seed) -> Case:
    n = rng.choice((100, 1000, 2000, 3000))
    lights = []
    for i in range(n):
        if rng.random() < 0.5:
            lights.append({"type": "directional", "direction": [0.0, -1.0, -1.0],
                           "intensity": 0.001})
        else:
            lights.append({"type": "point", "position": [float(i % 7), 2.0, 3.0],
                           "intensity": 0.001, "attenuation": [1.0, 0.1, 0.01]})
    return scene_case(rng, seed, f"{n} lights", small_scene(lights=lights))


def gen_bad_paths(rng, seed) -> Case:
    long_component = "m" * rng.choice((256, 300, 5000))
    long_path = "/".join(["d" * 100] * 45)
    what = rng.choice(("long component", "long path", "null byte", "unreadable folder",
                       "through a file", "newline", "empty", "folder", "dot", "absolute long"))
    mesh_path = {"long component": long_component + ".obj", "long path": long_path + "/x.obj",
                 "null byte": "me\0sh.obj", "unreadable folder": "locked/m.obj",
                 "through a file": "plain.txt/m.obj", "newline": "me\nsh.obj", "empty": "",
                 "folder": "adir.obj", "dot": ".", "absolute long": "/" + long_component + ".obj"}[what]
    files = {"s/locked/m.obj": obj_bytes(), "s/plain.txt": b"text\n", "s/adir.obj/k": b""}
    unreadable = ["s/locked"]
    if rng.random() < 0.5:                  # in a scene file's mesh = { file = ... }
        data = small_scene([{"name": "a", "mesh": {"file": mesh_path}}])
        return scene_case(rng, seed, f"bad mesh path: {what}", data, files, unreadable=unreadable)
    scene_path = {"long component": "{D}/" + long_component + ".toml",
                  "long path": long_path + ".toml", "null byte": "{D}/s/sc\0ene.toml",
                  "unreadable folder": "{D}/s/locked/scene.toml",
                  "through a file": "{D}/s/plain.txt/scene.toml", "newline": "{D}/s/sc\nene",
                  "empty": "", "folder": "{D}/s/adir.obj", "dot": ".",
                  "absolute long": "/" + long_component}[what]
    files["s/locked/scene.toml"] = toml_document(small_scene())
    return Case(seed, f"bad scene argument: {what}", command_for(rng, scene_path), files,
                unreadable=unreadable)


def gen_scene_name(rng, seed) -> Case:
    name = rng.choice(("a\0b", "n" * 300, "../../x", "{D}/abs/x", "", ".", "..", "a/b", "a\nb",
                       ".hidden", "x.png", "con", " ", "-o", "sphere"))
    data = small_scene(name=name.replace("{D}", "@D@"))
    case = scene_case(rng, seed, f"scene name {name!r}", data, dirs=["abs", "w/a/b"],
                      name_class=True)
    case.cwd = "w/a/b"
    if case.argv[0] == "render":            # no -o: the default output's name is the question
        i = case.argv.index("-o")
        del case.argv[i:i + 2]
    elif case.argv[0] in ("compare", "shaders"):
        i = case.argv.index("--out")
        del case.argv[i:i + 2]
    return case


def gen_output_faults(rng, seed) -> Case:
    fault = rng.choice(("existing folder", "folder named .png", "parent is a file", "empty",
                        "same file", "depth is a folder", "existing file", "deep new folder",
                        "no suffix", "bad suffix", "jpg transparent", "depth parent file",
                        "out is a file", "long output name", "null in output"))
    files = {"w/plain.txt": b"x\n", "w/old.png": b"not really a png", "w/dir.npy/keep": b"k",
             "w/out.png/keep": b"k"}
    argv = render_argv(rng, "sphere")
    i = argv.index("-o")
    if "--depth" in argv:
        j = argv.index("--depth")
        del argv[j:j + 2]
    output = {"existing folder": "{D}/w", "folder named .png": "{D}/w/out.png",
              "parent is a file": "{D}/w/plain.txt/x.png", "empty": "", "same file": "{D}/w/x.png",
              "depth is a folder": "{D}/w/x.png", "existing file": "{D}/w/old.png",
              "deep new folder": "{D}/w/n/e/w/x.png", "no suffix": "{D}/w/x",
              "bad suffix": "{D}/w/x.txt", "jpg transparent": "{D}/w/x.jpg",
              "depth parent file": "{D}/w/x.png", "out is a file": "",
              "long output name": "{D}/w/" + "o" * 300 + ".png",
              "null in output": "{D}/w/o\0.png"}[fault]
    argv[i + 1] = output
    if fault == "same file":
        argv += ["--depth", rng.choice(("{D}/w/x.png", "{D}/w/./x.png", "{D}/w/../w/x.png"))]
    elif fault == "depth is a folder":
        argv += ["--depth", "{D}/w/dir.npy"]
    elif fault == "depth parent file":
        argv += ["--depth", "{D}/w/plain.txt/d.npy"]
    elif fault == "jpg transparent":
        argv += ["--background", "transparent"]
    elif fault == "out is a file":
        argv = [rng.choice(("compare", "shaders")), "sphere", "--out", "{D}/w/plain.txt"]
        if argv[0] == "compare":
            argv += ["--size", "8x6", "--context", "egl"]
    return Case(seed, f"output fault: {fault}", argv, files)


def gen_messy(rng, seed) -> Case:
    what = rng.choice(("key newline", "material newline", "mesh inf", "mesh 1e300", "corrupt mesh",
                       "ply index 2^31+10", "translate 1e300", "eye 1e300", "scale 1e300",
                       "intensity 1e300", "position 1e300", "radius 1e300", "huge int",
                       "not utf-8", "bom", "object name newline", "shear 1e300", "rotate 1e300",
                       "near 1e-300", "far 1e300", "mesh -1e300"))
    data = small_scene()
    files = {}
    obj = data["objects"][0]
    big = rng.choice((1e300, 3.5e38, 1e39, -1e300))
    if what == "key newline":
        rng.choice((data["camera"], obj, data["lights"][0], data))[rng.choice(("ey\ne", "a\nb\nc", "\n"))] = 1.0
    elif what == "material newline":
        data["materials"] = {"re\nd": {"kd": 0.5}}
        obj["material"] = rng.choice(("re\nd", "r\ned"))
    elif what in ("mesh inf", "mesh 1e300", "mesh -1e300"):
        v = {"mesh inf": math.inf, "mesh 1e300": 1e300, "mesh -1e300": -1e300}[what]
        verts = list(TETRA_V)
        verts[rng.randrange(4)] = (v, 0.0, 0.0)
        suffix, blob = rng.choice(((".obj", obj_bytes(verts)), (".ply", ply_bytes(verts)),
                                   (".stl", stl_bytes(verts, ascii=True))))
        files["s/m" + suffix] = blob
        obj["mesh"] = {"file": "m" + suffix}
    elif what == "corrupt mesh":
        suffix, blob = valid_mesh(rng)
        files["s/m" + suffix] = mutate_bytes(rng, blob)
        obj["mesh"] = {"file": "m" + suffix}
    elif what == "ply index 2^31+10":
        faces = list(TETRA_F)
        faces[rng.randrange(4)] = (0, 1, (1 << 31) + 10)
        files["s/m.ply"] = ply_bytes(faces=faces, binary=rng.random() < 0.5)
        obj["mesh"] = {"file": "m.ply"}
    elif what == "translate 1e300":
        obj["translate"] = [big, 0.0, 0.0]
    elif what == "eye 1e300":
        data["camera"] = {"eye": [0.0, 0.0, big], "look": [0.0, 0.0, 0.0]}
        if rng.random() < 0.5:
            data["camera"]["far"] = 1e301
    elif what == "scale 1e300":
        obj["scale"] = big if big > 0 else 1e300
    elif what == "intensity 1e300":
        data["lights"][0]["intensity"] = abs(big)
    elif what == "position 1e300":
        data["lights"].append({"type": "point", "position": [big, 0.0, 0.0]})
    elif what == "radius 1e300":
        obj["mesh"] = {"primitive": rng.choice(("uv_sphere", "icosphere")), "radius": abs(big)}
    elif what == "huge int":
        obj["mesh"] = {"primitive": "plane", "segments": (1 << 63) - 1}
    elif what == "not utf-8":
        return scene_case(rng, seed, what, toml_document(data) + b"# \xff\xfe\n")
    elif what == "bom":
        return scene_case(rng, seed, what, b"\xef\xbb\xbf" + toml_document(data))
    elif what == "object name newline":
        obj["name"] = "a\nb"
        data["objects"].append({"mesh": {"primitive": "cube"}, "parent": "a\nc"})
    elif what == "shear 1e300":
        obj["shear"] = {"xy": big}
    elif what == "rotate 1e300":
        obj["rotate"] = [big, 0.0, 0.0]
    elif what == "near 1e-300":
        data["camera"].update(near=1e-300, far=rng.choice((1e-299, 1.0, 1e300)))
    elif what == "far 1e300":
        data["camera"].update(far=1e300, reversed_z=rng.random() < 0.5)
    return scene_case(rng, seed, f"messy: {what} ({big:g})", data, files)


def gen_resources(rng, seed) -> Case:
    what = rng.choice(("huge size", "max segments", "many max primitives", "icosphere 6 x many",
                       "big mesh header", "many objects", "huge size gpu"))
    if what in ("huge size", "huge size gpu"):
        size = rng.choice(("16384x16384", "16384x8192", "10000x10000"))
        argv = render_argv(rng, "sphere", size=size, gpu=what == "huge size gpu")
        if WITH_MAX_MEMORY and rng.random() < 0.7:
            argv += ["--max-memory", rng.choice(("1G", "100M", "64MiB", "0", "-1", "1e3", "x"))]
        return Case(seed, f"resources: {what} {size}", argv)
    if what == "max segments":
        mesh = rng.choice(({"primitive": "uv_sphere", "segments": 1024, "rings": 1024},
                           {"primitive": "torus", "major_segments": 1024, "minor_segments": 1024},
                           {"primitive": "plane", "segments": 1024},
                           {"primitive": "cylinder", "segments": 1024}))
        data = small_scene([{"name": "a", "mesh": mesh}])
    elif what == "many max primitives":
        data = small_scene([{"name": f"o{i}", "mesh": {"primitive": "uv_sphere", "segments": 1024,
                                                        "rings": 1024}} for i in range(50)])
    elif what == "icosphere 6 x many":
        data = small_scene([{"name": f"o{i}", "mesh": {"primitive": "icosphere",
                                                        "subdivisions": 6}} for i in range(40)])
    elif what == "many objects":
        data = small_scene([{"mesh": {"primitive": "cube", "size": 0.01},
                             "translate": [i * 0.001, 0.0, 0.0]} for i in range(1000)])
    else:                                   # a header promising gigabytes, a tiny body
        suffix, blob = rng.choice(((".ply", ply_bytes(vertex_count=2_147_483_658)),
                                   (".ply", ply_bytes(binary=True, vertex_count=1 << 31,
                                                      face_count=1 << 31)),
                                   (".stl", stl_bytes(count=0xFFFFFFFF)),
                                   (".stl", stl_bytes(count=1 << 28))))
        data = small_scene([{"name": "a", "mesh": {"file": "big" + suffix}}])
        case = scene_case(rng, seed, f"resources: {what} {suffix}", data, {"s/big" + suffix: blob})
        return case
    if WITH_MAX_MEMORY and rng.random() < 0.5:
        case = scene_case(rng, seed, f"resources: {what}", data)
        if case.argv[0] == "render":
            case.argv += ["--max-memory", "256M"]
        return case
    return scene_case(rng, seed, f"resources: {what}", data)


def gen_mesh_mutation(rng, seed) -> Case:
    suffix, blob = valid_mesh(rng)
    data = small_scene([{"name": "a", "mesh": {"file": "m" + suffix}}])
    if rng.random() < 0.3:
        data["objects"][0]["mesh"]["crease_angle"] = rng.choice((0.0, 180.0, 1e-300, 1e300, 90.0))
    return scene_case(rng, seed, f"mesh bytes mutated ({suffix})", data,
                      {"s/m" + suffix: mutate_bytes(rng, blob)})


def gen_options(rng, seed) -> Case:
    argv = command_for(rng, rng.choice(("sphere", "hierarchy", "spher", "sphere.toml")))
    for _ in range(rng.randint(1, 2)):
        op = rng.randrange(8)
        if op == 0 and "--size" in argv:
            argv[argv.index("--size") + 1] = rng.choice(
                ("0x0", "-5x5", "8x", "x6", "axb", "8X6", " 8x6", "8x6x2", "1x16384", "16385x1",
                 "99999999999999999999x1", "1e3x2", "８x６", "", "8 x 6", "0x8"))
        elif op == 1:
            argv += ["--threshold", rng.choice(("-1", "256", "1e3", "0", "255", "", "nan"))]
        elif op == 2:
            argv += [rng.choice(("--backend", "--context", "--background")),
                     rng.choice(("gpu2", "", "osmesa", "reference", "transparent", "\0"))]
        elif op == 3:
            argv += [rng.choice(("--bogus", "-x", "--", "-", "--size", "-o", "--depth=", "--out"))]
        elif op == 4:
            argv.insert(1, rng.choice(("--version", "--help", "-q", "--frames=1")))
        elif op == 5:
            argv[0] = rng.choice(("rendr", "", "scenes", "render", "shaders"))
        elif op == 6 and "--depth" not in argv and argv[0] == "render":
            argv += ["--depth", rng.choice(("{D}/w/d.NPY", "{D}/w/d", "{D}/w/d.npz", "{D}/w/d.npy"))]
        elif op == 7 and argv[0] == "render":       # the output stage's (PNG when taken)
            option, values = rng.choice(OUTPUT_OPTION_VALUES)
            argv += [option, rng.choice(values)]
    return Case(seed, "options", argv)


OUTPUT_OPTION_VALUES = (      # taken or refused; a taken one writes a PNG (_check_image opens it)
    ("--bits", ("0", "1", "3", "8", "12", "16", "17", "-1", "1.5", "", "x", "1e1")),
    ("--transfer", ("srgb", "linear", "gamma:2.2", "gamma:0", "gamma:nan", "gamma:", "gamma:1e400", "", "sRGB")),
    ("--dither", ("none", "bayer2", "bayer8", "blue-noise", "floyd-steinberg", "jarvis-judice-ninke",
                  "bayer3", "", "\0")),
    ("--halftone", ("6", "6:15", "1", "1.99", "nan", "6:inf", "-6", "6:x", "", "1e400")),
    ("--format", ("png8", "png16", "exr", "npy", "tiff", "", "PNG8")),
)


# ---- issue 30: files a user names (textures, glTF resources, job files, manifests, special files)

CANARY = "canary-30f2: the contents of another file"    # no error line may ever quote it
SPECIAL_KINDS = ("fifo", "dir", "socket", "/dev/zero", "link:/dev/zero", "link:fifo",
                 "dangling link", "link to the real file")


def png_bytes(rng: random.Random, size=None, mode=None) -> bytes:
    """A small, valid PNG (Pillow, deterministic for a seed)."""
    from PIL import Image
    mode = mode or rng.choice(("RGB", "RGBA", "L", "LA", "P", "I;16", "1"))
    w, h = size or (rng.randint(1, 9), rng.randint(1, 9))
    image = Image.new(mode, (w, h))
    image.putdata([rng.randrange(2 if mode == "1" else 65536 if mode == "I;16" else 256)
                   if mode in ("L", "P", "I;16", "1") else
                   tuple(rng.randrange(256) for _ in mode)
                   for _ in range(w * h)])
    out = io.BytesIO()
    image.save(out, "PNG")
    return out.getvalue()


def jpeg_bytes(rng: random.Random, size=None) -> bytes:
    from PIL import Image
    w, h = size or (rng.randint(1, 16), rng.randint(1, 16))
    image = Image.new(rng.choice(("RGB", "L")), (w, h), rng.randrange(256))
    out = io.BytesIO()
    image.save(out, "JPEG", quality=rng.choice((10, 90)), progressive=rng.random() < 0.3)
    return out.getvalue()


def _png_chunk(kind: bytes, data: bytes) -> bytes:
    import zlib
    return struct.pack(">I", len(data)) + kind + data + struct.pack(">I", zlib.crc32(kind + data))


def png_declaring(width: int, height: int, *, depth=8, colour=2, rows=2, crc=True) -> bytes:
    """A PNG whose IHDR declares width x height and whose IDAT holds only `rows` rows (of
    zeros, compressed): a decompression bomb when the rows are all there, a lie when not."""
    import zlib
    ihdr = struct.pack(">IIBBBBB", width & 0xFFFFFFFF, height & 0xFFFFFFFF, depth, colour, 0, 0, 0)
    head = _png_chunk(b"IHDR", ihdr)
    if not crc:
        head = head[:-4] + b"\0\0\0\0"
    channels = {0: 1, 2: 3, 3: 1, 4: 2, 6: 4}.get(colour, 3)
    row = 1 + (width * channels * depth + 7) // 8
    body = zlib.compress(b"\0" * min(row * rows, 1 << 22), 9)
    return b"\x89PNG\r\n\x1a\n" + head + _png_chunk(b"IDAT", body) + _png_chunk(b"IEND", b"")


def jpeg_declaring(rng: random.Random, width: int, height: int) -> bytes:
    """A valid small JPEG with its frame header's (SOF) size changed."""
    data = bytearray(jpeg_bytes(rng, (8, 8)))
    for marker in (b"\xff\xc0", b"\xff\xc2"):
        at = data.find(marker)
        if at >= 0:
            data[at + 5:at + 9] = struct.pack(">HH", height & 0xFFFF, width & 0xFFFF)
    return bytes(data)


def npy_declaring(shape, dtype="<f4", body=b"", fortran=False) -> bytes:
    header = repr({"descr": dtype, "fortran_order": fortran, "shape": tuple(shape)}).encode()
    header += b" " * (63 - (len(header) + 10) % 64) + b"\n"
    return b"\x93NUMPY\x01\x00" + struct.pack("<H", len(header)) + header + body


def _image_for(rng: random.Random, what: str, suffix: str) -> bytes:
    return bad_image(rng, suffix, what)[1]


def bad_image(rng: random.Random, suffix: str = ".png", what: str | None = None) -> tuple[str, bytes]:
    """(what, bytes) of an image that lies, bombs, is cut short or corrupt, or is fine."""
    what = what or rng.choice(("valid", "valid", "declares 50000x50000", "declares 65000x65000 jpeg",
                       "declares 20000x4", "declares 16384x16384", "declares 0x0",
                       "declares 2^31 wide", "1-bit bomb 50000x50000", "grey bomb 3000x3000",
                       "grey 1200x1200 (fits)", "bad IHDR CRC", "rows missing", "truncated",
                       "bytes mutated", "empty", "text", "16-bit depth 1 colour 3 lie",
                       "bad colour type"))
    valid = jpeg_bytes(rng) if suffix == ".jpg" else png_bytes(rng)
    data = {
        "valid": lambda: valid,
        "declares 50000x50000": lambda: png_declaring(50000, 50000),
        "declares 65000x65000 jpeg": lambda: jpeg_declaring(rng, 65000, 65000),
        "declares 20000x4": lambda: png_declaring(20000, 4, rows=4),
        "declares 16384x16384": lambda: png_declaring(16384, 16384, depth=16, colour=6),
        "declares 0x0": lambda: png_declaring(0, 0),
        "declares 2^31 wide": lambda: png_declaring(1 << 31, 1),
        "1-bit bomb 50000x50000": lambda: png_declaring(50000, 50000, depth=1, colour=0, rows=50),
        "grey bomb 3000x3000": lambda: png_declaring(3000, 3000, colour=0, rows=3000),
        "grey 1200x1200 (fits)": lambda: png_declaring(1200, 1200, colour=0, rows=1200),
        "bad IHDR CRC": lambda: png_declaring(8, 8, crc=False, rows=8),
        "rows missing": lambda: png_declaring(64, 64, rows=3),
        "truncated": lambda: valid[:rng.randrange(max(1, len(valid)))],
        "bytes mutated": lambda: mutate_bytes(rng, valid),
        "empty": lambda: b"",
        "text": lambda: b"not an image at all\n" + CANARY.encode(),
        "16-bit depth 1 colour 3 lie": lambda: png_declaring(8, 8, depth=16, colour=3, rows=8),
        "bad colour type": lambda: png_declaring(8, 8, colour=5, rows=8),
    }[what]()
    return what, data


COLOUR_REFUSES = ("declares 50000x50000", "declares 65000x65000 jpeg", "declares 0x0",
                  "declares 2^31 wide", "1-bit bomb 50000x50000", "grey bomb 3000x3000",
                  "truncated", "empty", "text", "bad IHDR CRC")


def _special(rng: random.Random, real: str) -> str:
    """A kind from SPECIAL_KINDS (`real`: the relative path of a real file for the link)."""
    kind = rng.choice(SPECIAL_KINDS)
    return f"link:{real}" if kind == "link to the real file" else kind


def textured_scene(image: str, rng: random.Random) -> dict:
    texture = {"image": image}
    if rng.random() < 0.3:
        texture["colorspace"] = rng.choice(("linear", "srgb"))
    if rng.random() < 0.3:
        texture["filter"] = rng.choice(("nearest", "bilinear", "trilinear"))
    mesh = rng.choice(({"primitive": "uv_sphere", "segments": 8, "rings": 4},
                       {"primitive": "cube"}, {"primitive": "plane"}))
    return small_scene([{"name": "a", "mesh": mesh, "material": "t"}],
                       materials={"t": {"texture": texture}})


def gen_textures(rng, seed) -> Case:
    """A texture image (a scene's material) or `renderer colour`'s input that lies about its
    size, is a bomb, is cut short or corrupt; now and then a special file."""
    suffix = rng.choice((".png", ".png", ".jpg"))
    what, data = bad_image(rng, suffix)
    files = {"s/t" + suffix: data, "outside/secret.txt": CANARY.encode()}
    specials = {}
    path = "t" + suffix
    if rng.random() < 0.15:
        kind = _special(rng, "s/t" + suffix)
        what = f"special: {kind}"
        if kind == "/dev/zero":
            path = kind
        else:
            path = "sp" + suffix
            specials["s/sp" + suffix] = kind
    if rng.random() < 0.2:
        # renderer colour's image: one it refuses (a colour report takes 2-3 s to write; the
        # hand-written tests, test_colour_command.py, have those)
        if what not in COLOUR_REFUSES:
            what = rng.choice(COLOUR_REFUSES)
            files["s/t" + suffix] = _image_for(rng, what, suffix)
        if rng.random() < 0.3:
            path = "a.npy"
            what, files["s/a.npy"] = rng.choice((
                ("npy declares 50000x50000x4", npy_declaring((50000, 50000, 4))),
                ("npy declares (2^40, 1, 3)", npy_declaring((1 << 40, 1, 3))),
                ("npy object dtype", npy_declaring((2, 2, 3), "|O"))
                if rng.random() < 0.5 else ("npy 4x4x3 cut short", npy_declaring((4, 4, 3), body=b"\0" * 20)),
                ("npy bytes mutated", mutate_bytes(rng, npy_declaring((50000, 50000, 4)))),
                ))
        argv = ["colour", path if path.startswith("/") else "{D}/s/" + path, "--out", "{D}/w/col",
                "--backend", "reference"]
        return Case(seed, f"colour image: {what} ({path})", argv, files, specials=specials)
    return scene_case(rng, seed, f"texture {path}: {what}", textured_scene(path, rng), files,
                      specials=specials)


def gltf_document(rng: random.Random, image_uri=None, buffer_uri=None) -> dict:
    """A one-triangle glTF with TEXCOORD_0 and a base-colour texture, its buffer a data: URI
    (or `buffer_uri`), its image `image_uri` (default a file beside it, t.png)."""
    import base64
    positions = struct.pack("<9f", 0, 0, 0, 1, 0, 0, 0, 1, 0)
    uvs = struct.pack("<6f", 0, 0, 1, 0, 0, 1)
    blob = positions + uvs
    buffer = {"byteLength": len(blob),
              "uri": buffer_uri or "data:application/octet-stream;base64,"
              + base64.b64encode(blob).decode()}
    return {
        "asset": {"version": "2.0"},
        "scene": 0, "scenes": [{"nodes": [0]}], "nodes": [{"mesh": 0}],
        "meshes": [{"primitives": [{"attributes": {"POSITION": 0, "TEXCOORD_0": 1},
                                    "material": 0}]}],
        "materials": [{"pbrMetallicRoughness": {"baseColorTexture": {"index": 0},
                                                "baseColorFactor": [1, 1, 1, 1]}}],
        "textures": [{"source": 0, "sampler": 0}],
        "samplers": [{"wrapS": 10497, "wrapT": 10497}],
        "images": [{"uri": image_uri or "t.png"}],
        "buffers": [buffer],
        "bufferViews": [{"buffer": 0, "byteOffset": 0, "byteLength": 36},
                        {"buffer": 0, "byteOffset": 36, "byteLength": 24}],
        "accessors": [{"bufferView": 0, "componentType": 5126, "count": 3, "type": "VEC3",
                       "min": [0, 0, 0], "max": [1, 1, 0]},
                      {"bufferView": 1, "componentType": 5126, "count": 3, "type": "VEC2"}],
    }


ODD_URIS = ("t.png", "t%2Epng", "./t.png", "sub/../t.png", "../outside/secret.txt",
            "%2e%2e/outside/secret.txt", "..%2Foutside%2Fsecret.txt", "{D}/s/model/t.png",
            "/etc/passwd", "/dev/zero", "file:///etc/passwd", "http://example.invalid/t.png",
            "sp.png", "t.png\0x", "", ".", "..", "sub", "x" * 300 + ".png",
            "data:image/png;base64,", "data:", "data:image/png;base64,!!!",
            "data:image/png,plain", "%ZZ", "link_out.png", "t%20space.png", "C:\\t.png")


def gen_gltf(rng, seed) -> Case:
    """A .gltf mesh file with odd or escaping image and buffer URIs, data: URIs, missing
    buffers and mutated JSON."""
    import base64
    import json
    image = png_bytes(rng, mode="RGB")
    doc = gltf_document(rng)
    what = rng.choice(("image uri", "image uri", "buffer uri", "data: image", "missing buffer",
                       "mutated", "mutated", "valid", "image special"))
    specials = {"s/model/link_out.png": "link:outside/secret.txt"}
    if what == "image uri":
        uri = rng.choice(ODD_URIS)
        doc["images"][0]["uri"] = uri
        what = f"image uri {uri[:40]!r}"
    elif what == "buffer uri":
        uri = rng.choice(ODD_URIS + ("b.bin",))
        doc["buffers"][0]["uri"] = uri
        what = f"buffer uri {uri[:40]!r}"
    elif what == "data: image":
        kind, data = bad_image(rng)
        doc["images"][0]["uri"] = "data:image/png;base64," + base64.b64encode(data).decode()
        what = f"data: image ({kind})"
    elif what == "missing buffer":
        op = rng.randrange(4)
        if op == 0:
            del doc["buffers"]
        elif op == 1:
            doc["bufferViews"][rng.randrange(2)]["buffer"] = rng.choice((1, -1, 2 ** 40, "0"))
        elif op == 2:
            doc["bufferViews"][1]["byteLength"] = rng.choice((1 << 40, 0, -1, 10 ** 30))
        else:
            doc["images"][0] = {"bufferView": rng.choice((5, 0, 1)), "mimeType": "image/png"}
        what = f"missing buffer ({op})"
    elif what == "mutated":
        doc = mutate_scene(rng, doc)
    elif what == "image special":
        kind = _special(rng, "s/model/t.png")
        doc["images"][0]["uri"] = kind if kind == "/dev/zero" else "sp.png"
        if kind != "/dev/zero":
            specials["s/model/sp.png"] = kind
        what = f"image special {kind}"
    text = json.dumps(doc).replace("{D}", "@D@").encode()
    files = {"s/model/m.gltf": text, "s/model/t.png": image, "s/model/t space.png": image,
             "s/model/b.bin": base64.b64decode(gltf_document(rng)["buffers"][0]["uri"].split(",")[1]),
             "s/model/sub/k": b"", "s/outside/secret.txt": CANARY.encode(),
             "outside/secret.txt": CANARY.encode()}
    data = small_scene([{"name": "a", "mesh": {"file": "model/m.gltf"}}])
    return scene_case(rng, seed, f"glTF: {what}", data, files, specials=specials)


def job_document(rng: random.Random, scene: str = "sphere") -> dict:
    """A small job (one or two items) of docs/batch-format.md, for `renderer batch`."""
    entry = {"scene": scene}
    r = rng.random()
    if r < 0.3:
        entry["cameras"] = {"orbit": {"views": rng.choice((1, 2)),
                                      **({"elevation": 20.0} if rng.random() < 0.3 else {})}}
    elif r < 0.5:
        entry["cameras"] = {"poses": [{"eye": [0.0, 1.0, 4.0], "look": [0.0, 0.0, 0.0]}]}
    elif r < 0.55:
        entry["cameras"] = {"animation": {"frames": 1, "step": 0.5}}
    if rng.random() < 0.3:
        entry["sweep"] = rng.choice(({"camera.fov_y": [30.0, 50.0]},
                                     {"objects[0].material.kd": [[0.8, 0.2, 0.2]]},
                                     {"camera.eye": [[0.0, 0.0, 4.0]]}))
    setting = rng.choice(({"name": "raster"}, {"method": "raster", "shading": "flat"},
                          {"name": "rt", "method": "raytrace", "samples": 1, "max_depth": 1}))
    if rng.random() < 0.4:
        setting["outputs"] = rng.choice((
            [{"format": "png8", "transfer": "srgb"}],
            [{"format": "png16", "bits": 12, "dither": "bayer4"}, {"depth": "npy"}],
            [{"format": "npy", "name": "c.npy"}],
            [{"format": "png8", "halftone": "6:15", "name": "h.png"}]))
    job = {"seed": rng.choice((0, 5, (1 << 64) - 1)), "size": [8, 6], "scenes": [entry],
           "settings": [setting]}
    if rng.random() < 0.3:
        job["name"] = rng.choice(("j", "", "../x", "a\nb", "x" * 300))
    return job


def batch_argv(job: str = "{D}/s/job.toml", out: str = "{D}/w/out") -> list[str]:
    return ["batch", job, "--out", out, "--context", "egl"]


def gen_job_files(rng, seed) -> Case:
    """A job file for `renderer batch`: small and valid, or with random keys and values in
    its scenes, cameras, sweeps and settings."""
    scene = rng.choice(("sphere", "sphere", "scene.toml", "hierarchy", "nosuch", "../s/scene.toml"))
    job = job_document(rng, scene)
    what = "valid"
    if rng.random() < 0.7:
        job = mutate_scene(rng, job)
        what = "mutated"
    files = {"s/job.toml": toml_document(job), "s/scene.toml": toml_document(small_scene())}
    return Case(seed, f"job file ({what}, scene {scene})", batch_argv(), files)


MANIFEST_JOB = toml_document({"seed": 5, "size": [8, 6],
                              "scenes": [{"scene": "sphere", "cameras": {"orbit": {"views": 2}}}],
                              "settings": [{"name": "raster"}]})
RECORD_PATHS = ("../../outside/victim.txt", "{D}/outside/victim.txt", "/etc/shadow", "/dev/zero",
                "items/fifo", "items/link", "items/dir", "", "items", ".", "items/./x",
                "items//a", "items/../manifest.jsonl", "manifest.jsonl", "x\0y", 5, None,
                ["items"], "items/sock")


def gen_manifests(rng, seed) -> Case:
    """`renderer batch` resuming a finished --out whose manifest (or folder) is tampered with."""
    ops = []
    for _ in range(rng.randint(1, 2)):
        op = rng.choice(("record path", "record path", "sha", "truncate", "bytes", "header",
                         "record", "delete file", "manifest special", "lock special",
                         "items link", "long line", "stray"))
        if op == "record path":
            ops.append((op, rng.randrange(2), rng.choice(RECORD_PATHS)))
        elif op in ("sha", "delete file"):
            ops.append((op, rng.randrange(2)))
        elif op == "header":
            ops.append((op, rng.choice(("job", "format", "items", "manifest", "name", "renderer")),
                        random_value(rng)))
        elif op in ("manifest special", "lock special"):
            ops.append((op, rng.choice(("fifo", "dir", "socket", "link:/dev/zero", "link:victim",
                                        "dangling link", "garbage"))))
        else:
            ops.append((op, rng.randrange(1 << 30)))
    files = {"s/job.toml": MANIFEST_JOB, "outside/victim.txt": CANARY.encode()}
    kinds = ", ".join(str(o[:3])[:60] for o in ops)
    return Case(seed, f"tampered manifest: {kinds}", batch_argv(), files, finished="w/out",
                tamper=ops)


def gen_special_files(rng, seed) -> Case:
    """A FIFO, a folder, a socket, /dev/zero or a link where a file is expected: the scene
    argument, a mesh file, a job file, a job's scene, `renderer colour`'s image."""
    where = rng.choice(("scene argument", "mesh file", "job file", "job scene", "colour input",
                        "glTF buffer", "batch --out"))
    kind = rng.choice(SPECIAL_KINDS)
    real = {"scene argument": "s/scene.toml", "mesh file": "s/m.obj", "job file": "s/job.toml",
            "job scene": "s/scene.toml", "colour input": "s/bomb.png",
            "glTF buffer": "s/model/b.bin", "batch --out": "w/outdir"}[where]
    suffix = Path(real).suffix
    special = {"glTF buffer": "s/model/sp.bin", "batch --out": "w/sp"}.get(where, "s/sp" + suffix)
    path = "/dev/zero" if kind == "/dev/zero" else "{D}/" + special
    specials = {} if kind == "/dev/zero" else \
        {special: f"link:{real}" if kind == "link to the real file" else kind}
    files = {"s/scene.toml": toml_document(small_scene()), "s/m.obj": obj_bytes(),
             "s/t.png": png_bytes(rng, (4, 3), "RGB"), "s/bomb.png": png_declaring(50000, 50000),
             "s/job.toml": toml_document(job_document(random.Random(seed), "scene.toml"))}
    dirs = ["w/outdir"]
    if where == "scene argument":
        argv = command_for(rng, path)
    elif where == "mesh file":
        rel = path if path.startswith("/") else Path(special).name
        data = small_scene([{"name": "a", "mesh": {"file": rel}}])
        files["s/scene.toml"] = toml_document(data)
        argv = command_for(rng, "{D}/s/scene.toml")
    elif where == "job file":
        argv = batch_argv(path)
    elif where == "job scene":
        rel = path if path.startswith("/") else Path(special).name
        files["s/job.toml"] = toml_document(job_document(rng, rel))
        argv = batch_argv()
    elif where == "colour input":
        argv = ["colour", path, "--out", "{D}/w/col", "--backend", "reference"]
    elif where == "glTF buffer":
        import base64
        doc = gltf_document(rng, image_uri="data:image/png;base64,"
                            + base64.b64encode(files["s/t.png"]).decode(),
                            buffer_uri=path if path.startswith("/") else "sp.bin")
        files["s/model/b.bin"] = base64.b64decode(gltf_document(rng)["buffers"][0]["uri"].split(",")[1])
        files["s/model/m.gltf"] = __import__("json").dumps(doc).encode()
        files["s/scene.toml"] = toml_document(small_scene([{"name": "a",
                                                            "mesh": {"file": "model/m.gltf"}}]))
        argv = command_for(rng, "{D}/s/scene.toml")
    else:
        argv = batch_argv(out=path)
    return Case(seed, f"special file: {kind} as the {where}", argv, files, dirs=dirs,
                specials=specials)


CLASSES = {                  # name: (generator, weight)
    "valid": (gen_valid, 10),
    "mutated_scene": (gen_mutated_scene, 22),
    "deep_nesting": (gen_deep_nesting, 5),
    "parents": (gen_parents, 3),          # ~1 s a case today (quadratic cycle check)
    "many_lights": (gen_many_lights, 3),
    "bad_paths": (gen_bad_paths, 8),
    "scene_name": (gen_scene_name, 7),
    "output_faults": (gen_output_faults, 9),
    "messy": (gen_messy, 12),
    "resources": (gen_resources, 3),
    "mesh_mutation": (gen_mesh_mutation, 9),
    "options": (gen_options, 8),
    # issue 30: the files a user names
    "textures": (gen_textures, 5),
    "gltf": (gen_gltf, 4),
    "job_files": (gen_job_files, 3),      # batch in this process: ~0.05 s a case, GL warm
    "manifests": (gen_manifests, 3),
    "special_files": (gen_special_files, 4),
}


def make_case(seed: int) -> Case:
    rng = random.Random(seed)
    names = list(CLASSES)
    only = os.environ.get("FUZZ_CLASS")
    if only:
        name = only
    else:
        name = rng.choices(names, weights=[CLASSES[n][1] for n in names])[0]
    case = CLASSES[name][0](rng, seed)
    case.kind = f"{name}: {case.kind}"
    return case


# =========================================================================== running a case

@dataclass
class Outcome:
    code: object = None            # main's return value
    stdout: str = ""
    stderr: str = ""
    error: str | None = None       # an exception out of main (its traceback)
    seconds: float = 0.0           # wall clock
    cpu_seconds: float = 0.0       # this process's CPU time, user and system, every thread


def cpu_time() -> float:
    usage = resource.getrusage(resource.RUSAGE_SELF)
    return usage.ru_utime + usage.ru_stime


class Runaway(BaseException):
    """Raised by the timer: BaseException, so no `except Exception` in the code swallows it."""


def _vm_size() -> int:
    with open("/proc/self/status") as status:
        for line in status:
            if line.startswith("VmSize:"):
                return int(line.split()[1]) * 1024
    return 0


@contextlib.contextmanager
def runaway_guard(seconds: float = RUNAWAY_SECONDS, wait_seconds: float = RUNAWAY_WAIT_SECONDS,
                  extra_bytes: int = RUNAWAY_BYTES):
    """A CPU-time timer (ITIMER_PROF: the process's user and system time -> SIGPROF ->
    Runaway), a wall-clock one (SIGALRM) and an address-space limit (RLIMIT_AS: an allocation
    past it is a MemoryError), all undone afterwards."""
    def working(signum, frame):
        raise Runaway(f"ran over {seconds:g} s of CPU time")

    def waiting(signum, frame):
        raise Runaway(f"ran over {wait_seconds:g} s of wall-clock time")
    old_handlers = signal.signal(signal.SIGPROF, working), signal.signal(signal.SIGALRM, waiting)
    soft, hard = resource.getrlimit(resource.RLIMIT_AS)
    limit = _vm_size() + extra_bytes
    if hard != resource.RLIM_INFINITY:
        limit = min(limit, hard)
    resource.setrlimit(resource.RLIMIT_AS, (limit, hard))
    signal.setitimer(signal.ITIMER_PROF, seconds)
    signal.setitimer(signal.ITIMER_REAL, wait_seconds)
    try:
        yield
    finally:
        signal.setitimer(signal.ITIMER_PROF, 0)
        signal.setitimer(signal.ITIMER_REAL, 0)
        resource.setrlimit(resource.RLIMIT_AS, (soft, hard))
        signal.signal(signal.SIGPROF, old_handlers[0])
        signal.signal(signal.SIGALRM, old_handlers[1])


def run_main(main, argv: list[str]) -> Outcome:
    """main(argv) with stdout/stderr captured (Python warnings and logging records count as
    stderr lines, as a real process prints them)."""
    out, err = io.StringIO(), io.StringIO()
    outcome = Outcome()
    start, start_cpu = time.perf_counter(), cpu_time()
    with warnings.catch_warnings(record=True) as caught, \
            contextlib.redirect_stdout(out), contextlib.redirect_stderr(err):
        warnings.simplefilter("always")
        try:
            with memory.limit_set(FUZZ_MEMORY_LIMIT), runaway_guard():
                outcome.code = main(argv)
        except SystemExit as done:
            outcome.code = done.code
        except BaseException:       # noqa: BLE001 - anything else is what we look for
            outcome.error = traceback.format_exc()
    outcome.seconds, outcome.cpu_seconds = time.perf_counter() - start, cpu_time() - start_cpu
    outcome.stdout = out.getvalue()
    outcome.stderr = err.getvalue() + "".join(
        warnings.formatwarning(w.message, w.category, w.filename, w.lineno) for w in caught)
    return outcome


def snapshot(root: Path) -> dict[str, tuple]:
    """Every file and folder under root: (is folder, size, mtime) by relative path."""
    found = {}
    for folder, dirs, files in os.walk(root):
        for name in dirs + files:
            path = Path(folder, name)
            st = path.lstat()
            found[str(path.relative_to(root))] = (stat.S_ISDIR(st.st_mode), st.st_size,
                                                  st.st_mtime_ns)
    return found


def _size(argv) -> tuple[int, int] | None:
    if "--size" not in argv:
        return None
    try:
        w, h = argv[argv.index("--size") + 1].lower().split("x")
        return int(w), int(h)
    except (ValueError, IndexError):
        return None


def _opt(argv, *names):
    for i, a in enumerate(argv[:-1]):
        if a in names:
            return argv[i + 1]
    return None


def _error_line_ok(line: str) -> bool:
    return line.startswith("renderer: ") or (line.startswith("renderer ") and ": " in line
                                             and " " not in line.split(": ")[0][9:])


def check_outcome(case: Case, outcome: Outcome, before: dict, after: dict, root: Path) -> list[str]:
    """What is wrong with the outcome; [] when it keeps issue 13's rules."""
    problems = []
    if outcome.error is not None:
        return [f"exception out of main():\n{outcome.error.rstrip()}"]
    text = outcome.stdout + outcome.stderr
    if "Traceback" in text:
        problems.append("'Traceback' in the output")
    if CANARY in text:
        problems.append("an error or output line quotes another file's contents (the canary)")
    new = sorted(p for p in after if p not in before)
    changed = sorted(p for p in after if p in before and after[p] != before[p] and not after[p][0])
    gone = sorted(p for p in before if p not in after)
    lines = stderr_lines(case, outcome)
    code = outcome.code
    if case.argv[:1] == ["batch"]:              # a stale lock file is taken over and removed
        gone = [p for p in gone if Path(p).name != ".renderer-batch.lock"]
    if gone:
        problems.append(f"files removed: {gone}")
    if code in (1, 2):
        usage = len(lines) == 2 and lines[1].startswith("usage: ") and code == 2
        if not (len(lines) == 1 or usage):
            problems.append(f"exit {code} with {len(lines)} lines on stderr (one expected)")
        if lines and not _error_line_ok(lines[0]):
            problems.append(f"the error line does not start with 'renderer: ': {lines[0]!r}")
        if lines and lines[0].startswith("renderer: warning:"):
            problems.append("a warning line in a failure")
        if new or changed:
            problems.append(f"exit {code} but files written or left: new {new}, changed {changed}")
        if case.name_class and code == 2 and lines and ": name: " not in lines[0]:
            problems.append("a scene name refused for something else than its name key "
                            "(the output name came from it?)")
    elif code == 0:
        problems += _check_success(case, outcome, new, changed, root)
    else:
        problems.append(f"exit status {code!r} (expected 0, 1 or 2)")
    return problems


def _check_success(case: Case, outcome: Outcome, new, changed, root: Path) -> list[str]:
    problems = []
    argv = [a.replace("{D}", str(root)) for a in case.argv]
    batch = argv[:1] == ["batch"]
    for line in stderr_lines(case, outcome):
        if batch and line.startswith("renderer batch: ") and " items" in line:
            continue                            # its summary
        if not (line.startswith("renderer: warning: ") or line.startswith("wrote ")):
            problems.append(f"on success, a stderr line that is neither a warning nor 'wrote': "
                            f"{line[:200]!r}")
    written = set(new) | set(changed)
    files = {p for p in written if not (root / p).is_dir()}
    hidden = [p for p in files if Path(p).name.startswith(".")]
    if hidden:
        problems.append(f"hidden files left: {hidden}")
    command = next((a for a in argv if not a.startswith("-")), None)
    if any(a in ("--help", "-h", "--version") for a in argv) or command in ("scenes",):
        if files:
            problems.append(f"{command or argv} wrote files: {sorted(files)}")
        return problems
    expected: set[str] = set()
    size = _size(argv) or (640, 480)
    if command == "render":
        output = _opt(argv, "-o", "--output")
        depth = _opt(argv, "--depth")
        if output is None:                     # paths.default_output: out/ under the cwd
            default_folder = str(Path(case.cwd, "out"))
            cwd_files = [p for p in files if str(Path(p).parent) == default_folder
                         and not p.endswith(".npy")]
            if len(cwd_files) != 1:
                problems.append(f"without -o: expected one image in {default_folder}, "
                                f"got {sorted(files)}")
            images = cwd_files
        else:
            images = [os.path.relpath(os.path.abspath(os.path.join(root / case.cwd, output)), root)]
        expected.update(images)
        for image in images:
            problems += _check_image(root / image, size)
        if depth is not None:
            rel = os.path.relpath(os.path.abspath(os.path.join(root / case.cwd, depth)), root)
            expected.add(rel)
            try:
                array = np.load(root / rel)
                if array.shape != (size[1], size[0]):
                    problems.append(f"depth {rel}: shape {array.shape}, expected {(size[1], size[0])}")
            except Exception as exc:             # noqa: BLE001
                problems.append(f"depth {rel} does not load: {exc!r}")
    elif command == "compare":
        out = _opt(argv, "--out")
        folders = ([os.path.relpath(os.path.abspath(os.path.join(root / case.cwd, out)), root)]
                   if out else sorted({str(Path(p).parent) for p in files}))
        for folder in folders:
            for name in ("gpu.png", "reference.png", "diff.png"):
                expected.add(str(Path(folder, name)))
                problems += _check_image(root / folder / name, size)
    elif command == "shaders":
        out = _opt(argv, "--out")
        folders = ([os.path.relpath(os.path.abspath(os.path.join(root / case.cwd, out)), root)]
                   if out else sorted({str(Path(p).parent) for p in files}))
        shader_files = {p for p in files if Path(p).suffix in (".vert", ".tesc", ".tese", ".geom", ".frag")
                        and str(Path(p).parent) in folders}
        if not shader_files and "objects: " in outcome.stdout:
            problems.append("shaders listed variants but wrote no shader files")
        expected |= shader_files
    elif command in ("colour", "batch"):
        out = os.path.relpath(os.path.realpath(os.path.join(root / case.cwd, _opt(argv, "--out"))),
                              os.path.realpath(root))
        if command == "colour":
            for name in ("chromaticity.png", "luminance.png", "munsell.md", "colour.json"):
                expected.add(str(Path(out, name)))
                if not (root / out / name).is_file():
                    problems.append(f"colour: {out}/{name} missing")
        else:
            problems += _check_batch(root / out, stderr_lines(case, outcome))
            expected |= {p for p in files if p == out or p.startswith(out + "/")}
    extra = sorted(files - expected)
    if extra:
        problems.append(f"files written that were not asked for: {extra}")
    return problems


def stderr_lines(case: Case, outcome: Outcome) -> list[str]:
    """stderr's lines; for `renderer batch`, but its progress bar's (tqdm, redrawn with \\r)
    and the note that it runs in this process (in_this_process)."""
    if case.argv[:1] != ["batch"]:
        return outcome.stderr.splitlines()
    return [line for line in outcome.stderr.replace("\r", "\n").splitlines()
            if line and "%|" not in line and "Ray is not installed" not in line]


def _check_batch(out: Path, lines: list[str]) -> list[str]:
    """A finished batch folder: a record for each of the job's items (its summary line
    says how many) and each record's files there, whole."""
    import json
    import re
    try:
        header, *records = [json.loads(line) for line in
                            (out / "manifest.jsonl").read_text().splitlines()]
    except (OSError, ValueError) as exc:
        return [f"batch: the manifest does not read: {exc!r}"]
    items = [int(m.group(1)) for line in lines if (m := re.match(r"renderer batch: (\d+) items: ", line))]
    keys = {record.get("key") for record in records}
    if len(items) != 1 or len(keys) != items[0] or len(records) != len(keys):
        return [f"batch: {len(records)} records of {len(keys)} keys for {items} items"]
    problems = []
    for record in records:
        for output in record["outputs"]:
            path = out / output["path"]
            if path.suffix == ".png":
                problems += _check_image(path, _PNG_ANY)
            elif not path.is_file():
                problems.append(f"batch: {output['path']} missing")
    return problems


_PNG_ANY = None                         # _check_image: any size


def _check_image(path: Path, size) -> list[str]:
    from PIL import Image
    try:
        with Image.open(path) as image:
            image.load()
            if size is not None and image.size != tuple(size):
                return [f"{path.name}: size {image.size}, expected {tuple(size)}"]
    except Exception as exc:                     # noqa: BLE001
        return [f"image {path} missing or unreadable: {exc!r}"]
    return []


def _unlock(root: Path) -> None:
    for folder, dirs, _ in os.walk(root):
        for name in dirs:
            with contextlib.suppress(OSError):
                os.chmod(Path(folder, name), 0o755)


def materialise(case: Case, root: Path) -> list[str]:
    root.mkdir(parents=True)
    for d in [case.cwd, "w", *case.dirs]:
        (root / d).mkdir(parents=True, exist_ok=True)
    for rel, data in case.files.items():
        (root / rel).parent.mkdir(parents=True, exist_ok=True)
        (root / rel).write_bytes(data)
    for rel, data in case.files.items():
        if b"@D@" in data:                      # a file naming a path in the case's folder
            (root / rel).write_bytes(data.replace(b"@D@", str(root).encode()))
    for rel, kind in case.specials.items():
        make_special(root, rel, kind)
    if case.finished:
        shutil.copytree(finished_batch(), root / case.finished, symlinks=True)
        tamper_batch(case, root / case.finished, root)
    for rel in case.unreadable:
        os.chmod(root / rel, 0)
    return [a.replace("{D}", str(root)) for a in case.argv]


def make_special(root: Path, rel: str, kind: str) -> None:
    """A FIFO, folder, socket or link at root/rel (Case.specials)."""
    import socket
    path = root / rel
    path.parent.mkdir(parents=True, exist_ok=True)
    if kind == "fifo":
        os.mkfifo(path)
    elif kind == "dir":
        path.mkdir()
    elif kind == "socket":
        with socket.socket(socket.AF_UNIX) as sock:
            try:
                sock.bind(str(path))
            except OSError:                     # a path too long for AF_UNIX: a FIFO instead
                os.mkfifo(path)
    elif kind == "dangling link":
        path.symlink_to(root / "nowhere")
    elif kind == "link:fifo":
        os.mkfifo(path.with_name(path.name + ".fifo"))
        path.symlink_to(path.with_name(path.name + ".fifo"))
    elif kind.startswith("link:"):
        target = kind[5:]
        path.symlink_to(target if target.startswith("/") else root / target)
    elif kind == "garbage":
        path.write_bytes(b"{not json\n" + CANARY.encode())
    else:
        raise ValueError(kind)


_FINISHED: list[Path] = []


def finished_batch() -> Path:
    """MANIFEST_JOB rendered once in this process (outside any case's guard), its --out."""
    if not _FINISHED:
        import atexit
        import tempfile

        import renderer.cluster.executor as executor
        from renderer.cli import main
        folder = Path(tempfile.mkdtemp(prefix="fuzz-batch-"))
        atexit.register(shutil.rmtree, folder, ignore_errors=True)
        (folder / "job.toml").write_bytes(MANIFEST_JOB)
        real = executor.ray_available
        executor.ray_available = lambda: False
        try:
            with contextlib.redirect_stderr(io.StringIO()):
                code = main(batch_argv(str(folder / "job.toml"), str(folder / "out")))
        finally:
            executor.ray_available = real
        assert code == 0, "the manifest cases' job does not render"
        _FINISHED.append(folder / "out")
    return _FINISHED[0]


def tamper_batch(case: Case, out: Path, root: Path) -> None:
    """Case.tamper's changes to a finished batch folder (gen_manifests)."""
    import json
    rng = random.Random(case.seed)
    manifest = out / "manifest.jsonl"
    for op, *args in case.tamper:
        if manifest.is_symlink() or not manifest.is_file():
            break
        header, *records = manifest.read_bytes().split(b"\n")[:3]
        records = [r for r in records if r]
        if op in ("record path", "sha", "delete file", "record") and len(records) > args[0] % 2:
            index = args[0] % 2
            try:
                record = json.loads(records[index])
                record["outputs"][0]["path"]
            except (ValueError, KeyError, IndexError, TypeError):
                continue                        # no longer a record (an earlier change)
            if op == "record path":
                path = args[1]
                path = path.replace("{D}", str(root)) if isinstance(path, str) else path
                record["outputs"][0]["path"] = path
                items = out / "items"
                for name, kind in (("fifo", "fifo"), ("dir", "dir"), ("sock", "socket"),
                                   ("link", "link:outside/victim.txt")):
                    if not (items / name).exists() and not (items / name).is_symlink():
                        make_special(root, str((items / name).relative_to(root)), kind)
            elif op == "sha":
                record["outputs"][0]["sha256"] = "0" * 64
            elif op == "delete file":
                with contextlib.suppress(OSError, TypeError):
                    (out / record["outputs"][0]["path"]).unlink()
            else:
                record = mutate_scene(rng, record)
            records[index] = json.dumps(record).encode()
        elif op == "header":
            try:
                data = json.loads(header)
            except ValueError:
                continue
            if not isinstance(data, dict):
                continue
            data[args[0]] = args[1] if not isinstance(args[1], Raw) else str(args[1])
            header = json.dumps(data).encode()
        elif op == "truncate":
            records[-1] = records[-1][:args[0] % max(1, len(records[-1]))]
        elif op == "bytes":
            text = mutate_bytes(rng, b"\n".join([header, *records]) + b"\n")
            manifest.write_bytes(text)
            continue
        elif op == "long line":
            records.append(b'{"key": "' + b"k" * (1 << 21) + b'"')
        elif op == "stray":
            (out / "items" / "stray.txt").write_bytes(b"s")
        elif op == "items link":
            if (out / "items").is_symlink():
                continue
            shutil.rmtree(out / "items")
            (out / "items").symlink_to(root / "outside")
            continue
        elif op in ("manifest special", "lock special"):
            target = manifest if op == "manifest special" else out / ".renderer-batch.lock"
            if target.is_dir() and not target.is_symlink():
                shutil.rmtree(target)
            elif target.exists() or target.is_symlink():
                target.unlink()
            kind = {"link:victim": "link:outside/victim.txt"}.get(args[0], args[0])
            make_special(root, str(target.relative_to(root)), kind)
            continue
        manifest.write_bytes(b"\n".join([header, *records]) + b"\n")


def run_case(case: Case, root: Path, main=None) -> list[str]:
    """Build the case under `root` (made here, removed after), run it, check it."""
    if main is None:
        from renderer.cli import main
    argv = materialise(case, root)
    before = snapshot(root)
    old_cwd = os.getcwd()
    os.chdir(root / case.cwd)
    try:
        with in_this_process(argv):
            outcome = run_main(main, argv)
    finally:
        os.chdir(old_cwd)
        _unlock(root)
    after = snapshot(root)
    problems = check_outcome(case, outcome, before, after, root)
    if outcome.cpu_seconds > RUNAWAY_SECONDS:
        problems.append(f"took {outcome.cpu_seconds:.1f} s of CPU time (runaway: over {RUNAWAY_SECONDS:g} s)")
    if outcome.seconds > RUNAWAY_WAIT_SECONDS:
        problems.append(f"took {outcome.seconds:.1f} s (runaway: over {RUNAWAY_WAIT_SECONDS:g} s)")
    shutil.rmtree(root, ignore_errors=True)
    if problems:
        problems.append(f"exit {outcome.code!r} in {outcome.seconds:.2f} s ({outcome.cpu_seconds:.2f} s "
                        f"of CPU); stderr: "
                        f"{outcome.stderr[:500]!r}")
    return problems


_WARM: set[str] = set()


@contextlib.contextmanager
def in_this_process(argv):
    """`renderer batch` without Ray (its jobs in this process, as where Ray is not
    installed); `renderer colour`'s first run (seconds of imports and tables) made once
    outside the guard, so that a case's time is its own."""
    import renderer.cluster.executor as executor
    command = argv[0] if argv else None
    if command == "colour" and "colour" not in _WARM:
        import tempfile

        from PIL import Image

        from renderer.cli import main
        _WARM.add("colour")
        with tempfile.TemporaryDirectory() as folder, \
                contextlib.redirect_stdout(io.StringIO()), contextlib.redirect_stderr(io.StringIO()):
            Image.new("RGB", (4, 3)).save(Path(folder, "t.png"))
            main(["colour", str(Path(folder, "t.png")), "--out", str(Path(folder, "c")),
                  "--backend", "reference"])
    real = executor.ray_available
    if command == "batch":
        executor.ray_available = lambda: False
    try:
        yield
    finally:
        executor.ray_available = real


def run_seeds(seeds, tmp_path: Path) -> None:
    failures, lines = [], []
    by_class: dict[str, list[int]] = {}
    seeds = list(seeds)
    for seed in seeds:
        case = make_case(seed)
        problems = run_case(case, tmp_path / f"case{seed}")
        if problems:
            failures.append(f"{case.describe()[:1500]}\nPROBLEMS:\n  " + "\n  ".join(problems))
            by_class.setdefault(case.kind.split(":")[0], []).append(seed)
            last = problems[0].strip().splitlines()[-1] if problems[0].startswith("exception") else problems[0]
            lines.append(f"seed {seed} [{case.kind[:70]}]: {last[:160]}")
    if failures:
        summary = "\n".join(f"  {k}: {len(v)} (seeds {v[:8]})" for k, v in sorted(by_class.items()))
        pytest.fail(f"{len(failures)} of {len(seeds)} fuzz cases break issue 13's rules "
                    f"(rerun one: FUZZ_SEEDS=SEED pytest tests/test_fuzz.py -k seeds; print it: "
                    f"python tests/test_fuzz.py SEED)\nby class:\n{summary}\n\n" + "\n".join(lines)
                    + "\n\nThe first ones in full:\n\n" + "\n\n".join(failures[:20]), pytrace=False)


# =========================================================================== the tests

@pytest.mark.slow                  # the full run's: the module's docstring says why
def test_fuzz_default(tmp_path):
    """DEFAULT_CASES cases from BASE_SEED (a few seconds when the code is right)."""
    run_seeds(range(BASE_SEED, BASE_SEED + DEFAULT_CASES), tmp_path)


SLOW_PARTS = 3                      # the slow cases in parts, so that xdist spreads them


@pytest.mark.slow
@pytest.mark.parametrize("part", range(SLOW_PARTS))
def test_fuzz_slow(tmp_path, part):
    """SLOW_CASES further cases, a third in each part (90 s in one test held CI's last
    minute on one worker)."""
    start = BASE_SEED + DEFAULT_CASES + part * SLOW_CASES // SLOW_PARTS
    run_seeds(range(start, start + SLOW_CASES // SLOW_PARTS), tmp_path)


@pytest.mark.skipif(not os.environ.get("FUZZ_SEEDS"), reason="FUZZ_SEEDS=SEED[,SEED...] not set")
def test_fuzz_seeds(tmp_path):
    """The seeds in FUZZ_SEEDS, e.g. to reproduce a failure."""
    run_seeds([int(s) for s in os.environ["FUZZ_SEEDS"].split(",") if s.strip()], tmp_path)


def test_every_class_is_generated():
    """Every class of issue 13 comes up within the first DEFAULT_CASES seeds."""
    if os.environ.get("FUZZ_CLASS"):
        pytest.skip("FUZZ_CLASS chooses one class")
    seen = {make_case(s).kind.split(":")[0] for s in range(BASE_SEED, BASE_SEED + DEFAULT_CASES)}
    assert seen == set(CLASSES)


def test_cases_are_deterministic():
    for seed in (BASE_SEED, BASE_SEED + 7, 99):
        assert make_case(seed).describe() == make_case(seed).describe()


# ---- the harness can fail

def _fake(behaviour):
    def main(argv):
        out = argv[argv.index("-o") + 1] if "-o" in argv else None
        if behaviour == "raises":
            raise ValueError("boom")
        if behaviour == "two lines":
            print("renderer: one", file=sys.stderr)
            print("renderer: two", file=sys.stderr)
            return 2
        if behaviour == "leaves a file":
            Path(out).write_bytes(b"half")
            print("renderer: failed", file=sys.stderr)
            return 2
        if behaviour == "leaves a tmp file":
            Path(out).with_name(f".{Path(out).name}.x.tmp").write_bytes(b"half")
            print("renderer: failed", file=sys.stderr)
            return 2
        if behaviour == "traceback text":
            print("Traceback (most recent call last):", file=sys.stderr)
            return 2
        if behaviour == "no prefix":
            print("oops", file=sys.stderr)
            return 2
        if behaviour == "bad image":
            Path(out).write_bytes(b"not a png")
            return 0
        if behaviour == "wrong size":
            from PIL import Image
            Image.new("RGB", (3, 3)).save(out)
            return 0
        if behaviour == "extra file":
            from PIL import Image
            Image.new("RGB", _size(argv)).save(out)
            Path(out).with_name("stray.txt").write_text("x")
            return 0
        if behaviour == "python warning":
            warnings.warn("overflow encountered", RuntimeWarning)
            return 2
        if behaviour == "status 3":
            return 3
        if behaviour == "memory":
            return len(bytearray(4 * RUNAWAY_BYTES))
        if behaviour == "slow":
            time.sleep(RUNAWAY_WAIT_SECONDS + 5)
            return 0
        if behaviour == "busy":
            while True:
                sum(range(10_000))
        if behaviour == "good":
            from PIL import Image
            Image.new("RGB", _size(argv)).save(out)
            return 0
        if behaviour == "good refusal":
            print("renderer: scene.toml: camera.fov_y: must be between 0 and 180", file=sys.stderr)
            return 2
        raise AssertionError(behaviour)
    return main


@pytest.mark.parametrize("behaviour, says", [
    ("raises", "exception out of main"), ("two lines", "2 lines on stderr"),
    ("leaves a file", "files written or left"), ("leaves a tmp file", "files written or left"),
    ("traceback text", "Traceback"), ("no prefix", "does not start with"),
    ("bad image", "unreadable"), ("wrong size", "size (3, 3)"), ("extra file", "not asked for"),
    ("python warning", "2 lines on stderr"), ("status 3", "exit status 3"),
    ("memory", "MemoryError"),
])
def test_the_checker_reports(tmp_path, behaviour, says):
    case = Case(0, "hand-made", ["render", "sphere", "--backend", "reference", "--size", "8x6",
                                 "-o", "{D}/w/out.png", "-q"])
    problems = run_case(case, tmp_path / "c", main=_fake(behaviour))
    assert any(says in p for p in problems), problems


@pytest.mark.parametrize("behaviour, says", [("busy", "of CPU time"), ("slow", "of wall-clock time")])
def test_the_checker_stops_a_runaway(tmp_path, monkeypatch, behaviour, says):
    """Working (CPU time) and waiting (wall clock) each have their limit."""
    monkeypatch.setattr(sys.modules[__name__], "RUNAWAY_SECONDS", 0.3)
    monkeypatch.setattr(sys.modules[__name__], "RUNAWAY_WAIT_SECONDS", 0.6)
    case = Case(0, "hand-made", ["render", "-o", "{D}/w/out.png", "--size", "8x6"])
    start = time.perf_counter()
    real = runaway_guard
    monkeypatch.setattr(sys.modules[__name__], "runaway_guard",
                        lambda: real(seconds=0.3, wait_seconds=0.6))
    problems = run_case(case, tmp_path / "c", main=_fake(behaviour))
    assert time.perf_counter() - start < 5
    assert any("Runaway" in p and says in p for p in problems), problems


@pytest.mark.parametrize("behaviour", ["good", "good refusal"])
def test_the_checker_passes_good_behaviour(tmp_path, behaviour):
    case = Case(0, "hand-made", ["render", "sphere", "--backend", "reference", "--size", "8x6",
                                 "-o", "{D}/w/out.png", "-q"])
    assert run_case(case, tmp_path / "c", main=_fake(behaviour)) == []


if __name__ == "__main__":
    for arg in sys.argv[1:]:
        print(make_case(int(arg)).describe())
