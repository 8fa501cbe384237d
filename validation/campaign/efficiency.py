"""Computational efficiency: wall time per simulated second of each model.

The paper reports its kinematic model 90 % and its single-track model 60 %
faster than its multibody model, that is wall-time ratios KIN/MBD = 0.1 and
STM/MBD = 0.4. Here every model runs the same logs through the same harness,
one after the other in one process with nothing else running, so the ratios
come from one run on one machine. The plant runs without recording its
extra outputs for the drawings (:meth:`plant.Plant.extras`). Model
construction (the plant compiles its MJCF) is timed apart from stepping.
"""

from __future__ import annotations

import time
from collections.abc import Callable, Sequence

import pandas as pd

from artic.mjcf.vehicle import Vehicle
from artic.validation.cli.progress import Counter
from artic.validation.harness.loop import run_closed_loop
from artic.validation.logs.runfile import Run
from artic.validation.models import build as build_model

PAPER_RATIO = {"kin": 0.1, "stm": 0.4, "mbd": 1.0}
"""Wall-time ratio to the multibody model reported by the paper (90 % and 60 % faster)."""


def measure(logs: Sequence[tuple[Vehicle, Run]], models: Sequence[str],
            repeat: int = 1, progress: Callable[[str], None] | None = None) -> pd.DataFrame:
    """Time each model on the logs.

    Parameters
    ----------
    logs : sequence of (Vehicle, Run)
        Logs with the vehicle to run them with.
    models : sequence of str
        Models to time.
    repeat : int
        Passes over the logs; the fastest pass counts (the usual guard against
        a busy machine).
    progress : callable, optional
        Receives progress lines with counts and the time left.

    Returns
    -------
    DataFrame
        Per model: ``simulated_s``, ``build_s`` (construction, per run),
        ``wall_s`` (stepping), ``wall_per_sim_s``, ``real_time_factor``, and
        ``ratio_to_mbd`` with the paper's ``paper_ratio`` beside it.
    """
    from artic.validation.harness.plantnotes import collect

    rows = []
    counter = Counter(len(models) * repeat * len(logs), "efficiency", progress)
    for name in models:
        best = None
        for _ in range(repeat):
            build = wall = sim = 0.0
            for vehicle, log in logs:
                t0 = time.perf_counter()
                model = build_model(name, vehicle)
                t1 = time.perf_counter()
                try:
                    # What the plant limits here, validation has already reported.
                    with collect():
                        run = run_closed_loop(model, log, vehicle, extras=False)
                finally:
                    model.close()
                t2 = time.perf_counter()
                counter.step(f"{name} on {log.name}")
                build += t1 - t0
                wall += t2 - t1
                sim += float(run.frame["t"].iloc[-1] - run.frame["t"].iloc[0])
            if best is None or wall < best[1]:
                best = (build, wall, sim)
        build, wall, sim = best
        rows.append({"model": name, "simulated_s": sim, "build_s": build / len(logs),
                     "wall_s": wall, "wall_per_sim_s": wall / sim,
                     "real_time_factor": sim / wall})
    out = pd.DataFrame(rows).set_index("model")
    if "mbd" in out.index:
        out["ratio_to_mbd"] = out["wall_per_sim_s"] / out.loc["mbd", "wall_per_sim_s"]
        out["paper_ratio"] = [PAPER_RATIO.get(m, float("nan")) for m in out.index]
    return out
