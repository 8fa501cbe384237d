"""Compiling ahead (artic.validation.runs.warmup): the campaign's numba functions, on a core."""

from __future__ import annotations

import json
import os
import subprocess
import sys

import pytest

from artic.validation.runs import warmup


def test_the_warm_up_process_runs_to_the_end():
    # With this suite's cache warm it only loads what is compiled; it must end cleanly.
    proc = warmup.start()
    proc.join(120)
    assert proc.exitcode == 0


@pytest.mark.slow
def test_after_the_warm_up_the_campaign_calls_load_from_the_cache(tmp_path):
    # From an empty cache folder: the warm-up compiles, and a new process making the
    # same calls loads every function from disk and compiles nothing. If the warm-up
    # passed other argument types than the campaign does, numba would compile again.
    env = {**os.environ, "NUMBA_CACHE_DIR": str(tmp_path)}
    warm = ("from artic.validation.plumbing import runtime; runtime.configure(); "
            "from artic.validation.runs import warmup; p = warmup.start(); p.join(); "
            "raise SystemExit(p.exitcode)")
    subprocess.run([sys.executable, "-c", warm], env=env, check=True, timeout=300)
    check = ("import json; from artic.validation.plumbing import runtime; runtime.configure(); "
             "from artic.validation.runs.warmup import compile_all; compile_all(); "
             "from artic.validation.criteria import pathdist; "
             "from artic.validation.harness import reducedloop; "
             "s = [f.stats for f in (reducedloop.compiled_loop, pathdist._query)]; "
             "print(json.dumps([[len(x.cache_hits), len(x.cache_misses)] for x in s]))")
    out = subprocess.run([sys.executable, "-c", check], env=env, check=True, timeout=300,
                         capture_output=True, text=True).stdout
    assert json.loads(out.strip().splitlines()[-1]) == [[1, 0], [1, 0]]
