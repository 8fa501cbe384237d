"""A reduced model's first call after install loads numba's cache instead of compiling.

``pip install`` fills the cache (``setup.py``'s ``build_ext`` runs
:mod:`artic.reduced.precompile`) where a user's process reads it:
``reduced/__pycache__`` beside the sources, with ``NUMBA_CACHE_DIR`` unset.
The ``artic`` command and the tests read the same folder while it holds today's
sources (:func:`artic.validation.plumbing.runtime.configure`), so a new user's
command, with an empty home folder, loads what the install compiled.
"""

from __future__ import annotations

import json
import os
import subprocess
import sys

import numpy as np
import pytest

from artic.reduced import control, precompile
from artic.validation.plumbing import runtime
from tests.helpers import FIRST_ROLLOUT


def test_precompile_calls_each_compiled_path_of_kin_and_the_stm():
    precompile.compile_all()
    for f in (control.rhs_batch, control.step_batch, control.rollout_steps,
              control.rollout_batch, control.step_one):
        # one signature serves both models: kind is an argument, P a float64 array
        assert any(str(sig[0]) == "int64" and str(sig[-1]) == "array(float64, 1d, C)"
                   for sig in f.signatures), (f, f.signatures)


@pytest.mark.slow
def test_the_first_rollout_after_install_loads_numbas_cache_within_half_a_second():
    # A user's process: numba's default cache, and no coverage tracing (pytest --cov
    # traces subprocesses through these variables, which slows a first call).
    env = {k: v for k, v in os.environ.items()
           if k != "NUMBA_CACHE_DIR" and not k.startswith(("COV_CORE", "COVERAGE"))}
    runs = []
    for _ in range(3):  # three fresh processes, each timing its first call
        out = subprocess.run([sys.executable, "-c", FIRST_ROLLOUT], env=env,
                             capture_output=True, text=True, check=True)
        runs.append(json.loads(out.stdout.strip().splitlines()[-1]))
    for got in runs:
        assert got["misses"] == 0 and got["hits"] == 1, (
            f"the first rollout compiled ({got}); was numba's cache filled at install? "
            "(pip install -e . runs artic.reduced.precompile)")
        # The cached code is the compiled code: 2 s at 1 m/s straight back.
        assert np.isclose(got["final"][0], -2.0, atol=1e-9), got
    # The target for the first call, 0.5 s (compiling the rollout instead
    # takes about 5 s). Counted in the process's CPU time, which other processes
    # inflate less than wall time, and the least of three fresh processes, each
    # a first call: about 0.35 s of it is numba's one-off set-up of its compiler
    # context and its probe of scipy's BLAS, which any first compiled call pays.
    assert min(got["cpu"] for got in runs) <= 0.5, runs


def test_a_command_with_an_empty_home_loads_the_installs_cache(tmp_path):
    # A new user's process configured as the artic command and the tests are: with
    # the install's cache current, numba is left on it, and the first rollout loads
    # (a hit, no miss) instead of compiling into a cache under the empty home.
    if not runtime.install_cache_current():
        pytest.fail("the install's numba cache does not hold today's sources: "
                    "pip install -e . fills it (artic.validation.plumbing.runtime)")
    env = {k: v for k, v in os.environ.items()
           if k != "NUMBA_CACHE_DIR" and not k.startswith(("COV_CORE", "COVERAGE"))}
    env["HOME"] = env["XDG_CACHE_HOME"] = str(tmp_path)
    code = ("from artic.validation.plumbing import runtime; "
            "print(runtime.configure())\n" + FIRST_ROLLOUT)
    out = subprocess.run([sys.executable, "-c", code], env=env, capture_output=True,
                         text=True, check=True, timeout=300).stdout.strip().splitlines()
    assert out[0] == str(runtime.install_cache())
    got = json.loads(out[-1])
    assert got["misses"] == 0 and got["hits"] == 1, got
    assert not (tmp_path / "artic").exists()  # nothing compiled under the home folder
