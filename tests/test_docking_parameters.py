"""No function of the docking benchmark takes more than ten parameters.

``tests/test_parameter_lists.py`` walks the rest of artic; this one walks
``validation/docking``, compiled kernels included (their groups travel as tuples),
with the same count and no waiting list.
"""

from __future__ import annotations

import ast

import pytest

from artic.validation.docking.spec import CONDITIONS, OPTIONS, RUN_OPTIONS, split_options
from tests.test_parameter_lists import MAX_PARAMETERS, ROOT, parameter_count


def test_no_docking_function_takes_more_than_ten_parameters():
    found = {}
    paths = sorted((ROOT / "validation" / "docking").rglob("*.py"))
    assert len(paths) > 20  # the walk sees the room (its modules, gym and controllers)
    for path in paths:
        for node in ast.walk(ast.parse(path.read_text(encoding="utf-8"))):
            if isinstance(node, (ast.FunctionDef, ast.AsyncFunctionDef)):
                n = parameter_count(node)
                if n > MAX_PARAMETERS:
                    found[(path.relative_to(ROOT).as_posix(), node.name)] = n
    assert not found, f"more than {MAX_PARAMETERS} parameters (group them in an object): {found}"


def test_split_options_sends_each_keyword_to_its_object():
    run, cond = split_options({"timeout": 5.0, "realtime": False, "delay": 0.02,
                               "sensor_set": "tractor", "truth": 3})
    assert run == {"timeout": 5.0, "realtime": False}
    assert (cond.delay, cond.sensor_set, cond.truth, cond.friction) == (0.02, "tractor", 3, 1.0)
    assert not set(RUN_OPTIONS) & set(CONDITIONS)
    assert sorted(OPTIONS) == sorted(RUN_OPTIONS + CONDITIONS)  # drive's keywords, each once


def test_split_options_refuses_an_unknown_keyword_as_a_function_would():
    with pytest.raises(TypeError, match="'speed'"):
        split_options({"speed": 1.0})
