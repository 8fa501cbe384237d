"""The docking MPC's solve on one core: per solve, designed on KIN and on the STM.

The issue's budget is absolute, a 99th-percentile solve of at most 20 ms at
10 Hz on one core, so these figures are times, not ratios: run them on an
otherwise quiet machine. The script pins itself to one core (the first this
process may use) for the timing and restores its affinity after; for the
strictest figure run it alone under ``taskset -c 0``.

A solve is one reversing sample of the MPC (``MPC._mpc``): the state
estimate, the prediction and its sensitivities on the design model, the
condensed QP and its solution by qpOASES; the forward stretches, the stops
and the cusps are the reference controller's and are not counted. Each
round drives the same docking runs on the plant (the straight and the
alley dock of ``gosar2022-unloaded``, two starts each) with each design
and pools their solves; the figures are the median, 99th percentile and
largest solve [ms], each given as the median and range of three rounds.

Run: ``python benchmarks/run.py`` (or this file alone). Needs ``artic[mpc]``.
"""

from __future__ import annotations

import importlib.util
import statistics

import numpy as np

from _timing import one_core, timed_method

ROUNDS = 3
VEHICLE = "gosar2022-unloaded"
RUNS = (("straight", 0), ("straight", 1), ("alley", 0), ("alley", 1))


def _round(base: type) -> np.ndarray:
    """Every solve of one round's runs [ms]."""
    from artic.validation.docking.run import drive
    from artic.validation.docking.scenarios import scenario

    cls, times = timed_method(base, "_mpc")
    for name, seed in RUNS:
        row = drive(scenario(name), VEHICLE, cls, seed).row
        if not row["success"]:
            print(f"  ({name} seed {seed}: {row['failure']})")
    return np.array(times)


def _fmt(xs: list[float]) -> str:
    return f"{statistics.median(xs):.2g} ({min(xs):.2g}-{max(xs):.2g})"


def main() -> dict[str, dict[str, list[float]]] | None:
    if importlib.util.find_spec("casadi") is None:
        print("skipped: the docking MPC needs CasADi (pip install -e '.[mpc]')")
        return None
    from artic.validation.docking.controllers.mpc import MPCKin, MPCStm

    designs = {"KIN": MPCKin, "STM": MPCStm}
    fig: dict[str, dict[str, list[float]]] = {
        d: {"solves": [], "p50": [], "p99": [], "max": []} for d in designs}
    with one_core() as core:
        _round(MPCKin)  # warm-up: numba's cache, the plant's library, CasADi's plugin
        for _ in range(ROUNDS):
            for d, base in designs.items():
                t = _round(base)
                fig[d]["solves"].append(float(t.size))
                for key, q in (("p50", 50), ("p99", 99), ("max", 100)):
                    fig[d][key].append(float(np.percentile(t, q)))
    where = f"core {core}" if core is not None else "no affinity control"
    print(f"Docking MPC solve per reversing sample, {VEHICLE}, {len(RUNS)} runs per round on "
          f"the plant, {where}; median (range) of {ROUNDS} rounds, in ms:")
    for d in designs:
        f = fig[d]
        print(f"  designed on {d}: {int(statistics.median(f['solves']))} solves a round; "
              f"median {_fmt(f['p50'])}, 99th percentile {_fmt(f['p99'])}, "
              f"largest {_fmt(f['max'])}")
    print("  (the issue's budget: 99th percentile at most 20 ms at 10 Hz on one core)")
    return fig


if __name__ == "__main__":
    from artic.validation.plumbing import runtime

    runtime.configure()
    main()
