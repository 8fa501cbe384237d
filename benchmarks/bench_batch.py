"""Batched reduced models against one call per log, honestly: three rounds, median and range.

The 8 forward tuning manoeuvres (constant steers at 200, 360 and 500 deg of
steering wheel, 5 and 10 km/h, 40 s at 100 Hz each), made by the STM itself,
run through the harness as one tuning objective evaluation does:

- ``batch``: :func:`validation.batch.run_batch`, numba's ``prange`` over the
  logs on every core;
- ``batch, 1 thread``: the same with numba limited to one thread, which
  separates the parallel gain from the batch's own work;
- ``kernel``: the ``prange`` call alone, without concatenating the inputs
  and splitting the outputs in Python;
- ``per log``: :func:`validation.harness.run_inputs`, one compiled call per log.

Each round times every variant once, in turn, after a warm-up that compiles;
a figure is the median (range) over the rounds of real time per manoeuvre
(simulated seconds of all manoeuvres / wall seconds), and of the ratio of
batch to per-log speed within the round.

Run: ``python benchmarks/run.py`` (or this file alone).
"""

from __future__ import annotations

import statistics
import time

import numba
import numpy as np

from mjcf import load_vehicle
from reduced import KinematicModel, SingleTrackModel
from validation.batch import batch_loop, run_batch
from validation.harness import loop_inputs, run_inputs
from validation.logs.runfile import Run
from validation.logs.schema import COLUMNS
from validation.simulate import simulate
from validation.steering import SteeringMap
from validation.synthetic.manoeuvres import make_profile

CELLS = [(200, 5), (500, 5), (360, 5), (360, 10)]
ROUNDS = 3
CALLS = 20
"""Calls per timing: one batch of KIN takes about a millisecond."""


def _wall(fn) -> float:
    t0 = time.perf_counter()
    for _ in range(CALLS):
        fn()
    return (time.perf_counter() - t0) / CALLS


def _kernel(cls, v, inputs):
    """The batch's prange call with its arguments prepared once."""
    probe = cls(v)
    X0 = []
    for inp in inputs:
        probe.reset(inp.initial)
        X0.append(probe.x.copy())
    kind, _, P, s1, s2 = probe.compiled()
    starts = np.concatenate([[0], np.cumsum([i.t.size for i in inputs])]).astype(np.int64)
    args = (kind, np.array(X0), P, s1, s2, starts,
            np.concatenate([np.append(np.diff(i.t), 0.0) for i in inputs]),
            *(np.concatenate([getattr(i, n) for i in inputs])
              for n in ("delta_c", "u1", "u1_dot", "gamma_meas", "reversing")),
            3.0, v.steering.delta_max, v.gamma_max)
    return lambda: batch_loop(*args)


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
            run = simulate(SingleTrackModel(v), v, p)
            logs.append(Run(run.frame[list(COLUMNS)], {"name": f"{amp}-{kph}-{side}"}))
    sim = sum(float(log.frame.t.iloc[-1]) for log in logs)
    threads = numba.get_num_threads()
    out: dict[str, list[float]] = {}
    for cls in (KinematicModel, SingleTrackModel):
        steering = SteeringMap.from_steering(v.steering_for(cls.name))
        inputs = [loop_inputs(log, v, steering) for log in logs]
        variants = {
            "batch": lambda cls=cls, inputs=inputs: run_batch(cls, v, inputs, 3.0),
            "kernel": _kernel(cls, v, inputs),
            "per log": lambda cls=cls, inputs=inputs: [run_inputs(cls(v), i, v, 3.0)
                                                       for i in inputs],
        }
        for fn in variants.values():
            fn()  # compiles, or loads numba's cache
        for _ in range(ROUNDS):
            walls = {k: _wall(fn) for k, fn in variants.items()}
            numba.set_num_threads(1)
            try:
                walls["batch, 1 thread"] = _wall(variants["batch"])
            finally:
                numba.set_num_threads(threads)
            for k, w in walls.items():
                out.setdefault(f"{cls.name} {k}", []).append(sim / w)
            out.setdefault(f"{cls.name} batch/per log", []).append(walls["per log"]
                                                                     / walls["batch"])
    print(f"The tuning set ({len(logs)} manoeuvres, {sim:.0f} s simulated), real time per "
          f"manoeuvre, median (range) of {ROUNDS} rounds, numba on {threads} threads:")
    for m in ("kin", "stm"):
        for k in ("batch", "batch, 1 thread", "kernel", "per log"):
            print(f"  {m.upper()} {k:16s} {_fmt(out[f'{m} {k}'])} x")
        r = out[f"{m} batch/per log"]
        print(f"  {m.upper()} batch speed / per-log speed: {statistics.median(r):.2f} "
              f"({min(r):.2f}-{max(r):.2f})")
    return out


if __name__ == "__main__":
    from validation import runtime

    runtime.configure()
    main()
