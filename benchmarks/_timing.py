"""Timing helper shared by the benchmarks (not a benchmark: run.py runs bench_*.py)."""

from __future__ import annotations

import contextlib
import math
import os
import time
from collections.abc import Callable, Iterator

REPEATS = 5


def best_wall(fn: Callable[[], object], repeats: int = REPEATS) -> float:
    """Best wall time of ``fn()`` over ``repeats`` calls after one warm-up (compilation) [s]."""
    fn()
    best = math.inf
    for _ in range(repeats):
        t0 = time.perf_counter()
        fn()
        best = min(best, time.perf_counter() - t0)
    return best


def bare_steps(model, states, nstep: int, callback: bool = False) -> float:
    """Wall time of ``mj_step(nstep)`` from each of ``states`` (integration states) [s].

    With ``callback`` False, MuJoCo's passive callback is switched off for the
    timing (and restored): the model's bare step. The state is set outside the
    timed span.
    """
    import mujoco

    d = mujoco.MjData(model)
    spec = mujoco.mjtState.mjSTATE_INTEGRATION
    saved = mujoco.get_mjcb_passive()
    if not callback:
        mujoco.set_mjcb_passive(None)
    wall = 0.0
    try:
        for s in states:
            mujoco.mj_setState(model, d, s, spec)
            t0 = time.perf_counter()
            mujoco.mj_step(model, d, nstep=nstep)
            wall += time.perf_counter() - t0
    finally:
        mujoco.set_mjcb_passive(saved)
    return wall


@contextlib.contextmanager
def one_core() -> Iterator[int | None]:
    """Run the calling thread on one core (the first it may use), then restore its affinity."""
    if not hasattr(os, "sched_setaffinity"):  # pragma: no cover - not Linux
        yield None
        return
    saved = os.sched_getaffinity(0)
    core = min(saved)
    os.sched_setaffinity(0, {core})
    try:
        yield core
    finally:
        os.sched_setaffinity(0, saved)


def timed_method(base: type, method: str) -> tuple[type, list[float]]:
    """A subclass of ``base`` whose ``method`` records each call's wall time [ms] in the list."""
    times: list[float] = []

    def wrapped(self, *args, **kwargs):
        t0 = time.perf_counter()
        out = getattr(super(timed, self), method)(*args, **kwargs)
        times.append(1e3 * (time.perf_counter() - t0))
        return out

    timed = type(base.__name__, (base,), {method: wrapped})
    return timed, times
