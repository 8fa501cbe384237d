"""The plant's convergence in its timestep, on every manoeuvre kind of the campaign.

Each manoeuvre kind of the synthetic campaign (constant steer, slalom,
figure-8, ramp steer in reverse, docking, parking), in both load conditions,
drives the plant through the validation harness (the log's steering and
speed, the reversing feedback at K = 3) at several timesteps, RK4. The
reference is plain RK4 at 1 ms (``Plant(spin_fit=False)``: the model's own
rates, nothing fitted to the step). For each other step the table gives the
largest difference over the run in:

- the semitrailer sensor's position [m] (``x_2``, ``y_2``);
- the articulation angle [deg];
- the yaw rates [rad/s] (``r_1``, ``r_2``, the larger).

The plant runs on the preset of the log's load condition and, for the
``six-axle`` preset, on the loaded logs. The targets (issue: a plant accurate
at the log's rate) are 1 cm, 0.05 deg and 1e-3 rad/s. The compared steps run
with the wheel-spin mode fitted to the step (the plant's default,
:mod:`artic.plant.spinmode`); ``--plain`` runs them without it too. The logs
are generated once into ``--out-dir`` (default ``benchmarks/.convergence``)
and reused.

Run: ``python benchmarks/bench_convergence.py [--steps 0.005,0.01] [--plain]
[--markdown] [--out-dir DIR]``. This measures accuracy, not time: the figures
do not depend on the machine.
"""

from __future__ import annotations

import argparse
import math
from pathlib import Path

import numpy as np

from artic.mjcf import load_vehicle
from artic.mjcf.builder import TIMESTEP
from artic.plant import Plant
from artic.validation.campaign.main import load_logs
from artic.validation.harness.loop import run_closed_loop
from artic.validation.synthetic.testmatrix import MATRIX

REFERENCE_STEP = 1e-3
TARGETS = {"pos_m": 0.01, "gamma_deg": 0.05, "r_rad_s": 1e-3}
HERE = Path(__file__).resolve().parent


def one_per_kind() -> list[str]:
    """The first manoeuvre of each (kind, load) cell of the test matrix."""
    seen, names = set(), []
    for m in MATRIX:
        if (m.kind, m.load) not in seen:
            seen.add((m.kind, m.load))
            names.append(m.name)
    return names


def largest_differences(run, ref) -> dict[str, float]:
    """Largest differences of ``run`` from ``ref`` over their common samples."""
    n = min(len(run.frame), len(ref.frame))
    a, b = run.frame.iloc[:n], ref.frame.iloc[:n]
    pos = np.hypot(a["x_2"].to_numpy() - b["x_2"].to_numpy(),
                   a["y_2"].to_numpy() - b["y_2"].to_numpy())
    dg = np.angle(np.exp(1j * (a["gamma"].to_numpy() - b["gamma"].to_numpy())))
    dr = np.maximum(np.abs(a["r_1"].to_numpy() - b["r_1"].to_numpy()),
                    np.abs(a["r_2"].to_numpy() - b["r_2"].to_numpy()))
    return {"pos_m": float(pos.max()), "gamma_deg": math.degrees(float(np.abs(dg).max())),
            "r_rad_s": float(dr.max())}


def met(d: dict[str, float]) -> bool:
    """Whether every difference is within its target."""
    return all(d[k] <= TARGETS[k] for k in TARGETS)


def main(argv: list[str] | None = None) -> None:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    steps_default = ",".join(f"{h:g}" for h in sorted({TIMESTEP, 0.005, 0.01}))
    ap.add_argument("--steps", default=steps_default,
                    help="comma-separated timesteps [s] to compare with 1 ms")
    ap.add_argument("--plain", action="store_true",
                    help="run each step without the spin mode's fit as well")
    ap.add_argument("--markdown", action="store_true", help="print the table as Markdown")
    ap.add_argument("--out-dir", type=Path, default=HERE / ".convergence")
    args = ap.parse_args(argv)
    steps = [float(s) for s in args.steps.split(",")]
    variants = [(h, True) for h in steps] + ([(h, False) for h in steps] if args.plain else [])
    logs = load_logs(args.out_dir, seed=0, jobs=2, only=one_per_kind())
    cases = [(log, f"gosar2022-{log.meta['load']}") for log in logs]
    cases += [(log, "six-axle") for log in logs if log.meta.get("load") == "loaded"]
    head = (f"largest differences from plain RK4 at {REFERENCE_STEP * 1e3:g} ms; targets "
            f"{TARGETS['pos_m'] * 100:g} cm, {TARGETS['gamma_deg']:g} deg, "
            f"{TARGETS['r_rad_s']:g} rad/s")
    names = [f"{h * 1e3:g} ms" + ("" if fit else " plain") for h, fit in variants]
    if args.markdown:  # one row per case, a cell per step: position, articulation, yaw rate
        print(head + "; each cell: position [m], articulation [deg], yaw rate [rad/s], "
              "**bold** where a target is missed\n")
        print("| manoeuvre | vehicle | " + " | ".join(names) + " |")
        print("|---|---|" + "---|" * len(names))
    else:
        print(head)
        print(f"{'manoeuvre':42s} {'vehicle':20s} {'step':>11s} {'pos [m]':>9s} "
              f"{'gamma [deg]':>11s} {'r [rad/s]':>10s}  met")
    worst = {v: dict.fromkeys(TARGETS, 0.0) for v in variants}
    for log, preset in cases:
        vehicle = load_vehicle(preset)
        with Plant(vehicle, timestep=REFERENCE_STEP, spin_fit=False) as p:
            ref = run_closed_loop(p, log, vehicle, extras=False)
        cells = []
        for (h, fit), step in zip(variants, names, strict=True):
            with Plant(vehicle, timestep=h, spin_fit=fit) as p:
                run = run_closed_loop(p, log, vehicle, extras=False)
            d = largest_differences(run, ref)
            for k in TARGETS:
                worst[(h, fit)][k] = max(worst[(h, fit)][k], d[k])
            if args.markdown:
                cells.append(", ".join(f"**{d[k]:.1e}**" if d[k] > TARGETS[k] else f"{d[k]:.1e}"
                                       for k in TARGETS))
            else:
                print(f"{log.name[:42]:42s} {preset:20s} {step:>11s} {d['pos_m']:9.2e} "
                      f"{d['gamma_deg']:11.2e} {d['r_rad_s']:10.2e}  "
                      f"{'yes' if met(d) else 'NO'}", flush=True)
        if args.markdown:
            print(f"| {log.name} | {preset} | " + " | ".join(cells) + " |", flush=True)
    print()
    for (h, fit), w in worst.items():
        print(f"worst at {h * 1e3:g} ms{'' if fit else ' plain'}: {w['pos_m']:.2e} m, "
              f"{w['gamma_deg']:.2e} deg, {w['r_rad_s']:.2e} rad/s: "
              f"{'meets' if met(w) else 'misses'} the targets")


if __name__ == "__main__":
    main()
