"""The README's Python example runs as written, from any folder (not only the repository
root): it loads a built-in scene by name."""

import re
import subprocess
import sys
from pathlib import Path

README = Path(__file__).resolve().parent.parent / "README.md"

# What the example leaves behind, checked after it has run.
CHECKS = """
assert scene.name == "sphere", scene.name
assert frame.rgba8.shape == (480, 640, 4) and expected.rgba8.shape == (480, 640, 4)
assert (frame.rgba8[..., 3] == 255).mean() > 0.05 and (expected.rgba8[..., 3] == 255).mean() > 0.05
print("README example ran")
"""


def using_it_python_block() -> str:
    """The one ```python block of the README's "Using it" section."""
    section = re.search(r"^## Using it\n(.*?)^## ", README.read_text(encoding="utf-8"), re.S | re.M)
    assert section, "README.md has no '## Using it' section"
    blocks = re.findall(r"^```python\n(.*?)^```", section[1], re.S | re.M)
    assert len(blocks) == 1, f"expected one python block in 'Using it', found {len(blocks)}"
    return blocks[0]


def test_the_using_it_example_loads_a_builtin_scene_by_name():
    assert 'load_scene("sphere")' in using_it_python_block()


def test_the_using_it_example_runs_from_another_folder(tmp_path):
    result = subprocess.run([sys.executable, "-c", using_it_python_block() + CHECKS],
                            cwd=tmp_path, capture_output=True, text=True, timeout=120)
    assert result.returncode == 0, result.stderr
    assert result.stdout.strip().splitlines()[-1] == "README example ran"
    assert list(tmp_path.iterdir()) == []                    # it writes nothing
