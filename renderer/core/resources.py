"""Where the shader files (glsl/) and bundled assets (assets/) are.

Two layouts (pyproject.toml, [tool.setuptools.package-dir]):
- an installed wheel carries them inside the package, as renderer/glsl and renderer/assets;
- a source checkout or an editable install keeps them at the top of the repository, beside
  renderer/ (the layout the product brief fixes).
"""

from __future__ import annotations

import functools
from pathlib import Path

PACKAGE_DIR = Path(__file__).resolve().parents[1]      # renderer/


def _locate(name: str) -> Path:
    candidates = (PACKAGE_DIR / name,            # wheel: renderer/glsl
                  PACKAGE_DIR.parent / name)     # checkout / editable: <repo>/glsl
    for candidate in candidates:
        if candidate.is_dir():
            return candidate
    raise FileNotFoundError(f"renderer data folder {name!r} not found; looked in "
                            + " and ".join(str(c) for c in candidates))


@functools.cache
def glsl_dir() -> Path:
    """The folder of the GLSL sources (vertex.glsl, geometry.glsl, fragment.glsl, lighting.glsl)."""
    return _locate("glsl")


@functools.cache
def assets_dir() -> Path:
    """The folder of bundled assets (meshes/, scenes/)."""
    return _locate("assets")
