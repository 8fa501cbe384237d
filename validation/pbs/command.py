"""``artic pbs``: the low-speed performance measures of a vehicle on every model and the truth.

Runs the PBS low-speed turn, the FHWA turn and J695's steady circle
(:mod:`artic.validation.pbs.run`) on KIN, the STM, the plant and the
synthetic campaign's truth, and writes into ``--out-dir``: the tables
(``pbs.csv``, ``pbs.md``: each measure per model with the truth's value and,
for the truth and the plant, the PBS level it meets), the figure
(``swept-path.png``) and a Rerun recording of the PBS turn (``pbs-turn.rrd``;
``--no-recording`` leaves it out).
"""

from __future__ import annotations

import argparse
import time
from pathlib import Path

from artic.mjcf.errors import UserError

DEFAULT_MODELS = "kin,stm,mbd,truth"


def add_options(p) -> None:
    """Add ``artic pbs``'s options to its subparser ``p``.

    The subparser comes from :func:`artic.validation.cli.toplevel.parser`.
    """
    from artic.validation.plumbing import options

    p.add_argument("--vehicle", default="gosar2022-loaded",
                   help="preset or vehicle file (default: %(default)s)")
    p.add_argument("--out-dir", type=options.output_path, required=True, help="output folder")
    p.add_argument("--models", default=DEFAULT_MODELS,
                   help="comma-separated, of kin, stm, mbd, truth (default: %(default)s; "
                        "truth for the gosar2022 presets only)")
    p.add_argument("--seed", type=options.number(0, 2**31 - 1, integer=True), default=0,
                   help="the synthetic truth's seed (default: %(default)s)")
    p.add_argument("--no-recording", action="store_true", help="write no Rerun recording")
    p.set_defaults(func=run)


def _models(text: str, vehicle) -> list[str]:
    from artic.validation.pbs.run import MODELS, TRUTH_LOADS

    names = [n.strip() for n in text.split(",") if n.strip()]
    bad = [n for n in names if n not in MODELS]
    if bad or not names:
        raise UserError(f"--models {text!r}: expected a comma-separated list of "
                        f"{', '.join(MODELS)}")
    if "truth" in names and vehicle.name not in TRUTH_LOADS and text == DEFAULT_MODELS:
        names.remove("truth")  # the default asks for the truth only where there is one
    return names


def _record(out: Path, runs, vehicle) -> Path:
    from artic.validation.logs.runfile import Run, new_frame
    from artic.validation.review.recording import record_manoeuvre

    n = min(len(r.drives["pbs"][0]) for r in runs.values())

    def as_run(name, r) -> Run:
        t, obs, delta = (a[:n] for a in r.drives["pbs"])
        i_s = r.vehicle.steering_for("mbd").i_s
        frame = new_frame(t, delta * i_s, obs)
        frame["delta"] = delta
        frame["delta_fb"] = 0.0  # the path follower is the whole steering: no feedback
        return Run(frame, {"name": f"pbs-turn-{name}"})

    ref = "truth" if "truth" in runs else next(iter(runs))
    log = as_run(ref, runs[ref])
    log.meta.update({"name": "pbs-turn", "manoeuvre": "pbs-turn", "direction": "forward"})
    others = {k: as_run(k, r) for k, r in runs.items() if k != ref}
    return record_manoeuvre(out, log, others, vehicle,
                            extra=f"The PBS low-speed turn; the reference is `{ref}`.")


def run(args: argparse.Namespace) -> int:
    """Run ``artic pbs``; returns the exit code."""
    from artic.mjcf.vehicle import load_vehicle
    from artic.validation.pbs.figure import plot_swept_paths
    from artic.validation.pbs.run import run_model
    from artic.validation.pbs.tables import markdown, table, write_tables
    from artic.validation.plumbing.outputs import check_output_dir

    vehicle = load_vehicle(args.vehicle)
    names = _models(args.models, vehicle)
    out = check_output_dir(args.out_dir)
    runs = {}
    for name in names:
        t0 = time.process_time()
        runs[name] = run_model(name, vehicle, args.seed)
        print(f"pbs: {name} done ({time.process_time() - t0:.1f} s CPU)", flush=True)
    write_tables(out, runs, vehicle.name)
    plot_swept_paths(out / "swept-path.png", runs,
                     f"PBS low-speed turn: {vehicle.name}, each model's swept path over the "
                     "truth's" if "truth" in runs else f"PBS low-speed turn: {vehicle.name}")
    if not args.no_recording:
        _record(out / "pbs-turn.rrd", runs, vehicle)
    print(markdown(table(runs), vehicle.name))
    print(f"wrote {out}")
    return 0



