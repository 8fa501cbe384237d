"""The docking MPPI's compute on one core: per reversing sample, designed on KIN and on the STM.

The budget is absolute, the 0.1 s sample on one core (the issue: MPPI's 99th
percentile below it), so these figures are times, not ratios: run them on an
otherwise quiet machine. The script pins itself to one core (the first this
process may use) for the timing and restores its affinity after; for the
strictest figure run it alone under ``taskset -c 0``.

A sample is one reversing command of MPPI (``MPPI._mppi``): the state
estimate, the batched rollout of every sampled steering sequence on the
design model (1 024 on KIN, 256 on the STM), their costs (tracking, steering,
collisions, articulation) and the weighted average; the forward stretches,
the stops and the cusps are the reference controller's and are not counted.
Each round drives the same docking runs on the plant (the straight and the
alley dock of ``gosar2022-unloaded``, one start each) with each design and
pools their samples; the figures are the median, 99th percentile and
largest [ms], each given as the median and range of three rounds.

Run: ``python benchmarks/run.py`` (or this file alone).
"""

from __future__ import annotations

import statistics

import numpy as np

from _timing import one_core, timed_method

ROUNDS = 3
VEHICLE = "gosar2022-unloaded"
RUNS = (("straight", 0), ("alley", 0))


def _round(base: type) -> np.ndarray:
    """Every reversing sample of one round's runs [ms]."""
    from artic.validation.docking.run import drive
    from artic.validation.docking.scenarios import scenario

    cls, times = timed_method(base, "_mppi")
    for name, seed in RUNS:
        row = drive(scenario(name), VEHICLE, cls, seed, realtime=False).row
        if not row["success"]:
            print(f"  ({name} seed {seed}: {row['failure']})")
    return np.array(times)


def _fmt(xs: list[float]) -> str:
    return f"{statistics.median(xs):.2g} ({min(xs):.2g}-{max(xs):.2g})"


def main() -> dict[str, dict[str, list[float]]]:
    from artic.validation.docking.controllers.mppi import MPPIKin, MPPIStm

    designs = {"KIN": MPPIKin, "STM": MPPIStm}
    fig: dict[str, dict[str, list[float]]] = {
        d: {"samples": [], "p50": [], "p99": [], "max": []} for d in designs}
    with one_core() as core:
        _round(MPPIStm)  # warm-up: numba's cache, the plant's library
        for _ in range(ROUNDS):
            for d, base in designs.items():
                t = _round(base)
                fig[d]["samples"].append(float(t.size))
                for key, q in (("p50", 50), ("p99", 99), ("max", 100)):
                    fig[d][key].append(float(np.percentile(t, q)))
    where = f"core {core}" if core is not None else "no affinity control"
    print(f"Docking MPPI compute per reversing sample, {VEHICLE}, {len(RUNS)} runs per round "
          f"on the plant, {where}; median (range) of {ROUNDS} rounds, in ms:")
    for d in designs:
        f = fig[d]
        print(f"  designed on {d}: {int(statistics.median(f['samples']))} samples a round; "
              f"median {_fmt(f['p50'])}, 99th percentile {_fmt(f['p99'])}, "
              f"largest {_fmt(f['max'])}")
    print("  (the budget: 99th percentile below the 100 ms sample on one core)")
    return fig


if __name__ == "__main__":
    from artic.validation.plumbing import runtime

    runtime.configure()
    main()
