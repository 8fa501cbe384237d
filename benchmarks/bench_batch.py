"""Reduced-model logs on threads against one call per log: three rounds, median and range.

The 8 forward tuning manoeuvres (constant steers at 200, 360 and 500 deg of
steering wheel, 5 and 10 km/h, 40 s at 100 Hz each), made by the STM itself,
run through the harness as one tuning objective evaluation does:

- ``batch, 2 threads``: :func:`artic.validation.harness.batch.run_batch` with ``jobs=2``,
  the logs spread over a thread pool (the compiled loop releases the GIL);
- ``batch, 1 thread``: the same with ``jobs=1``;
- ``per log``: :func:`artic.validation.harness.loop.run_inputs`, one compiled call per log.

Each round times every variant once, in turn, after a warm-up that compiles;
a figure is the median (range) over the rounds of real time per manoeuvre
(simulated seconds of all manoeuvres / wall seconds), and of the ratio of
batch to per-log speed within the round. Last, the compiled loop's
compilation from nothing (an empty numba cache, in a fresh process), the
price of the first run on a fresh machine.

Run: ``python benchmarks/run.py`` (or this file alone).
"""

from __future__ import annotations

import os
import statistics
import subprocess
import sys
import tempfile
import time

from artic.mjcf import load_vehicle
from artic.reduced import KIN, STM
from artic.validation.harness.batch import run_batch
from artic.validation.harness.loop import loop_inputs, run_inputs
from artic.validation.harness.simulate import simulate
from artic.validation.logs.runfile import Run
from artic.validation.logs.schema import COLUMNS
from artic.validation.synthetic.manoeuvres import make_profile

CELLS = [(200, 5), (500, 5), (360, 5), (360, 10)]
ROUNDS = 3
CALLS = 20
"""Calls per timing: one batch of KIN takes about a millisecond."""


def _wall(fn) -> float:
    t0 = time.perf_counter()
    for _ in range(CALLS):
        fn()
    return (time.perf_counter() - t0) / CALLS


def _compile_from_nothing() -> float:
    """Wall time of the first KIN run in a fresh process with an empty numba cache [s]."""
    code = ("import time, sys; sys.path.insert(0, 'benchmarks');"
            "from artic.mjcf import load_vehicle; from artic.reduced import KIN;"
            "from bench_closedloop import _inputs; "
            "from artic.validation.harness.loop import run_inputs;"
            "v = load_vehicle('gosar2022-unloaded'); i = _inputs(v);"
            "t0 = time.perf_counter(); run_inputs(KIN(v), i, v, 3.0);"
            "print(time.perf_counter() - t0)")
    with tempfile.TemporaryDirectory() as cache:
        env = {**os.environ, "NUMBA_CACHE_DIR": cache}
        out = subprocess.run([sys.executable, "-c", code], env=env, check=True,
                             capture_output=True, text=True)
    return float(out.stdout.split()[-1])


def _fmt(xs) -> str:
    return f"{statistics.median(xs):8.0f} ({min(xs):.0f}-{max(xs):.0f})"


def main() -> dict[str, list[float]]:
    v = load_vehicle("gosar2022-unloaded")
    s = v.steering_for("stm")
    logs = []
    for amp, kph in CELLS:
        for side in ("left", "right"):
            p = make_profile("constant-steer", amplitude_deg=amp, speed_kph=kph, side=side,
                             duration=40.0, delta_h_offset=s.delta_h_offset)
            run = simulate(STM(v), v, p)
            logs.append(Run(run.frame[list(COLUMNS)], {"name": f"{amp}-{kph}-{side}"}))
    sim = sum(float(log.frame.t.iloc[-1]) for log in logs)
    out: dict[str, list[float]] = {}
    for cls in (KIN, STM):
        steering = v.steering_for(cls.name)
        inputs = [loop_inputs(log, v, steering) for log in logs]
        variants = {
            "batch, 2 threads": lambda cls=cls, inputs=inputs: run_batch(cls, v, inputs, 3.0, 2),
            "batch, 1 thread": lambda cls=cls, inputs=inputs: run_batch(cls, v, inputs, 3.0, 1),
            "per log": lambda cls=cls, inputs=inputs: [run_inputs(cls(v), i, v, 3.0)
                                                       for i in inputs],
        }
        for fn in variants.values():
            fn()  # compiles, or loads numba's cache
        for _ in range(ROUNDS):
            walls = {k: _wall(fn) for k, fn in variants.items()}
            for k, w in walls.items():
                out.setdefault(f"{cls.name} {k}", []).append(sim / w)
            out.setdefault(f"{cls.name} batch/per log", []).append(
                walls["per log"] / walls["batch, 2 threads"])
    out["compile"] = [_compile_from_nothing() for _ in range(ROUNDS)]
    print(f"The tuning set ({len(logs)} manoeuvres, {sim:.0f} s simulated), real time per "
          f"manoeuvre, median (range) of {ROUNDS} rounds:")
    for m in ("kin", "stm"):
        for k in ("batch, 2 threads", "batch, 1 thread", "per log"):
            print(f"  {m.upper()} {k:16s} {_fmt(out[f'{m} {k}'])} x")
        r = out[f"{m} batch/per log"]
        print(f"  {m.upper()} batch (2 threads) speed / per-log speed: {statistics.median(r):.2f} "
              f"({min(r):.2f}-{max(r):.2f})")
    c = out["compile"]
    print(f"  compiling the loop from nothing (first KIN run, fresh process): "
          f"{statistics.median(c):.1f} s ({min(c):.1f}-{max(c):.1f})")
    return out


if __name__ == "__main__":
    from artic.validation.plumbing import runtime

    runtime.configure()
    main()
