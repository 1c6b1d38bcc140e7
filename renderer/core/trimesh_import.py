"""trimesh, imported without scipy where scipy is not loaded yet: `from renderer.core.trimesh_import
import trimesh`.

trimesh imports scipy.spatial and scipy.optimize when it is itself imported (for convex hulls,
k-d trees, fitting spheres), if scipy is installed, and it is here (colour-science needs it):
some 190 of trimesh's 285 ms of import, a tenth of the time from a command's start to the
first image of a mesh (issue 32). This project uses trimesh's file readers and icosphere, which
need none of it. So while trimesh imports, scipy is hidden (a None in sys.modules, which makes
`import scipy` fail as if it were absent, and trimesh then stubs those features, as it does
without scipy), and shown again after: scipy itself still imports normally for whoever asks,
and a process that loaded scipy before gets the ordinary trimesh. tests/test_meshio.py holds
every mesh format's reading, and trimesh's and scipy's use afterwards, to that."""

from __future__ import annotations

import sys

if "trimesh" in sys.modules or "scipy" in sys.modules:
    import trimesh
else:
    sys.modules["scipy"] = None                 # `import scipy...` raises ImportError
    try:
        import trimesh
    finally:
        del sys.modules["scipy"]

__all__ = ["trimesh"]
