"""Sphinx's configuration for the manual (README "Documentation"; tests/test_docs.py builds it
with warnings as errors). The pages are the Markdown files of docs/ (MyST); the gallery is
made from examples/ by sphinx-gallery when the docs build, so each of its pictures is one the
current code drew."""

import sys
from pathlib import Path

ROOT = Path(__file__).resolve().parents[1]
sys.path.insert(0, str(ROOT))              # the checkout's renderer, as the tests import it

project = "checked-renderer"
author = "the checked-renderer developers"
extensions = ["myst_parser", "sphinx_gallery.gen_gallery"]
source_suffix = {".md": "markdown", ".rst": "restructuredtext"}
root_doc = "index"
exclude_patterns = ["_build", "gallery/*.ipynb", "gallery/*.py", "gallery/*.zip",
                    "gallery/*.md5", "gallery/*.codeobj.json"]
myst_heading_anchors = 3                   # [x](conventions.md#rays) reaches a heading
myst_enable_extensions = ["dollarmath"]
suppress_warnings = ["myst.header"]        # a page's first heading may be ## (a report's)
html_theme = "alabaster"
html_static_path = []

sphinx_gallery_conf = {
    "examples_dirs": str(ROOT / "examples"),
    "gallery_dirs": "gallery",
    "filename_pattern": r"/plot_",         # every example runs: its pictures are the current code's
    "download_all_examples": False,
    "remove_config_comments": True,
    "within_subsection_order": "FileNameSortKey",
}
