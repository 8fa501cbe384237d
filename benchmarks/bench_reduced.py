"""Real-time factor of KIN and STM through the closed-loop harness.

A 60 s manoeuvre at 100 Hz (6000 samples): a slalom forward and an
articulation-tracking reverse run, each driven through the harness as in
validation. Real-time factor = simulated time / wall time, best of several
repeats after one warm-up (which includes compilation).

Also times the orthogonal path distance: 10 000 model points against a
10 000-sample measured path.

Run: ``python benchmarks/run.py`` (or this file alone).
"""

from __future__ import annotations

import math

import numpy as np

from _timing import REPEATS, best_wall
from artic.mjcf import load_vehicle
from artic.reduced import KIN, STM
from artic.validation.criteria.pathdist import distance_to_polyline
from artic.validation.harness.loop import run_closed_loop
from artic.validation.harness.simulate import drive_articulation, simulate
from artic.validation.logs.runfile import Run
from artic.validation.logs.schema import COLUMNS
from artic.validation.synthetic.manoeuvres import make_profile


def _logs(v):
    s = v.steering_for("stm")
    prof = make_profile("slalom", amplitude_deg=200, speed_kph=5, duration=60.0,
                        delta_h_offset=s.delta_h_offset, L1=v.L1, i_s=s.i_s)
    fwd = simulate(STM(v), v, prof)
    t = np.arange(0.0, 60.0, 0.01)
    rev = drive_articulation(STM(v), v, t, np.full_like(t, -3 / 3.6),
                             math.radians(30) * np.clip(t / 30, 0, 1),
                             steering=s)
    return [Run(r.frame[list(COLUMNS)], {"name": n}) for r, n in ((fwd, "fwd"), (rev, "rev"))]


def main() -> dict[str, float]:
    v = load_vehicle("gosar2022-unloaded")
    logs = _logs(v)
    out = {}
    for log in logs:
        sim_time = float(log.frame.t.iloc[-1])
        for cls in (KIN, STM):
            wall = best_wall(lambda cls=cls, log=log: run_closed_loop(cls(v), log, v))
            out[f"{cls.name}_{log.name}_rtf"] = sim_time / wall
    out["stm_over_kin_cost"] = out["kin_fwd_rtf"] / out["stm_fwd_rtf"]
    rng = np.random.default_rng(0)
    path = np.cumsum(rng.normal(0, 0.02, (10_000, 2)), axis=0)
    pts = path + rng.normal(0, 0.5, path.shape)
    out["pathdist_10k_s"] = best_wall(lambda: distance_to_polyline(pts, path))
    print("Reduced models through the closed-loop harness (60 s at 100 Hz, best of "
          f"{REPEATS}):")
    for log in ("fwd", "rev"):
        for m in ("kin", "stm"):
            print(f"  {m.upper()} {log}: {out[f'{m}_{log}_rtf']:8.0f} x real time")
    print(f"  STM step cost / KIN step cost: {out['stm_over_kin_cost']:.2f}")
    print(f"Path distance, 10 000 points to a 10 000-vertex path: "
          f"{out['pathdist_10k_s'] * 1e3:.1f} ms")
    return out


if __name__ == "__main__":
    main()
