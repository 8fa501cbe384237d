"""The synthetic truth's convergence in its timestep, on every manoeuvre kind of the campaign.

The independent truth (:class:`artic.validation.synthetic.truthplant.TruthPlant`)
runs twice in a campaign: its driver makes each log (generation), and the
harness replays each log on it (the floor, ``truth_model(..., speed="follow")``).
This study does both at several timesteps, RK4, for the first manoeuvre of
each kind and load condition of the test matrix (constant steer, slalom,
figure-8, ramp steer in reverse, docking, parking), and compares them with
the same at 1 ms:

- **generation**: :func:`artic.validation.synthetic.generate.simulate_manoeuvre`
  with ideal sensors (the truth's own motion), seed 0;
- **floor**: the 1 ms log of the generation replayed through the harness
  (the log's steering and speed, the reversing feedback at K = 3), as the
  campaign's references stage replays each log on its truth.

The differences (:func:`bench_convergence.largest_differences`: the
semitrailer sensor's position, the articulation, the yaw rates) and the
targets are the plant's study's (``bench_convergence.py``): 1 cm, 0.05 deg,
1e-3 rad/s. The summary gives the worst of the forward kinds
(:data:`artic.validation.synthetic.truthplant.FORWARD_KINDS`, which the truth
steps at :data:`~artic.validation.synthetic.truthplant.FORWARD_TIMESTEP`) and
of the reversing ones apart. A generation whose driver ends on another sample than at 1 ms
(``n`` differs) made a discrete decision (stop, shuffle, end) a sample
earlier or later; its differences are those of the decision, which the
column ``n`` flags. The truth exists for the gosar2022 presets only, so there
is no six-axle case.

Run: ``python benchmarks/bench_truth_convergence.py [--steps 0.005,0.01]
[--all] [--markdown]``. This measures accuracy, not time: the figures do not
depend on the machine.
"""

from __future__ import annotations

import argparse

from artic.validation.harness.loop import run_closed_loop
from artic.validation.synthetic.generate import simulate_manoeuvre
from artic.validation.synthetic.sensors import SensorModel
from artic.validation.synthetic.testmatrix import MATRIX
from artic.validation.synthetic.truth import truth_configuration, truth_vehicle
from artic.validation.synthetic.truthplant import (
    FORWARD_KINDS,
    FORWARD_TIMESTEP,
    TIMESTEP,
    truth_model,
)
from bench_convergence import REFERENCE_STEP, TARGETS, largest_differences, met, one_per_kind

SEED = 0


def generation(m, h: float):
    """The truth's driver on manoeuvre ``m`` at step ``h`` [s], measured ideally."""
    return simulate_manoeuvre(m, SEED, SensorModel.ideal(), timestep=h)


def floor(log, h: float):
    """``log`` replayed through the harness on the truth that made it, at step ``h`` [s]."""
    truth = truth_configuration(SEED, "independent")
    vt = truth_vehicle(log.meta["load"], truth, SEED, log.meta.get("slope"))
    with truth_model(vt, truth, "follow", h) as p:
        return run_closed_loop(p, log, vt, extras=False)


def cell(d: dict[str, float], markdown: bool) -> str:
    """Position, articulation and yaw rate of one comparison, flagged where missed."""
    if markdown:
        return ", ".join(f"**{d[k]:.1e}**" if d[k] > TARGETS[k] else f"{d[k]:.1e}"
                         for k in TARGETS)
    return " ".join(f"{d[k]:9.2e}" for k in TARGETS) + ("" if met(d) else "  NO")


def main(argv: list[str] | None = None) -> None:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    default = ",".join(f"{h:g}" for h in sorted({TIMESTEP, FORWARD_TIMESTEP, 0.005, 0.01}))
    ap.add_argument("--steps", default=default,
                    help="comma-separated timesteps [s] to compare with 1 ms")
    ap.add_argument("--all", action="store_true", help="every manoeuvre of the test matrix")
    ap.add_argument("--only", default="", help="comma-separated manoeuvre names")
    ap.add_argument("--markdown", action="store_true", help="print the table as Markdown")
    args = ap.parse_args(argv)
    steps = [float(s) for s in args.steps.split(",")]
    names = (args.only.split(",") if args.only else
             [m.name for m in MATRIX] if args.all else one_per_kind())
    cols = [f"{w} {h * 1e3:g} ms" for h in steps for w in ("generation", "floor")]
    print(f"largest differences from the truth at {REFERENCE_STEP * 1e3:g} ms; targets "
          f"{TARGETS['pos_m'] * 100:g} cm, {TARGETS['gamma_deg']:g} deg, "
          f"{TARGETS['r_rad_s']:g} rad/s; each cell: position [m], articulation [deg], "
          "yaw rate [rad/s]" + (", **bold** where a target is missed\n" if args.markdown
                                else ""))
    if args.markdown:
        print("| manoeuvre | " + " | ".join(cols) + " | n |")
        print("|---|" + "---|" * len(cols) + "---|")
    groups = ("forward", "reversing")
    worst = {(c, g): dict.fromkeys(TARGETS, 0.0) for c in cols for g in groups}
    for name in names:
        m = next(x for x in MATRIX if x.name == name)
        group = groups[m.kind not in FORWARD_KINDS]
        ref = generation(m, REFERENCE_STEP)
        ref_floor = floor(ref, REFERENCE_STEP)
        cells, lengths = [], []
        for h in steps:
            run = generation(m, h)
            lengths.append(len(run.frame))
            for c, d in ((f"generation {h * 1e3:g} ms", largest_differences(run, ref)),
                         (f"floor {h * 1e3:g} ms", largest_differences(floor(ref, h),
                                                                        ref_floor))):
                w = worst[(c, group)]
                worst[(c, group)] = {k: max(w[k], d[k]) for k in TARGETS}
                cells.append(cell(d, args.markdown))
        n = ", ".join(str(k) for k in lengths) + f" / {len(ref.frame)}"
        if args.markdown:
            print(f"| {name} | " + " | ".join(cells) + f" | {n} |", flush=True)
        else:
            for c, text in zip(cols, cells, strict=True):
                print(f"{name[:44]:44s} {c:20s} {text}", flush=True)
            print(f"{'':44s} samples at each step / at 1 ms: {n}", flush=True)
    print()
    for (c, g), w in worst.items():
        print(f"worst {c}, {g} kinds: {w['pos_m']:.2e} m, {w['gamma_deg']:.2e} deg, "
              f"{w['r_rad_s']:.2e} rad/s: {'meets' if met(w) else 'misses'} the targets")


if __name__ == "__main__":
    main()
