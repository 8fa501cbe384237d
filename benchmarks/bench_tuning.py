"""Plant tuning per load condition: the campaign's fit against full differences, three rounds.

The campaign's 8 tuning manoeuvres (constant steers, 4 per load condition)
are generated from the structural truth into a temporary folder, as
``artic campaign`` makes them, with the STM tuned first for its start values.
Then per load condition and round, both fits of the plant, on 2 threads:

- ``campaign``: :func:`artic.validation.campaign.tuning.tune_model`, as the
  campaign runs it: the STM's steering ratio and offset as start, one
  forward-difference Jacobian with its columns at once on the thread pool,
  Broyden's updates, ``TOLERANCES["plant"]``;
- ``full differences``: ``least_squares``' own two-point differences at every
  step, from the nominal values, with KIN's and STM's tolerances, one
  evaluation after another (its four runs on the two threads): the plant's
  fit before the speed work, on today's plant and thread pool.

A figure is the median (range) over the rounds of the wall-time ratio
campaign / full differences, measured within the round, with the evaluation
counts and the largest parameter differences between the two fits. The
plant's own step got cheaper too (``bench_closedloop``), and the runs of one
evaluation went on threads; this ratio is the fitting algorithm's share alone.

Run: ``python benchmarks/run.py`` (or this file alone; about 6 minutes).
"""

from __future__ import annotations

import statistics
import tempfile
import time
from pathlib import Path

from artic.mjcf import load_vehicle
from artic.validation.campaign.main import PRESET, load_logs, start_from
from artic.validation.campaign.tuning import Objective, full_difference_fit, tune_model
from artic.validation.synthetic.testmatrix import TUNING

ROUNDS = 3
LOADS = ("unloaded", "loaded")


def _full_differences(vehicle, logs) -> tuple[dict[str, float], int, float]:
    t0 = time.perf_counter()
    obj = Objective("mbd", vehicle, logs, jobs=2)
    fitted, _ = full_difference_fit(obj)
    return fitted, obj.evaluations, time.perf_counter() - t0


def main() -> dict[str, list[float]]:
    out: dict[str, list[float]] = {}
    with tempfile.TemporaryDirectory() as tmp:
        logs = load_logs(Path(tmp), seed=0, jobs=2, only=list(TUNING))
        for load in LOADS:
            vehicle = load_vehicle(PRESET.format(load=load))
            tuning = [log for log in logs if log.meta.get("load") == load]
            stm = tune_model("stm", vehicle, tuning, jobs=2)
            start = start_from("mbd", {"stm": stm.fitted})
            for _ in range(ROUNDS):
                fit = tune_model("mbd", vehicle, tuning, jobs=2, start=start)
                ref, n_ref, wall_ref = _full_differences(vehicle, tuning)
                out.setdefault(f"{load} ratio", []).append(fit.wall_s / wall_ref)
                out.setdefault(f"{load} campaign s", []).append(fit.wall_s)
                out.setdefault(f"{load} full s", []).append(wall_ref)
                out.setdefault(f"{load} evaluations", []).append(fit.evaluations)
                out.setdefault(f"{load} full evaluations", []).append(n_ref)
                out.setdefault(f"{load} d_i_s rel", []).append(
                    abs(fit.fitted["i_s"] / ref["i_s"] - 1.0))
                out.setdefault(f"{load} d_offset rad", []).append(
                    abs(fit.fitted["delta_h_offset"] - ref["delta_h_offset"]))
                out.setdefault(f"{load} d_q", []).append(abs(fit.fitted["q"] - ref["q"]))

    def fmt(xs, f="{:.2f}") -> str:
        return f"{f.format(statistics.median(xs))} ({f.format(min(xs))}-{f.format(max(xs))})"

    print(f"Plant tuning per load condition, 4 manoeuvres of 40 s, 2 threads, median (range) "
          f"of {ROUNDS} rounds:")
    for load in LOADS:
        print(f"  {load}: campaign fit {fmt(out[f'{load} campaign s'], '{:.1f}')} s, "
              f"{fmt(out[f'{load} evaluations'], '{:.0f}')} evaluations; full differences "
              f"{fmt(out[f'{load} full s'], '{:.1f}')} s, "
              f"{fmt(out[f'{load} full evaluations'], '{:.0f}')} evaluations")
        print(f"    campaign / full differences, wall: {fmt(out[f'{load} ratio'])}")
        print(f"    largest differences of the fits: i_s {max(out[f'{load} d_i_s rel']):.1e} "
              f"relative, offset {max(out[f'{load} d_offset rad']):.1e} rad, "
              f"q {max(out[f'{load} d_q']):.1e} /rad")
    return out


if __name__ == "__main__":
    from artic.validation.plumbing import runtime

    runtime.configure()
    main()
