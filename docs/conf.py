"""Sphinx configuration for artic's documentation site.

Built in ``.ci/run`` with ``sphinx-build -W`` (warnings are errors), so a
broken reference or a malformed docstring fails CI. The pages are Markdown
(MyST); the API reference is generated from the numpydoc docstrings of the
public names in ``artic.__all__``.
"""

from __future__ import annotations

import sys
from pathlib import Path

import artic

sys.path.insert(0, str(Path(__file__).parent / "_ext"))  # artic_layout: the module table

project = "artic"
author = "artic developers"
copyright = "artic developers"  # noqa: A001 (Sphinx's name)
release = artic.__version__
version = release

extensions = [
    "myst_parser",
    "sphinx.ext.autodoc",
    "sphinx.ext.autosummary",
    "numpydoc",
    "artic_layout",
]
source_suffix = {".md": "markdown", ".rst": "restructuredtext"}
exclude_patterns = ["_build", "images", "_templates"]
templates_path = ["_templates"]
myst_enable_extensions = ["colon_fence"]
myst_heading_anchors = 3

autosummary_generate = True
autodoc_typehints = "none"  # numpydoc's Parameters sections carry the types and units
# The Warp plant's modules import warp and mujoco_warp, which only the gpu extra
# installs; the docs build (the test extra) documents them against stand-ins, so
# the API pages list them whether or not the extra is installed.
autodoc_mock_imports = ["warp", "mujoco_warp"]
numpydoc_show_class_members = False
numpydoc_class_members_toctree = False

html_theme = "furo"
html_title = f"artic {release}"
