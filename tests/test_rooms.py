"""validation's rooms: the root holds what every room shares, and each room says its job.

The layout is the map a newcomer reads (``docs/contributing.md``): a module is found by
the room of its job, which the room's ``__init__`` docstring states, and by the module
list the docs generate from the code. The root's file names and the rooms' docstrings
are form: ``.ci/form.py`` checks them in CI (a lint step), and the test here shows
that its rules can fail.
"""

from __future__ import annotations

import importlib
import importlib.util
import json
import subprocess
import sys
from pathlib import Path

ROOT = Path(__file__).resolve().parents[1]

def _form():
    """``.ci/form.py``, the lint step that holds the layout's form policies."""
    spec = importlib.util.spec_from_file_location("form", ROOT / ".ci" / "form.py")
    form = importlib.util.module_from_spec(spec)
    spec.loader.exec_module(form)
    return form


def test_the_form_lint_names_each_breach_and_passes_a_tidy_tree(tmp_path):
    # The root whitelist and the rooms' docstrings are form, not behaviour: CI
    # checks them with .ci/form.py (before the tests). Here: its rules can fail.
    form = _form()
    room = tmp_path / "validation" / "harness"
    room.mkdir(parents=True)
    (tmp_path / "validation" / "__init__.py").write_text('"""The rooms, one per job."""\n')
    (tmp_path / "validation" / "models.py").write_text("")
    (room / "__init__.py").write_text(
        '"""The closed-loop harness: drives any model from a log.\n\n'
        ':mod:`~artic.validation.harness.loop`: the loop."""\n')
    (room / "loop.py").write_text("")
    assert form.problems(tmp_path) == []
    (tmp_path / "validation" / "helpers.py").write_text("")  # a module beside the rooms
    (room / "__init__.py").write_text('"""Harness\n\n:mod:`artic.validation.harness.loops`"""\n')
    found = form.problems(tmp_path)
    assert len(found) == 3, found
    assert found[0].startswith("validation/ holds helpers.py beside __init__.py, models.py")
    assert "first line must say the room's job" in found[1]
    assert "names artic.validation.harness.loops, which do not exist" in found[2]
    assert not form.job(None) and not form.job("The harness and\nits law.")


def test_the_docs_list_every_module_generated_from_the_code():
    # contributing.md's module list is drawn at each docs build from the four
    # folders' files (docs/_ext/artic_layout.py), so it cannot fall behind the code.
    page = (ROOT / "docs" / "contributing.md").read_text()
    block = page.split("## Every module", 1)[1].split("```{eval-rst}", 1)[1].split("```", 1)[0]
    assert block.strip() == ".. artic-layout::"
    spec = importlib.util.spec_from_file_location("artic_layout",
                                                  ROOT / "docs" / "_ext" / "artic_layout.py")
    layout = importlib.util.module_from_spec(spec)
    spec.loader.exec_module(layout)
    rows = dict(row for f in layout.FOLDERS for row in layout.modules(ROOT / f, f"artic.{f}"))
    # Every package and module the wheel installs, and nothing else.
    files = {p for f in layout.FOLDERS for p in (ROOT / f).rglob("*.py")
             if "__pycache__" not in p.parts}
    assert set(rows.values()) == files
    for name, path in rows.items():
        dotted = "artic." + ".".join(path.relative_to(ROOT).with_suffix("").parts)
        assert name == dotted.removesuffix(".__init__"), (name, path)
    # The first line is the docstring's, as Python reads it.
    for name in ("artic.plant", "artic.plant.tyre", "artic.validation.campaign.main"):
        doc = importlib.import_module(name).__doc__
        assert layout.first_line(rows[name]) == doc.strip().splitlines()[0]


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
