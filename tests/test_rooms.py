"""validation's rooms: the root holds what every room shares, and each room lists its modules.

The layout is the map a newcomer reads (``docs/contributing.md``): a module is found by
the room of its job and the room's ``__init__`` docstring, which names every module in
it. These tests keep the root from regrowing and the docstrings from falling behind.
"""

from __future__ import annotations

import ast
import re
from pathlib import Path

import pytest

ROOT = Path(__file__).resolve().parents[1]
VALIDATION = ROOT / "validation"

ROOT_MODULES = {"__init__.py", "models.py", "testing.py"}
"""What validation's root holds: the model registry every room reads, and the pytest
plugin (its import path, ``artic.validation.testing``, is what users write)."""

PACKAGES = sorted(p.parent for p in VALIDATION.rglob("__init__.py")
                  if "__pycache__" not in p.parts)


def test_validation_root_holds_only_the_registry_and_the_plugin():
    found = {p.name for p in VALIDATION.glob("*.py")}
    assert found == ROOT_MODULES, (
        f"validation/ holds {sorted(found - ROOT_MODULES)} beside {sorted(ROOT_MODULES)}: "
        "put a new module in the room of its job (harness/, criteria/, runs/, review/, cli/, "
        "logs/, synthetic/, campaign/, docking/)")


def _children(package: Path) -> list[str]:
    """The modules (``name.py``) and sub-packages (``name/``) of a package."""
    modules = [p.stem for p in package.glob("*.py") if p.name != "__init__.py"]
    subs = [p.name + "/" for p in package.iterdir()
            if p.is_dir() and (p / "__init__.py").is_file()]
    return sorted(modules + subs)


def _names(doc: str, child: str) -> bool:
    """Whether ``doc`` names ``child``: a reference ending in it, or its file or folder name."""
    stem = child.rstrip("/")
    return bool(re.search(rf"\.{stem}`|``{stem}(\.py|/)``|\b{stem}\.py\b", doc))


@pytest.mark.parametrize("package", PACKAGES, ids=lambda p: str(p.relative_to(ROOT)))
def test_each_room_names_every_module_in_its_docstring(package):
    doc = ast.get_docstring(ast.parse((package / "__init__.py").read_text()))
    assert doc, f"{package.relative_to(ROOT)}/__init__.py has no docstring saying its job"
    missing = [c for c in _children(package) if not _names(doc, c)]
    assert not missing, (f"{package.relative_to(ROOT)}/__init__.py: its docstring names no "
                         f"{', '.join(missing)}; add a line saying what each does")


def test_the_naming_rule_can_fail():
    # A room whose docstring mentions a module only in passing does not name it.
    assert _names(":mod:`~artic.validation.harness.loop`: the loop", "loop")
    assert _names("``harness/``: the closed loop", "harness/")
    assert not _names("the loop and its feedback", "loop")
    assert not _names(":mod:`~artic.validation.harness.loops`", "loop")
