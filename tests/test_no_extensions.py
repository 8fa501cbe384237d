"""artic without its C parts: an install without a C compiler, forced by ``ARTIC_NO_EXTENSIONS=1``.

The plant then runs on numpy (``Plant(backend="auto")`` warns and takes
``"python"``); what is compiled with no Python version (the truths' tyres and
loops, the comparisons of a compiled part with its reference) says so, and
its tests skip with that reason (:func:`tests.helpers.needs_compiled`).
"""

from __future__ import annotations

import os
import subprocess
import sys
from pathlib import Path

import pytest

ROOT = Path(__file__).resolve().parents[1]

FALLBACK_FILES = (
    "test_budget.py", "test_closedloop.py", "test_ctyre.py", "test_plant.py",
    "test_plant_options.py", "test_plant_step.py", "test_spinmode.py", "test_standalone.py",
    "test_tmeasy.py", "test_truth_model.py", "test_truth_timestep.py", "test_tyre_moments.py",
    "test_yard_truth.py", "test_extensions.py")
"""The test files whose outcome depends on the compiled parts: the plant, its callback,
step and loop, the harness's count of plant runs, the truths."""

SWITCHED_OFF = """
import warnings
from artic.mjcf import load_vehicle
from artic.plant import Plant, PlantWarning, closedloop, ctyre
from artic.validation.synthetic import truthc, yardtruth

assert ctyre.library() is None and "ARTIC_NO_EXTENSIONS" in ctyre.unavailable_reason()
assert closedloop.unavailable_reason() == ctyre.unavailable_reason()
assert truthc._loaded()[0] is None and yardtruth._library()[0] is None
with warnings.catch_warnings(record=True) as caught:
    warnings.simplefilter("always")
    with Plant(load_vehicle("gosar2022-unloaded")) as p:
        assert p.backend == "python" and p.closed_loop() is None
assert any(issubclass(w.category, PlantWarning) for w in caught)
try:
    yardtruth.library()
except yardtruth.YardUnavailable as exc:
    print(exc)
"""


def _env() -> dict[str, str]:
    return {**os.environ, "ARTIC_NO_EXTENSIONS": "1"}


def test_the_switch_turns_every_compiled_part_off():
    out = subprocess.run([sys.executable, "-c", SWITCHED_OFF], env=_env(), cwd=ROOT,
                         capture_output=True, text=True)
    assert out.returncode == 0, out.stderr[-3000:]
    assert "switched off (ARTIC_NO_EXTENSIONS is set)" in out.stdout


@pytest.mark.slow
def test_the_fast_tests_of_the_compiled_parts_pass_without_them():
    # What CI checks of an install without a C compiler: the fast tests of every
    # file that touches a compiled part, with the parts switched off. Each either
    # passes on the numpy fallback or skips because it needs what has no Python
    # version; none fails. Left out: the six tests marked long_on_numpy (timestep
    # studies at 1 ms, slopes, the hitch's transients), 84 % of this run's time on the
    # numpy tyre (858 of 1 026 s, measured on a loaded machine). They check the plant's
    # numerics and physics, which the fallback shares; the suite runs them compiled, and
    # the numpy tyre is held to the compiled one force by force and along a plant's
    # trajectory (tests/test_ctyre.py).
    files = [str(ROOT / "tests" / f) for f in FALLBACK_FILES]
    out = subprocess.run([sys.executable, "-m", "pytest", "-m", "not slow and not long_on_numpy",
                          "-q", "-rs",
                          "-p", "no:cacheprovider", *files], env=_env(), cwd=ROOT,
                         capture_output=True, text=True)
    # On a failure, what failed first: its traceback and the summary's FAILED lines
    # (the skip reasons, -rs, would otherwise fill the message's tail).
    failures = out.stdout.partition("= FAILURES =")[2][:6000]
    failed = [line for line in out.stdout.splitlines() if line.startswith(("FAILED", "ERROR"))]
    assert out.returncode == 0, "\n".join([*failed, failures, out.stdout[-1500:]])
