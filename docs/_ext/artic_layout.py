"""The ``artic-layout`` directive: every package and module of artic, its docstring's first line.

``docs/contributing.md`` ("Every module") lists the layout with it. The table is
drawn at each docs build from the source files of the four folders (``mjcf``,
``plant``, ``reduced``, ``validation``, which install as ``artic.*``), read with
:mod:`ast`: nothing is imported, so the Warp modules are listed without the gpu
extra. It replaces a recursive autosummary whose page per module (215 of them)
held only a pointer back, while the theme drew on every page of the site a
navigation tree of every module: ``sphinx-build -W -b html docs`` took 44.8 s
(43.4-46.0), and 11.5 s (11.3-11.8) with this table (median and range of three runs
each, alternately, quiet, two cores, 2026-12-07).
"""

from __future__ import annotations

import ast
from pathlib import Path

from docutils import nodes
from docutils.statemachine import StringList
from sphinx.util.docutils import SphinxDirective

ROOT = Path(__file__).resolve().parents[2]
"""The repository root: the folders of :data:`FOLDERS` sit there."""

FOLDERS = ("mjcf", "plant", "reduced", "validation")
"""The folders that install as ``artic.<folder>``, in the order the table lists them."""


def first_line(path: Path) -> str:
    """The first line of ``path``'s module docstring, or a note that it has none."""
    doc = ast.get_docstring(ast.parse(path.read_text(encoding="utf-8")))
    return doc.strip().splitlines()[0] if doc and doc.strip() else "(no docstring)"


def modules(folder: Path, name: str) -> list[tuple[str, Path]]:
    """Package ``name`` at ``folder``, then its modules and sub-packages, depth first."""
    out = [(name, folder / "__init__.py")]
    for path in sorted(folder.iterdir()):
        if path.is_dir() and (path / "__init__.py").is_file():
            out += modules(path, f"{name}.{path.name}")
        elif path.suffix == ".py" and path.stem != "__init__":
            out.append((f"{name}.{path.stem}", path))
    return out


class Layout(SphinxDirective):
    """A two-column table: module name, first line of its docstring."""

    def run(self) -> list[nodes.Node]:
        """Parse the table as reStructuredText, the docstrings' own markup."""
        rows = [row for f in FOLDERS for row in modules(ROOT / f, f"artic.{f}")]
        lines = [".. list-table::", "   :header-rows: 1", "   :widths: 35 65", "",
                 "   * - module", "     - what it does"]
        for name, path in rows:
            self.env.note_dependency(str(path))  # an edited docstring rebuilds the page
            lines += [f"   * - ``{name}``", f"     - {first_line(path)}"]
        box = nodes.container()
        self.state.nested_parse(StringList(lines, source="artic-layout"), self.content_offset,
                                box)
        return box.children


def setup(app) -> dict:
    """Register the directive."""
    app.add_directive("artic-layout", Layout)
    return {"parallel_read_safe": True, "parallel_write_safe": True}
