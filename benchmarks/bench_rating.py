"""ISO/TS 18571's rating of a run: CPU per (log, model) pair, by run length.

The campaign rates five signals of every (log, model) pair
(:mod:`artic.validation.criteria.rating`) at 10 Hz; the magnitude score's time
warping costs the square of the samples. Timed: :func:`gaps` on a 30 s, a
60 s and a 200 s run (a constant steer, a ramp steer, a long docking drive) at
100 Hz whose signals swing with a 10 s period, the model 10 % off. Printed:
the best of a few process-CPU times after a warm-up that compiles.

Run: ``python benchmarks/run.py`` (or this file alone).
"""

from __future__ import annotations

import math
import time

import numpy as np
import pandas as pd

from artic.validation.criteria.rating import gaps
from artic.validation.logs.runfile import Run

COLUMNS = ("r_1", "r_2", "v_y_1", "v_y_2", "gamma")


def _pair(seconds: float) -> tuple[Run, Run]:
    t = np.arange(int(seconds * 100) + 1) * 0.01
    rng = np.random.default_rng(0)
    log = pd.DataFrame({"t": t} | {c: 0.1 * np.sin(2 * math.pi * t / 10.0 - k)
                                   + rng.normal(0.0, 0.002, t.size)
                                   for k, c in enumerate(COLUMNS)})
    model = log.copy()
    model[list(COLUMNS)] *= 1.1
    return Run(log, {"name": "log"}), Run(model, {"name": "run"})


def main() -> dict[str, float]:
    out = {}
    for seconds in (30.0, 60.0, 200.0):
        log, run = _pair(seconds)
        gaps(log, run)  # compiles the warping once
        best = math.inf
        for _ in range(5):
            c0 = time.process_time()
            gaps(log, run)
            best = min(best, time.process_time() - c0)
        out[f"{seconds:g} s"] = best
        print(f"  rating a {seconds:g} s run (5 signals at 10 Hz): {1e3 * best:.1f} ms CPU")
    return out


if __name__ == "__main__":
    main()
