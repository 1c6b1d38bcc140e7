"""The manual's "Layout" page (docs/layout.md) against the tree: it names every shader under glsl/, every
package and module under renderer/ and reference/ (an __init__.py only where the section
chooses to), and every file or folder it names exists.

A path in backticks counts where it starts at a top-level entry of the repository
(`glsl/vertex.glsl`, `renderer/core/`). A bare name (`warp.glsl`, `scene.py`, `raytrace/`) in a
table is read in its folder: in a row whose first cell is a folder (`renderer/core/`), that
folder; in any other row the folder of the last full path before it in the same cell. The
tables are the listing: a bare name in a paragraph is read in no folder, and not counted."""

import os
import re
from pathlib import Path

ROOT = Path(__file__).resolve().parents[1]
SHADERS = {".glsl", ".comp", ".vert", ".tesc", ".tese", ".geom", ".frag"}
FILE_SUFFIXES = SHADERS | {".py", ".md", ".toml", ".sh", ".txt", ".json", ".csv", ".png", ".obj"}
SKIPPED = {".git", ".venv", "build", "__pycache__", "out"}
TOKEN = re.compile(r"`([^`\s]+)`")
NUMBERS = {word: n for n, word in enumerate(
    "zero one two three four five six seven eight nine ten eleven twelve thirteen fourteen "
    "fifteen sixteen seventeen eighteen nineteen twenty".split())}


LAYOUT = ROOT / "docs" / "layout.md"


def layout_section(page: str) -> str:
    """The page after its title."""
    return page.split("\n", 1)[1]


def tree(root: Path) -> tuple[set[str], set[str]]:
    """(every file and folder, folders ending in '/'; what the section must name)."""
    existing, required = set(), set()
    for folder, folders, files in os.walk(root):
        folders[:] = [name for name in folders
                      if name not in SKIPPED and not name.endswith(".egg-info")]
        for path in [Path(folder, name) for name in folders + files]:
            _place(path, path.relative_to(root).parts, existing, required)
    return existing, required


def _place(path: Path, parts: tuple[str, ...], existing: set[str], required: set[str]) -> None:
    """Adds one file or folder to what exists, and to what the section must name if it is one."""
    name = "/".join(parts) + ("/" if path.is_dir() else "")
    existing.add(name)
    if parts[0] == "glsl" and path.suffix in SHADERS:
        required.add(name)
    elif parts[0] in ("renderer", "reference") and len(parts) > 1:
        if path.is_dir() and (path / "__init__.py").exists():
            required.add(name)
        elif path.suffix == ".py" and path.name != "__init__.py":
            required.add(name)


def _units(section: str):
    """(in a table, row folder or None, text) for each table cell and each paragraph."""
    paragraph = []
    for line in section.splitlines() + [""]:
        if line.startswith("|"):
            cells = line.strip().strip("|").split("|")
            first = TOKEN.findall(cells[0])
            folder = first[0] if first and first[0].endswith("/") else None
            yield from ((True, folder, cell) for cell in cells)
        elif line.strip():
            paragraph.append(line)
            continue
        if paragraph:
            yield False, None, " ".join(paragraph)
            paragraph = []


def named_paths(section: str, top_level: set[str]) -> tuple[set[str], list[str]]:
    """(every path the section names, resolved; the bare names with no folder to read them in)."""
    named, unplaced = set(), []
    for in_table, folder, text in _units(section):
        base = folder
        for token in TOKEN.findall(text):
            is_dir = token.endswith("/")
            if token.startswith("-") or not (is_dir or Path(token).suffix in FILE_SUFFIXES):
                continue                                    # GpuRenderer, #define, renderer.scene
            if token.split("/")[0] + ("/" if "/" in token else "") in top_level:
                named.add(token)
                if folder is None and "/" in token:
                    base = token.rpartition("/")[0] + "/"
            elif not in_table:
                continue                                    # prose: `frame.py` of which folder?
            elif base is None:
                unplaced.append(token)
            else:
                named.add(base + token)
    return named, unplaced


def layout_problems(section: str, existing: set[str], required: set[str]) -> list[str]:
    top_level = {name for name in existing if name.count("/") == 0
                 or (name.count("/") == 1 and name.endswith("/"))}
    named, unplaced = named_paths(section, top_level)
    return ([f"not in the Layout: {name}" for name in sorted(required - named)]
            + [f"no such file: {name}" for name in sorted(named - existing)]
            + [f"no folder to read `{name}` in" for name in unplaced])


def test_the_layout_names_every_shader_and_module_and_only_what_exists():
    existing, required = tree(ROOT)
    assert {"glsl/vertex.glsl", "renderer/core/", "reference/raytrace/trace.py"} <= required
    section = layout_section(LAYOUT.read_text())
    assert layout_problems(section, existing, required) == []


def test_the_layout_counts_the_ray_tracing_stages_right():
    stages = sorted(path.stem for path in (ROOT / "glsl" / "raytrace").glob("*.glsl"))
    assert stages == sorted(path.stem for path in (ROOT / "reference" / "raytrace").glob("*.py")
                            if path.stem not in ("__init__", "pipeline"))
    claim = re.search(r"`reference/raytrace/` hold (\w+) stages",
                      " ".join(layout_section(LAYOUT.read_text()).split()))
    assert claim and NUMBERS.get(claim.group(1)) == len(stages)


FAKE_EXISTING = {"glsl/", "glsl/a.glsl", "glsl/raytrace/", "glsl/raytrace/b.glsl",
                 "glsl/raytrace/c.frag", "renderer/", "renderer/core/", "renderer/core/scene.py",
                 "renderer/core/new.py", "reference/", "reference/a.py", "README.md"}
FAKE_REQUIRED = {"glsl/a.glsl", "glsl/raytrace/b.glsl", "glsl/raytrace/c.frag", "renderer/core/",
                 "renderer/core/scene.py", "renderer/core/new.py", "reference/a.py"}


def test_the_check_sees_a_file_the_layout_misses_and_one_it_invents():
    section = ("| notes | GPU | reference |\n| --- | --- | --- |\n"
               "| a | `glsl/a.glsl` | `reference/a.py` |\n"
               "| b | `glsl/raytrace/b.glsl`, `gone.glsl` (`renderer/core/x.py`) | |\n"
               "\n| folder | what |\n| --- | --- |\n"
               "| `renderer/core/` | the scene (`scene.py`), `GpuRenderer`, `--size`, "
               "`glsl/raytrace/c.frag`, `frame.py` |\n| c | `intro.glsl` | |\n\n"
               "A paragraph's `colour.py` is read nowhere; its `reference/gone.py` is.\n")
    assert layout_problems(section, FAKE_EXISTING, FAKE_REQUIRED) == [
        "not in the Layout: renderer/core/new.py",
        "no such file: glsl/raytrace/gone.glsl",
        "no such file: reference/gone.py",
        "no such file: renderer/core/frame.py",
        "no such file: renderer/core/x.py",
        "no folder to read `intro.glsl` in"]


def test_the_check_passes_a_layout_that_names_everything():
    section = ("| a | `glsl/a.glsl`, `glsl/raytrace/b.glsl`, `c.frag` | `reference/a.py` |\n\n"
               "| `renderer/core/` | `scene.py`, `new.py` |\n")
    assert layout_problems(section, FAKE_EXISTING, FAKE_REQUIRED) == []


def test_the_tree_requires_shaders_packages_and_modules_but_not_package_inits(tmp_path):
    for name in ("glsl/raytrace/b.glsl", "glsl/notes.txt", "renderer/__init__.py",
                 "renderer/methods/__init__.py", "renderer/methods/raster.py",
                 "reference/output/__init__.py", "reference/output/colour.py", "tests/t.py"):
        (tmp_path / name).parent.mkdir(parents=True, exist_ok=True)
        (tmp_path / name).write_text("")
    existing, required = tree(tmp_path)
    assert required == {"glsl/raytrace/b.glsl", "renderer/methods/", "renderer/methods/raster.py",
                        "reference/output/", "reference/output/colour.py"}
    assert {"tests/t.py", "glsl/notes.txt", "renderer/__init__.py", "renderer/"} <= existing
