"""The speed issue's end-to-end figures: each command three times, median and range.

Each command runs as a user runs it (the ``artic`` console script beside this
Python, a fresh process, start-up included) into a fresh temporary folder,
on all cores:

- ``artic --help``: the start-up (the target is 0.3 s: no MuJoCo, numba, Rerun,
  pandas or scipy loaded, ``tests/test_startup.py``);
- ``artic campaign --out-dir DIR``: the main job from nothing, with the stages
  of the median run (from its ``report.md``);
- ``artic campaign --seeds 3 --out-dir DIR``: three trucks;
- ``artic dock --out-dir DIR``: the docking benchmark's default run;
- ``artic simulate --model mbd --manoeuvre constant-steer --duration 600``:
  the plant open loop on one core, as a real-time factor.

Run: ``python benchmarks/bench_commands.py [--runs N] [--only campaign,seeds,dock,simulate]``
(about 17 minutes on two cores with three runs). Time a quiet machine: the
figures are wall times.
"""

from __future__ import annotations

import argparse
import statistics
import subprocess
import sys
import tempfile
import time
from pathlib import Path

from bench_campaign import _stages

ARTIC = str(Path(sys.executable).with_name("artic"))
SIM_SECONDS = 600.0
COMMANDS = {
    "help": ["--help"],
    "campaign": ["campaign", "--out-dir", "{out}"],
    "seeds": ["campaign", "--seeds", "3", "--out-dir", "{out}"],
    "dock": ["dock", "--out-dir", "{out}"],
    "simulate": ["simulate", "--model", "mbd", "--manoeuvre", "constant-steer", "--duration",
                 f"{SIM_SECONDS:g}", "--out", "{out}/run.parquet"],
}


def _run(args: list[str]) -> tuple[float, dict[str, float]]:
    """One run in a fresh folder: wall time [s] and, for a campaign, its stages [s]."""
    with tempfile.TemporaryDirectory() as tmp:
        out = Path(tmp) / "out"
        out.mkdir()
        cmd = [ARTIC, *(a.format(out=out) for a in args)]
        t0 = time.perf_counter()
        subprocess.run(cmd, check=True, stdout=subprocess.DEVNULL, stderr=subprocess.DEVNULL)
        wall = time.perf_counter() - t0
        report = out / "report.md"
        return wall, (_stages(report) if args[0] == "campaign" and report.is_file() else {})


def main(runs: int = 3, only: tuple[str, ...] = tuple(COMMANDS)) -> dict[str, float]:
    """Time each command ``runs`` times; print and return the medians [s]."""
    out = {}
    for name in only:
        results = [_run(COMMANDS[name]) for _ in range(runs)]
        walls = [w for w, _ in results]
        med = statistics.median(walls)
        line = (f"{name:<9} {med:6.2f} s ({min(walls):.2f}-{max(walls):.2f} s, {runs} runs)"
                if med < 10 else
                f"{name:<9} {med:6.1f} s ({min(walls):.1f}-{max(walls):.1f} s, {runs} runs)")
        if name == "simulate":
            line += f": {SIM_SECONDS / med:.0f}x real time end to end"
        stages = results[walls.index(sorted(walls)[(runs - 1) // 2])][1]
        if stages:
            line += "; median run: " + ", ".join(f"{k} {v:.0f} s" for k, v in stages.items()
                                                 if k != "total" and v >= 0.5)
        print(line, flush=True)
        out[name] = med
    return out


if __name__ == "__main__":
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--runs", type=int, default=3)
    parser.add_argument("--only", default=",".join(COMMANDS),
                        help="comma-separated: " + ", ".join(COMMANDS))
    a = parser.parse_args()
    main(a.runs, tuple(a.only.split(",")))
