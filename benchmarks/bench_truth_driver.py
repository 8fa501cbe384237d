"""The truth's docking driver on every docking and parking manoeuvre of the test matrix.

For each seed, every docking and parking manoeuvre (17) is generated as the
campaign does (:func:`artic.validation.synthetic.generate.simulate_manoeuvre`),
and the truth's own record of it read: whether the driver docked, his
shuffles, the rear's lateral and heading errors at the face, the peak
articulation against the truck's ``gamma_max`` (jackknife), the drive's
length. ``docs/design/truth.md`` (*Its driver in docking and parking*) quotes
the figures for seeds 0-7.

Run: ``python benchmarks/bench_truth_driver.py [--seeds 0-7] [--jobs 2]``.
These are the driver's outcomes, not times: they do not depend on the machine.
"""

from __future__ import annotations

import argparse
import math
from concurrent.futures import ProcessPoolExecutor

import numpy as np


def drive(args: tuple[str, int]) -> dict:
    """One manoeuvre on one seed: the truth's record of the drive."""
    from artic.validation.synthetic.generate import simulate_manoeuvre
    from artic.validation.synthetic.testmatrix import MATRIX
    from artic.validation.synthetic.truth import slope, truth_configuration, truth_vehicle

    name, seed = args
    m = next(m for m in MATRIX if m.name == name)
    meta = simulate_manoeuvre(m, seed).meta
    truth = truth_configuration(seed)
    vt = truth_vehicle(m.load, truth, seed, slope(seed, m.index, truth))
    return {"kind": m.kind, "docked": bool(meta["docked"]), "shuffles": meta["shuffles"],
            "e_y": abs(meta["final_lateral_error"]),
            "e_psi": math.degrees(abs(meta["final_heading_error"])),
            "peak": math.degrees(meta["peak_articulation"]),
            "jackknife": meta["peak_articulation"] >= vt.gamma_max}


def _seeds(text: str) -> list[int]:
    lo, _, hi = text.partition("-")
    return list(range(int(lo), int(hi or lo) + 1))


def main(argv: list[str] | None = None) -> None:
    from artic.validation.synthetic.testmatrix import MATRIX

    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--seeds", default="0", help="a seed or a range, 0-7 (default: 0)")
    ap.add_argument("--jobs", type=int, default=1)
    a = ap.parse_args([] if argv is None else argv)
    tasks = [(m.name, s) for s in _seeds(a.seeds) for m in MATRIX
             if m.kind in ("docking", "parking")]
    with ProcessPoolExecutor(a.jobs) as ex:
        rows = list(ex.map(drive, tasks))
    print("| kind | drives | docked | jackknifed | without a shuffle | most shuffles | "
          "largest lateral error at the face [m] | largest heading error [deg] | "
          "peak articulation, median and largest [deg] |")
    print("|---|---|---|---|---|---|---|---|---|")
    for kind in ("docking", "parking"):
        r = [x for x in rows if x["kind"] == kind]
        peak = np.array([x["peak"] for x in r])
        print(f"| {kind} | {len(r)} | {sum(x['docked'] for x in r)} | "
              f"{sum(x['jackknife'] for x in r)} | {sum(x['shuffles'] == 0 for x in r)} | "
              f"{max(x['shuffles'] for x in r)} | {max(x['e_y'] for x in r):.2f} | "
              f"{max(x['e_psi'] for x in r):.1f} | {np.median(peak):.0f}, {peak.max():.0f} |")


if __name__ == "__main__":
    import sys

    main(sys.argv[1:])
