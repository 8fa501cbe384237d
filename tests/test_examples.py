"""Every public name's Examples section runs, as a doctest, and says what it shows.

The API reference renders these sections; running them here keeps them true.
"""

from __future__ import annotations

import doctest

import pytest

import artic

PUBLIC = [n for n in artic.__all__ if n != "__version__"]
CAMPAIGNS = {"run_campaign"}
"""Names whose example runs a campaign end to end: in the slow set (issue 42)."""


def _params() -> list:
    return [pytest.param(n, marks=pytest.mark.slow) if n in CAMPAIGNS else n for n in PUBLIC]


@pytest.mark.parametrize("name", _params())
def test_the_examples_of_a_public_name_run(name, tmp_path, monkeypatch):
    monkeypatch.chdir(tmp_path)  # an example that writes does so here
    obj = getattr(artic, name)
    tests = [t for t in doctest.DocTestFinder(recurse=False).find(obj, name)
             if t.examples]
    assert tests, f"artic.{name} has no Examples section"
    runner = doctest.DocTestRunner(optionflags=doctest.ELLIPSIS)
    for test in tests:
        runner.run(test)
    result = runner.summarize(verbose=False)
    assert result.failed == 0, f"{result.failed} of artic.{name}'s examples failed (above)"
