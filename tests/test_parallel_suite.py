"""The README's test command spreads the suite over processes file by file.

pytest-xdist's ``--dist loadfile`` keeps a file's tests in one process (its
module fixtures made once) and ``tests/conftest.py`` deals the files with the
default campaign and the slow tests first. A plugin's change of behaviour
would make the suite slower or make a costly fixture twice, silently: these
tests see it.
"""

from __future__ import annotations

import re
import subprocess
import sys
from pathlib import Path
from types import SimpleNamespace

import pytest

from tests import conftest

ROOT = Path(__file__).resolve().parents[1]


# A pytest-xdist session in a process of its own: end to end, in the slow set (issue 42).
@pytest.mark.slow
def test_each_file_runs_whole_in_one_process():
    pytest.importorskip("xdist", reason="pytest-xdist (the test extra) is not installed")
    # Three files that import little (the check is of the dealing, not of the tests).
    files = ["tests/test_parameter_lists.py", "tests/test_see_also.py", "tests/test_startup.py"]
    out = subprocess.run([sys.executable, "-m", "pytest", "-n", "2", "--dist", "loadfile", "-v",
                          "-p", "no:cacheprovider", *files], cwd=ROOT, capture_output=True,
                         text=True, timeout=600)
    assert out.returncode == 0, out.stdout[-3000:]
    workers: dict[str, set[str]] = {}
    for worker, name in re.findall(r"\[(gw\d+)\].* PASSED (tests/\S+?)::", out.stdout):
        workers.setdefault(name, set()).add(worker)
    assert set(workers) == set(files)
    assert all(len(w) == 1 for w in workers.values()), workers
    # Two processes were used: the files were spread, not run one after another.
    assert len(set().union(*workers.values())) == 2, workers


def _item(path: str, slow: bool = False, campaign: bool = False):
    return SimpleNamespace(path=Path(path), fixturenames=["default_campaign"] if campaign else [],
                           get_closest_marker=lambda name: object() if slow and name == "slow"
                           else None)


def test_the_default_campaign_and_the_slow_files_are_dealt_first():
    items = [_item("a.py"), _item("b.py", slow=True), _item("b.py"), _item("c.py"),
             _item("d.py", campaign=True, slow=True), _item("d.py")]
    worker = SimpleNamespace(workerinput={}, option=SimpleNamespace(dist="no"))
    conftest.pytest_collection_modifyitems(worker, items)
    assert [str(i.path) for i in items] == ["d.py", "d.py", "b.py", "b.py", "a.py", "c.py"]
    # A plain run (no xdist) keeps the collection's order.
    plain = SimpleNamespace(option=SimpleNamespace(dist="no"))
    again = [_item("a.py"), _item("d.py", campaign=True)]
    conftest.pytest_collection_modifyitems(plain, again)
    assert [str(i.path) for i in again] == ["a.py", "d.py"]
