"""The process-wide settings of the artic command (artic.validation.plumbing.runtime), each in
a fresh process.

MuJoCo's callbacks and numba's configuration are per process, and the
bindings' default timer cannot be put back once replaced, so every check runs
in a subprocess.
"""

from __future__ import annotations

import os
import subprocess
import sys

import pytest

from artic.plant import ctyre

STEP = ("import mujoco; m = mujoco.MjModel.from_xml_string('<mujoco><worldbody><body>"
        "<freejoint/><geom size=\".1\"/></body></worldbody></mujoco>'); "
        "d = mujoco.MjData(m); T = mujoco.mjtTimer.mjTIMER_STEP\n")


def run(code: str) -> list[str]:
    env = {k: v for k, v in os.environ.items() if k != "NUMBA_CACHE_DIR"}
    return subprocess.run([sys.executable, "-c", code], capture_output=True, text=True,
                          check=True, env=env).stdout.split()


@pytest.fixture(scope="module", autouse=True)
def compiled():
    # CI installs with a C compiler: the zero clock lives in the compiled library.
    assert ctyre.library() is not None, ctyre.unavailable_reason()


def test_configure_stops_the_default_step_timer():
    out = run(STEP + "mujoco.mj_step(m, d); a = d.timer[T].duration\n"
              "from artic.validation.plumbing import runtime; runtime.configure()\n"
              "mujoco.mj_step(m, d); mujoco.mj_step(m, d)\n"
              "print(a > 0, d.timer[T].duration == a, d.timer[T].number)")
    # timed before, not after; the steps still count
    assert out == ["True", "True", "3"]


def test_configure_keeps_a_users_timer():
    out = run(STEP + "n = [0]\n"
              "def clock():\n    n[0] += 1\n    return float(n[0])\n"
              "mujoco.set_mjcb_time(clock)\n"
              "from artic.validation.plumbing import runtime; runtime.configure()\n"
              "mujoco.mj_step(m, d); print(mujoco.get_mjcb_time() is clock, n[0] > 0)")
    assert out == ["True", "True"]


def test_configure_does_not_import_numba_and_numba_then_uses_the_folder():
    # With compiled sources edited since the install (its cache not current).
    out = run("import sys; from artic.validation.plumbing import runtime\n"
              "runtime.install_cache_current = lambda: False; f = runtime.configure()\n"
              "print('numba' in sys.modules)\n"
              "import numba; print(numba.config.CACHE_DIR == str(f))")
    assert out == ["False", "True"]
