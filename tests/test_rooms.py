"""validation's rooms: the root holds what every room shares, and each room says its job.

The layout is the map a newcomer reads (``docs/contributing.md``): a module is found by
the room of its job, which the room's ``__init__`` docstring states, and by the module
list the docs generate from the code. These tests keep the root from regrowing, each
room's job stated and its docstring free of stale names.
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


def _job(doc: str | None) -> str:
    """The job a room's docstring states: its first line, if it is a sentence of its own."""
    first = (doc or "").strip().splitlines()[0] if (doc or "").strip() else ""
    return first if len(first.split()) >= 3 and first.endswith(".") else ""


def _named_modules(doc: str) -> set[str]:
    """The artic modules a docstring refers to by role, e.g. :mod:`~artic.validation.x`."""
    return set(re.findall(r":mod:`~?(artic\.[\w.]+)`", doc))


def _exists(module: str) -> bool:
    rel = Path(*module.split(".")[1:])
    return (ROOT / rel).with_suffix(".py").is_file() or (ROOT / rel / "__init__.py").is_file()


@pytest.mark.parametrize("package", PACKAGES, ids=lambda p: str(p.relative_to(ROOT)))
def test_each_room_states_its_job_and_names_only_modules_it_has(package):
    # A room's docstring says its job in its first line; the modules it names
    # must exist (a renamed or moved module leaves no stale pointer). The full
    # list of every room's modules is generated in the docs (contributing.md),
    # so adding a module needs no line here.
    doc = ast.get_docstring(ast.parse((package / "__init__.py").read_text()))
    where = f"{package.relative_to(ROOT)}/__init__.py"
    assert _job(doc), f"{where}: its docstring's first line must say the room's job"
    stale = sorted(m for m in _named_modules(doc) if not _exists(m))
    assert not stale, f"{where}: its docstring names {', '.join(stale)}, which do not exist"


def test_the_rules_can_fail():
    assert _job("The closed-loop harness: drives any model from a log.\n\nMore.")
    assert not _job(None) and not _job("Harness") and not _job("The harness and\nits law.")
    assert _named_modules(":mod:`~artic.validation.harness.loop`: the loop, and "
                          ":mod:`artic.mjcf`") == {"artic.validation.harness.loop", "artic.mjcf"}
    assert _exists("artic.validation.harness.loop") and _exists("artic.validation.harness")
    assert not _exists("artic.validation.harness.loops")


def test_the_docs_list_every_module_generated_from_the_code():
    # contributing.md's module list is autosummary's, recursive over the four
    # folders, so it cannot fall behind the code.
    page = (ROOT / "docs" / "contributing.md").read_text()
    block = page.split("```{eval-rst}", 1)[1].split("```", 1)[0]
    assert ":recursive:" in block and ":template: layout-module.rst" in block
    assert set(re.findall(r"(?m)^   (artic\.\w+)\s*$", block)) == {
        f"artic.{p}" for p in ("mjcf", "plant", "reduced", "validation")}
    assert (ROOT / "docs" / "_templates" / "layout-module.rst").is_file()


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
