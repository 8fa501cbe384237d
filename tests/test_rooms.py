"""validation's rooms: the root holds what every room shares, and each room lists its modules.

The layout is the map a newcomer reads (``docs/contributing.md``): a module is found by
the room of its job and the room's ``__init__`` docstring, which names every module in
it. These tests keep the root from regrowing and the docstrings from falling behind.
"""

from __future__ import annotations

import ast
import json
import re
import subprocess
import sys
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
    assert not _names(":mod:`~artic.validation.review.loops`", "loop")


def test_artic_validate_reaches_nothing_of_the_campaign(tmp_path):
    # What artic validate does (runs, tables, recordings, the gain sweep) is general
    # work, outside campaign/; the static contract (pyproject.toml) guards the rooms,
    # this the command itself, whose module also holds artic campaign and artic tune.
    log, out = tmp_path / "rev.parquet", tmp_path / "val"
    code = (
        "import json, sys\n"
        "from artic.validation.cli.entry import main\n"
        f"assert main(['simulate', '--model', 'kin', '--manoeuvre', 'ramp-steer-reverse', "
        f"'--amplitude-deg', '30', '--duration', '10', '--out', {str(log)!r}]) == 0\n"
        f"code = main(['validate', {str(log)!r}, '--models', 'kin', '--gain-sweep', "
        f"'--out-dir', {str(out)!r}])\n"
        "print(json.dumps([code, sorted(m for m in sys.modules if m.startswith('artic.'))]))\n")
    done = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True,
                          timeout=600)
    assert done.returncode == 0, done.stderr[-2000:]
    code, loaded = json.loads(done.stdout.splitlines()[-1])
    assert code == 0
    # It did the work whose modules it must find outside the campaign:
    assert {"artic.validation.runs.validate", "artic.validation.review.tables",
            "artic.validation.review.recording", "artic.validation.runs.gainsweep"} <= set(loaded)
    assert (out / "recordings" / "rev.rrd").is_file() and (out / "gain_sweep.csv").is_file()
    assert not [m for m in loaded if m.startswith("artic.validation.campaign")], loaded
