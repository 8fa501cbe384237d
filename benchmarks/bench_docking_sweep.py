"""A docking robustness sweep of 1 000 runs on this machine's cores: the wall time.

The issue's target: a sweep of at least 1 000 runs finishes in at most 10
minutes on two cores without recordings. The sweep is the reference
controller over five road frictions (dry 1.0 to packed snow 0.3), the four
scenarios and 50 seeded starts on ``gosar2022-unloaded``:

    artic dock --sweep friction=1.0,0.8,0.6,0.45,0.3 --scenario all
        --vehicle gosar2022-unloaded --seeds 50 --no-recordings --jobs CORES

run through the command itself (the runs, the per-run files, ``sweep.csv``,
the paired comparisons, ``sweep.md`` and ``sweep.png``), each round into a
fresh folder. The figure is the wall time, the median and range of three
rounds, against the 10 minute target; it is absolute, so time it on an
otherwise quiet machine. Before the rounds, one run of each scenario warms
numba's cache.

Run: ``python benchmarks/run.py`` (or this file alone; ``--small`` runs two
levels, one scenario and two seeds once, to check that it works).
"""

from __future__ import annotations

import contextlib
import io
import os
import statistics
import sys
import tempfile
import time
from pathlib import Path

TARGET = 600.0
"""The issue's bound on a 1 000-run sweep on two cores [s]."""

ROUNDS = 3
FULL = ("friction=1.0,0.8,0.6,0.45,0.3", "all", 50)
SMALL = ("friction=1.0,0.3", "straight", 2)


def _cores() -> int:
    try:
        return len(os.sched_getaffinity(0)) or 1
    except AttributeError:  # pragma: no cover - not Linux
        return os.cpu_count() or 1


def _sweep(out: Path, sweep: str, scenarios: str, seeds: int, jobs: int) -> float:
    """Wall time of one ``artic dock --sweep`` into ``out`` [s]."""
    from artic.validation.cli.commands import main as artic

    args = ["dock", "--sweep", sweep, "--scenario", scenarios, "--vehicle",
            "gosar2022-unloaded", "--seeds", str(seeds), "--no-recordings", "--jobs", str(jobs),
            "--out-dir", str(out)]
    t0 = time.perf_counter()
    with contextlib.redirect_stdout(io.StringIO()), contextlib.redirect_stderr(io.StringIO()):
        code = artic(args)
    wall = time.perf_counter() - t0
    if code != 0:
        raise RuntimeError(f"artic {' '.join(args)} exited with {code}")
    return wall


def main(small: bool = False) -> dict[str, list[float]]:
    import pandas as pd

    sweep, scenarios, seeds = SMALL if small else FULL
    levels = len(sweep.split("=", 1)[1].split(","))
    n_scen = 4 if scenarios == "all" else len(scenarios.split(","))
    runs = levels * n_scen * seeds
    jobs = _cores()
    rounds = 1 if small else ROUNDS
    walls = []
    with tempfile.TemporaryDirectory() as tmp:
        _sweep(Path(tmp) / "warm", "friction=1.0", scenarios, 1, jobs)  # numba's cache
        for k in range(rounds):
            out = Path(tmp) / f"round{k}"
            walls.append(_sweep(out, sweep, scenarios, seeds, jobs))
            docked = int(pd.read_csv(out / "sweep_runs.csv")["success"].sum())
    med = statistics.median(walls)
    print(f"Docking sweep of {runs} runs ({sweep}, {scenarios}, {seeds} seeds, reference "
          f"controller, no recordings) on {jobs} core{'s' if jobs > 1 else ''}: "
          f"{med:.0f} s median ({min(walls):.0f}-{max(walls):.0f} s) of {rounds} round"
          f"{'s' if rounds > 1 else ''}, {med / runs:.2f} s per run; {docked} of {runs} "
          f"docked in the last")
    if not small:
        print(f"  target: at most {TARGET:.0f} s on two cores: "
              + ("met" if med <= TARGET else "NOT met"))
    return {"wall_s": walls}


if __name__ == "__main__":
    from artic.validation.plumbing import runtime

    runtime.configure()
    main(small="--small" in sys.argv[1:])
