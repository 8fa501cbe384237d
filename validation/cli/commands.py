"""The ``artic`` command line.

Subcommands:

- ``artic vehicle show VEHICLE [--json]``: the resolved parameter set;
- ``artic vehicle keys``: the parameter file format;
- ``artic simulate --model kin|stm --vehicle V --manoeuvre KIND ... --out RUN.parquet``;
- ``artic validate LOG.parquet ... --vehicle V --models kin,stm,mbd [--gain K]
  [--gain-sweep] [--no-recordings] [--steer-from log|yaw-rate] [--noise N.toml]
  --out-dir DIR``: metrics (a log split at gaps pooled over its segments), the
  Table 2/3 summaries, one Rerun recording per log, and each criterion's noise
  floor from the sensor noise declared (:mod:`artic.validation.criteria.noisefloor`);
- ``artic tune LOG.parquet ... --vehicle V --models kin,stm,mbd --out PARAMS.toml``;
- ``artic mjcf --vehicle V -o MODEL.xml``: the multibody model as MJCF;
- ``artic logs import SRC... [--channels MAP.toml] [--vehicle V] --out-dir DIR``:
  exports (or CSVs, ROS bags and MCAP files through a channel map) to canonical
  Parquet;
- ``artic campaign [--out-dir DIR] [--seeds N]``: the main job, on one truck or several;
- ``artic dock [--scenario S] [--vehicle V] [--controller C] [--seeds N] --out-dir DIR``:
  the docking benchmark (:mod:`artic.validation.docking.command`).

Errors in the user's input end with exit code 2 and a one-line message that
names the file and what to change; no traceback. That covers the options
(every number finite and in range, see :mod:`artic.validation.plumbing.options`), the
output locations (checked before the work starts; a read-only, full or
wrong-type path is named with the system's reason), the input files
(malformed CSV, Parquet, ``.mat``, JSON or TOML), a run too long for the
memory, and an unreachable Dask scheduler. Warnings are one line each, too.
A simulation that diverges ends with exit code 1. These are the errors of
:mod:`artic.mjcf.errors` (a :class:`~artic.mjcf.errors.UserError`, a
:class:`~artic.mjcf.errors.PlantError`), caught by type; anything else is a
bug in artic: its traceback, a line asking to report it, and exit code 3.
"""

from __future__ import annotations

import argparse
import dataclasses
import json
import math
import os
import sys
import traceback
import warnings
from collections.abc import Sequence
from pathlib import Path

from artic.mjcf import schema
from artic.mjcf.errors import PlantError, UserError, one_line
from artic.mjcf.vehicle import load_vehicle
from artic.validation.cli import toplevel
from artic.validation.docking import command as dock_command
from artic.validation.harness.reversing import DEFAULT_GAIN
from artic.validation.logs.schema import CHECKS, MIN_SEGMENT, SOURCES
from artic.validation.pbs import command as pbs_command
from artic.validation.plumbing import options, runtime
from artic.validation.plumbing.outputs import (
    OutDirLock,
    check_output_dir,
    check_output_file,
    clean_stale,
)
from artic.validation.synthetic.manoeuvres import KINDS, default_duration, make_profile
from artic.validation.synthetic.truth import TRUTHS

# Start-up: ``artic --help`` and a mistyped option answer in a fraction of a second
# because this module imports only what the parser needs (numpy, the vehicle files,
# the option converters). Each command imports its readers, writers and models in
# its own body, so pandas, scipy, numba, MuJoCo and Rerun load only for a command
# that uses them (tests/test_startup.py).

JOBS = os.cpu_count() or 1
"""Default of every ``--jobs``: the number of cores."""

MIN_RUN = MIN_SEGMENT
"""Shortest run ``artic simulate`` writes [s]: what an import keeps of a segment, as the
criteria and the differentiator need a second."""

USER_ERRORS = (UserError, FileNotFoundError)
"""What the user can fix (:mod:`artic.mjcf.errors`): one line, exit code 2. Anything
else that escapes a command is a bug: its traceback, and a request to report it."""

REPORT = ("artic: this is a bug in artic, not in your input; please report it with the "
          "command you ran and the traceback above")


def finite_json(value):
    """``value`` with every non-finite float replaced by ``None`` (JSON has no NaN)."""
    if isinstance(value, float) and not math.isfinite(value):
        return None
    if isinstance(value, dict):
        return {k: finite_json(v) for k, v in value.items()}
    if isinstance(value, list | tuple):
        return [finite_json(v) for v in value]
    return value


def _vehicle_show(args: argparse.Namespace) -> int:
    v = _load_vehicle(args.vehicle)
    flat = v.flat()
    if args.json:
        print(json.dumps(finite_json(flat), indent=2, allow_nan=False))
    else:
        width = max(map(len, flat))
        for k, val in flat.items():
            shown = f"{val:.6g}" if isinstance(val, float) else val
            print(f"{k:<{width}}  {shown}")
    return 0


def _vehicle_keys(args: argparse.Namespace) -> int:
    print(schema.describe())
    return 0


def _load_vehicle(name: str):
    """The vehicle file or preset ``name``, its ``[steering.NAME]`` tables checked.

    Each must name a registered model (:func:`artic.validation.models.check_vehicle`).
    """
    from artic.validation.models import check_vehicle

    return check_vehicle(load_vehicle(name))


def _simulate(args: argparse.Namespace) -> int:
    from artic.validation.harness.loop import DIVERGED
    from artic.validation.harness.simulate import simulate
    from artic.validation.logs.runfile import write_run
    from artic.validation.models import build, close

    out = check_output_file(args.out)
    v = _load_vehicle(args.vehicle)
    s = v.steering_for(args.model)
    reverse = args.manoeuvre.endswith("reverse")
    speed = args.speed_kph if args.speed_kph is not None else (3.0 if reverse else 5.0)
    amplitude = args.amplitude_deg if args.amplitude_deg is not None else (
        90.0 if reverse else 200.0)
    duration = args.duration if args.duration is not None else default_duration(
        args.manoeuvre, amplitude, speed, L1=v.L1, i_s=s.i_s)
    what = "--duration" if args.duration is not None else (
        f"--speed-kph {speed:g} and --amplitude-deg {amplitude:g} (a {args.manoeuvre} lasts "
        f"{duration:.3g} s at them)")
    if duration < MIN_RUN:
        raise UserError(f"{what}: a run of {duration:.3g} s is too short to validate; the "
                         f"criteria and the differentiator need at least {MIN_RUN:g} s: give "
                         f"--duration {MIN_RUN:g} or more")
    options.check_memory(int(duration / 0.01) + 1, what)
    profile = make_profile(args.manoeuvre, amplitude_deg=args.amplitude_deg,
                           speed_kph=args.speed_kph, side=args.side, duration=args.duration,
                           delta_h_offset=s.delta_h_offset, L1=v.L1, i_s=s.i_s)
    model = build(args.model, v)
    try:
        run = simulate(model, v, profile)
    finally:
        close(model)
    status = run.meta["status"]
    span = float(run.frame.t.iloc[-1] - run.frame.t.iloc[0]) if len(run.frame) else 0.0
    if span < MIN_RUN - 1e-9:
        end = f" ({span:.3g} s)" if len(run.frame) else ""
        print(f"artic: simulation failed: {len(run.frame)} sample(s){end}, too short to "
              f"validate (at least {MIN_RUN:g} s), not written: {status}", file=sys.stderr)
        return 1
    write_run(run, out)
    end = f", {run.frame.t.iloc[-1]:.2f} s" if len(run.frame) else ""
    print(f"wrote {out}: {len(run.frame)} samples{end}"
          + ("" if status == "ok" else f"; {status}"))
    if f": {DIVERGED}" in status:  # not finite, or beyond every physical range
        print(f"artic: simulation failed: {status}", file=sys.stderr)
        return 1
    return 0


def _check_tyre_data(vehicle, models: Sequence[str]) -> None:
    """Refuse, before any work, models the vehicle has no fitting tyre data for."""
    from artic.mjcf.plausible import check_tyre_data

    for m in models:
        check_tyre_data(vehicle, m)


def _read_logs(args: argparse.Namespace, vehicle) -> list:
    from artic.validation.logs.consistency import parse_accept
    from artic.validation.logs.importers import read_log

    accept = parse_accept(args.accept)
    logs = [read_log(p, vehicle, accept) for p in args.logs]
    if getattr(args, "steer_from", "log") == "yaw-rate":
        for log in logs:
            log.meta["steer_from"] = "yaw-rate"
    return logs


def _validate(args: argparse.Namespace) -> int:
    from artic.validation.criteria.fixedscale import SCALE_FILE, write_scale
    from artic.validation.criteria.pooled import pool_segments, segment_of, whole_logs
    from artic.validation.logs.noise import from_meta, read_noise
    from artic.validation.logs.runfile import atomic_write
    from artic.validation.models import parse_models
    from artic.validation.review.tables import markdown, summary, write_table
    from artic.validation.runs.validate import (
        FAILED,
        stderr_progress,
        validate_runs,
        write_metrics,
    )

    v = _load_vehicle(args.vehicle)
    models = parse_models(args.models)
    _check_tyre_data(v, models)
    out = check_output_dir(args.out_dir)
    declared_file = read_noise(args.noise) if args.noise is not None else None
    logs = _read_logs(args, v)
    declared = {log.name: declared_file if declared_file is not None else from_meta(log.meta)
                for log in logs}
    for log in logs:
        if log.meta.get("derived"):
            print(f"note: {log.name}: {log.meta['derived']['note']}")
        if log.meta.get("steer_from") == "yaw-rate":
            print(f"note: {log.name}: --steer-from yaw-rate: the models' tractors follow the "
                  "measured yaw rate, so the comparison is about the semitrailer")
    with OutDirLock(out, "validate"):
        clean_stale(out)
        metrics = validate_runs(logs, v, models, gain=args.gain, out_dir=out,
                                progress=stderr_progress, jobs=args.jobs)
        if any(segment_of(log) for log in logs):
            metrics = pool_segments(metrics, logs, out / "runs")
        path = write_metrics(metrics, out / "metrics.csv")
        write_scale(metrics.attrs["scale"], out / SCALE_FILE)
        failed = metrics[metrics["status"].astype(str).str.startswith(FAILED)]
        print(f"wrote {path} ({len(metrics)} rows) and {len(metrics) - len(failed)} runs in "
              f"{out / 'runs'}" + (f"; {len(failed)} (log, model) pair(s) failed, see their "
                                   "status in metrics.csv" if len(failed) else ""))
        print("\n" + per_run_lines(metrics))
        _pbs_measures(out, logs, v, metrics)
        print("\n" + _noise_floor(logs, metrics, out, v, declared, args.noise))
        if args.recordings:
            _validate_recordings(out, logs, v, models, metrics)
        for direction, stem, title in (("forward", "table2_forward", "Forward (Table 2 columns)"),
                                       ("reverse", "table3_reverse", "Reverse (Table 3 columns)")):
            table = summary(whole_logs(metrics), direction)
            if len(table):
                write_table(table, out / stem, title)
                print(f"\n{title}\n\n{markdown(table)}")
        if args.gain_sweep:
            from artic.validation.runs.gainsweep import (
                DEFAULT_GAINS,
                bounds_text,
                gain_sweep,
                plot_gain_sweep,
                sweep_table,
            )

            rev = [log for log in logs if (log.frame["v_x_1"] < 0).mean() > 0.5]
            if not rev:
                raise UserError("--gain-sweep needs reverse logs (the tractor reversing for "
                                 "most of the log); none of the given logs is one")
            sweep = gain_sweep({"logs": (v, rev)}, models, DEFAULT_GAINS, args.jobs,
                               stderr_progress)
            atomic_write(out / "gain_sweep.csv",
                         lambda p: sweep.to_csv(p, index=False, float_format="%.6g"))
            plot_gain_sweep(sweep, out / "gain_sweep.png", args.gain)
            print(f"\nGain sweep (stability bound K_min: {bounds_text(sweep.attrs['K_min'])}; "
                  f"{out / 'gain_sweep.png'})\n\n{markdown(sweep_table(sweep))}")
    return 1 if len(failed) else 0


def _noise_floor(logs, metrics, out: Path, vehicle, declared: dict,
                 noise_file: Path | None) -> str:
    from artic.validation.logs.runfile import atomic_write
    """The noise floor's text, ``OUT/noise_floor.csv`` written; one line without declared noise."""
    from artic.validation.criteria import noisefloor

    have = [name for name, n in declared.items() if n]
    if not have:
        return ("Noise floor: no sensor noise declared, so what the sensors alone make of each "
                "criterion is unknown; declare it with --noise FILE.toml or in the [noise] "
                "table of the channel map the logs were imported with (the logs guide)")
    table = noisefloor.of_runs(logs, metrics, out / "runs", vehicle, declared,
                               metrics.attrs.get("scale"))
    path = atomic_write(out / "noise_floor.csv",
                        lambda p: table.to_csv(p, index=False, float_format="%.6g"))
    source = str(noise_file) if noise_file is not None else "the logs' channel maps"
    missing = len(declared) - len(have)
    tail = (f"\n{missing} log(s) declare no noise and have no floor" if missing else "")
    return f"{noisefloor.text(table, source)}{tail}\nwrote {path}"


def per_run_lines(metrics) -> str:
    """One line per (log, model): the articulation error, eps_n and the status.

    The articulation error comes first: many real logs have a hitch sensor
    and little else, and ``eps_gamma`` needs nothing more.
    """
    lines = ["Per run: eps_gamma (articulation error, eq. 8) and eps_n"]
    width = max((len(f"{r.log} / {r.model}") for r in metrics.itertuples()), default=0)
    for r in metrics.itertuples():
        what = f"{r.log} / {r.model}"
        g, n = float(r.eps_gamma), float(r.eps_n)
        if math.isnan(g):
            shown = "eps_gamma -"
        else:
            shown = f"eps_gamma {math.degrees(g):6.2f} deg ({g:.4f} rad)"
        shown += "; eps_n -" if math.isnan(n) else f"; eps_n {n:.3g} %"
        if r.status != "ok":
            shown += f"; {r.status}"
        lines.append(f"  {what:<{width}}  {shown}")
    return "\n".join(lines)


def _pbs_measures(out: Path, logs, vehicle, metrics) -> None:
    """The low-speed measures of each log and each model with a result on it (pbs.fromlog)."""
    from artic.validation.pbs.fromlog import write_validate_table
    from artic.validation.runs.validate import is_failed

    ok = [(r.log, r.model) for r in metrics.itertuples() if not is_failed(r.status)]
    path = write_validate_table(out, logs, vehicle, ok)
    if path is not None:
        print(f"wrote {path} (swept width and off-tracking of each log and model)")


def _validate_recordings(out: Path, logs, vehicle, models, metrics) -> None:
    """One Rerun recording per log, with every model that has a result on it."""
    from artic.validation.logs.runfile import read_run
    from artic.validation.review.recording import record_manoeuvre
    from artic.validation.runs.validate import is_failed

    for log in logs:
        rows = metrics[metrics["log"] == log.name]
        ok = [r.model for r in rows.itertuples() if not is_failed(r.status)]
        runs = {m: read_run(out / "runs" / f"{log.name}.{m}.parquet") for m in models if m in ok}
        target = record_manoeuvre(out / "recordings" / f"{log.name}.rrd", log, runs, vehicle,
                                  rows)
        print(f"wrote {target} ({target.stat().st_size / 1e6:.1f} MB; open it with "
              f"`rerun {target}`)")


def _tune(args: argparse.Namespace) -> int:
    from artic.mjcf.writer import fitted_changes, updated, write_vehicle
    from artic.validation.campaign.tuning import tune
    from artic.validation.logs.consistency import accepted_in
    from artic.validation.logs.yawsteer import wants_yaw_rate
    from artic.validation.models import parse_models
    from artic.validation.runs.validate import stderr_progress

    out = check_output_file(args.out)
    v = _load_vehicle(args.vehicle)
    models = parse_models(args.models)
    _check_tyre_data(v, models)
    logs = _read_logs(args, v)
    unsteered = [log.name for log in logs if wants_yaw_rate(log.meta)]
    if unsteered:
        raise UserError(f"{', '.join(unsteered)}: no steering channel (delta_h derived from the "
                         "yaw rate); tuning fits the steering map and needs a measured steering "
                         "wheel: leave it out")
    reverse = [log.name for log in logs if (log.frame["v_x_1"] < 0).mean() > 0.5]
    if reverse:
        raise UserError(f"tuning uses forward manoeuvres; {', '.join(reverse)} reverse(s) "
                         "for most of the log: leave it out")
    _, fits = tune(v, logs, models, args.jobs, stderr_progress)
    print("model  parameter        nominal      fitted       bounds")
    for fit in fits:
        for row in fit.rows():
            flag = "  (at bound)" if row["at_bound"] else ""
            print(f"{row['model']:<6} {row['parameter']:<16} {row['nominal']:<12.6g} "
                  f"{row['fitted']:<12.6g} [{row['lo']:.4g}, {row['hi']:.4g}]{flag}")
        print(f"{fit.model:<6} eps_n before {fit.eps_n_before:.3f} %, after "
              f"{fit.eps_n_after:.3f} % ({fit.evaluations} evaluations, {fit.wall_s:.1f} s)")
    accepted = sorted({name for log in logs for name in accepted_in(log.meta)})
    source = f"Tuned by artic on {', '.join(log.name for log in logs)}" + (
        f" (checks accepted with --accept: {', '.join(accepted)})" if accepted else "")
    data = updated(args.vehicle, fitted_changes(v, {f.model: f.fitted for f in fits}),
                   source, name=f"{v.name}-tuned")
    write_vehicle(data, out)
    print(f"wrote {out}")
    return 0


def _mjcf(args: argparse.Namespace) -> int:
    from artic.validation.logs.runfile import atomic_write_text

    check_output_file(args.output, "-o")
    v = load_vehicle(args.vehicle)
    if args.no_scene:  # the vehicle's geometry alone, for viewing or for other scenes
        from artic.mjcf.builder import to_xml

        text, what = to_xml(v, scene=False), "no tyre data; plant.load needs the full file"
    else:
        from artic.plant.standalone import to_xml

        text, what = to_xml(v), "with its tyre data: plant.load(path) simulates it"
    path = atomic_write_text(args.output, text)
    print(f"wrote {path} ({v.name}: {len(v.axles)} axles; {what})")
    return 0


def _logs_import(args: argparse.Namespace) -> int:
    from artic.validation.logs.consistency import parse_accept
    from artic.validation.logs.importers import import_sources

    accept = parse_accept(args.accept)
    vehicle = load_vehicle(args.vehicle) if args.vehicle else None
    out = check_output_dir(args.out_dir)
    for path in import_sources(args.sources, out, accept, vehicle, channels=args.channels):
        print(f"wrote {path}")
    return 0


def _logs_generate(args: argparse.Namespace) -> int:
    from artic.validation.runs.validate import stderr_progress
    from artic.validation.synthetic.generate import generate_campaign

    only = [o for o in args.only.split(",") if o] if args.only else None
    check_output_dir(args.out_dir)
    from artic.validation.synthetic.sensors import SensorModel

    sensors = SensorModel.ideal() if args.sensors == "ideal" else SensorModel()
    paths = generate_campaign(args.out_dir, seed=args.seed, only=only, progress=stderr_progress,
                              jobs=args.jobs, sensors=sensors, truth=args.truth,
                              drift=args.drift)
    print(f"{len(paths)} manoeuvres in {args.out_dir}; the truth as vehicle files "
          f"{args.out_dir / 'truth-unloaded.toml'} and truth-loaded.toml")
    return 0


def _tyre_curves(args: argparse.Namespace) -> int:
    import math

    from artic.mjcf.vehicle import resolve_tyre_file, tyre_names
    from artic.plant.curves import curves, plot_curves
    from artic.plant.tyre import TyreParams
    from artic.validation.logs.runfile import atomic_write

    try:
        loads = [float(x) for x in args.fz.split(",") if x.strip()]
    except ValueError:
        raise UserError(f"--fz {args.fz!r}: expected loads in newtons, such as "
                         "10e3,30e3,50e3") from None
    if not loads or not all(math.isfinite(f) and f > 0.0 for f in loads):
        raise UserError(f"--fz {args.fz!r}: every load must be a positive number of newtons")
    given = Path(args.tyre)
    shipped = tyre_names()
    if not given.is_file() and (given.parent != Path(".") or given.name not in shipped):
        raise UserError(f"--tyre {args.tyre}: no such file, nor a tyre shipped with artic "
                        f"({', '.join(shipped)}); give a .tir file or one of those names")
    # Here or shipped: the current folder stands where a vehicle file's would.
    path = resolve_tyre_file(args.tyre, Path.cwd() / "command-line", "--tyre")
    p = TyreParams.from_tir(path)  # a TirError (a ValueError) names the file and key
    out = check_output_dir(args.out, "--out")
    out.mkdir(parents=True, exist_ok=True)
    table = curves(p, loads)
    csv = atomic_write(out / f"{path.stem}.curves.csv",
                       lambda f: table.to_csv(f, index=False, float_format="%.6g"))
    png = atomic_write(out / f"{path.stem}.curves.png",
                       lambda f: plot_curves(table, f, path.name))
    print(f"wrote {csv} ({len(table)} points) and {png}")
    return 0


def _campaign(args: argparse.Namespace) -> int:
    from artic.validation.campaign.config import CampaignConfig
    from artic.validation.campaign.executors import DaskOptions
    from artic.validation.campaign.main import run_campaign
    from artic.validation.models import parse_models
    from artic.validation.plumbing.heap import single_arena

    single_arena()  # for the campaign's peak memory (artic.validation.plumbing.heap)

    sweep = tuple(parse_models(args.sweep_models, "--sweep-models")) if args.sweep_models else ()
    models = tuple(parse_models(args.models))
    dask = DaskOptions(timeout=args.scheduler_timeout, tls_ca_file=args.tls_ca_file,
                       tls_cert=args.tls_cert, tls_key=args.tls_key)
    dask.check(args.executor, args.scheduler)
    only = tuple(o for o in args.only.split(",") if o) if args.only else None
    # Checked as it is made, before the output folder is: nothing is written.
    config = CampaignConfig(Path(args.out_dir), models=models, seed=args.seed, jobs=args.jobs,
                            gain=args.gain, sweep_models=sweep, only=only,
                            recordings=args.recordings, executor=args.executor,
                            scheduler=args.scheduler, dask=dask, truth=args.truth,
                            remeasure=args.remeasure, seeds=args.seeds, sensors=args.sensors,
                            drift=args.drift, oracle=args.oracle, tuning=args.tuning)
    run_campaign(dataclasses.replace(config, out_dir=check_output_dir(args.out_dir)))
    return 0


def _add_accept(p: argparse.ArgumentParser) -> None:
    p.add_argument("--accept", action="append", default=[], metavar="CHECK",
                   help="use the logs although this consistency check refuses them "
                        "(recorded in the run's metadata); repeat or comma-separate; "
                        f"checks: {', '.join(CHECKS)}")


def _one_model(text: str) -> str:
    """``--model``: one model of the registry (built-in or registered), by name."""
    from artic.validation.models import parse_models

    try:
        models = parse_models(text, "")  # argparse names the option
    except ValueError as exc:
        raise argparse.ArgumentTypeError(f"invalid choice: {exc}") from None
    if len(models) != 1:
        raise argparse.ArgumentTypeError(f"invalid choice: {text!r} names {len(models)} models; "
                                         "give one (artic validate takes several)")
    return models[0]


def _add_vehicle(p: argparse.ArgumentParser) -> None:
    """The ``--vehicle`` option every command that builds a model takes."""
    p.add_argument("--vehicle", default="gosar2022-unloaded",
                   help="preset name or TOML file (default: %(default)s)")


def build_parser() -> argparse.ArgumentParser:
    """The argument parser of ``artic``: :func:`toplevel.parser` with each command's options."""
    p, cmd = toplevel.parser()
    veh = cmd["vehicle"]
    vsub = veh.add_subparsers(dest="vehicle_command", required=True, parser_class=toplevel.Parser)
    show = vsub.add_parser("show", help="print the resolved parameters")
    show.add_argument("vehicle", help="preset name or TOML file")
    show.add_argument("--json", action="store_true", help="print JSON")
    show.set_defaults(func=_vehicle_show)
    keys = vsub.add_parser("keys", help="print the parameter file format")
    keys.set_defaults(func=_vehicle_keys)

    sim = cmd["simulate"]
    sim.add_argument("--model", required=True, type=_one_model,
                     help="kin, stm, mbd, or a registered model (see artic.register_model)")
    _add_vehicle(sim)
    sim.add_argument("--manoeuvre", required=True, choices=KINDS,
                     help="the steering-wheel and speed profile: straight; constant-steer "
                          "(a ramp to the amplitude, held); slalom (a sine past cones 12 m apart); "
                          "figure-8; ramp-steer-reverse (reversing, a 20 s ramp to the "
                          "amplitude from t = 5 s, held; no feedback, so it jackknifes "
                          "some seconds later and the run stops there); swept-sine (a sine "
                          "rising from 0.05 to 0.8 Hz over 60 s, then 5 s straight)")
    sim.add_argument("--amplitude-deg", type=options.AMPLITUDE_DEG, default=None,
                     help="steering-wheel amplitude [deg] (default 200 forward, 90 reverse)")
    sim.add_argument("--speed-kph", type=options.SPEED_KPH, default=None,
                     help="speed [km/h], positive (default 5 forward, 3 reverse)")
    sim.add_argument("--side", choices=("left", "right"), default="left",
                     help="which way the wheel turns first (default: %(default)s)")
    sim.add_argument("--duration", type=options.DURATION, default=None,
                     help="length [s] (default: one that completes the manoeuvre: straight "
                          "30, constant-steer 60, slalom six cones, figure-8 both "
                          "circles, ramp-steer-reverse 60, swept-sine 65)")
    sim.add_argument("--out", required=True, type=options.output_path,
                     help="the run to write, .parquet (its folder must exist)")
    sim.set_defaults(func=_simulate)

    val = cmd["validate"]
    val.add_argument("logs", nargs="+", type=Path, help="logs in the signal schema (.parquet)")
    _add_vehicle(val)
    val.add_argument("--models", default="kin,stm",
                     help="comma-separated: kin, stm, mbd and registered models "
                          "(default: %(default)s)")
    val.add_argument("--gain", type=options.GAIN, default=DEFAULT_GAIN,
                     help="reversing feedback gain K [rad/rad] (default: %(default)s)")
    val.add_argument("--out-dir", required=True, type=options.output_path,
                     help="output folder: metrics.csv, the runs, the recordings (made with its "
                          "parents)")
    val.add_argument("--gain-sweep", action="store_true",
                     help="also sweep K over the reverse logs; marks the stability bound")
    val.add_argument("--recordings", action=argparse.BooleanOptionalAction, default=True,
                     help="write one Rerun recording per log in OUT_DIR/recordings "
                          "(default: on)")
    val.add_argument("--jobs", type=options.JOBS, default=JOBS,
                     help="threads (default: the number of cores, %(default)s)")
    val.add_argument("--steer-from", choices=("log", "yaw-rate"), default="log",
                     help="steer the models from the log's steering wheel (log; a log without "
                          "one is steered from its yaw rate) or from the measured yaw rate "
                          "(yaw-rate: the tractors follow it, and the comparison is about the "
                          "semitrailer) (default: %(default)s)")
    val.add_argument("--noise", type=Path, default=None, metavar="FILE.toml",
                     help="the logs' sensor noise: a [noise] table (standard deviation, "
                          "correlation time, bias per channel), alone or in a channel map; "
                          "prints each criterion's floor, what a perfect model would score "
                          "from that noise alone (default: the [noise] table of the channel "
                          "map each log was imported with, if any)")
    _add_accept(val)
    val.set_defaults(func=_validate)

    tun = cmd["tune"]
    tun.add_argument("logs", nargs="+", type=Path, help="forward logs (.parquet)")
    _add_vehicle(tun)
    tun.add_argument("--models", default="kin,stm", help="comma-separated (default: %(default)s)")
    tun.add_argument("--out", required=True, type=options.output_path,
                     help="tuned vehicle file (.toml)")
    tun.add_argument("--jobs", type=options.JOBS, default=JOBS,
                     help="threads for the plant (default: the number of cores, %(default)s)")
    _add_accept(tun)
    tun.set_defaults(func=_tune)

    mj = cmd["mjcf"]
    _add_vehicle(mj)
    mj.add_argument("-o", "--output", required=True, type=options.output_path, help="output .xml")
    mj.add_argument("--no-scene", action="store_true", help="the vehicle only, no yard")
    mj.set_defaults(func=_mjcf)

    logs = cmd["logs"]
    lsub = logs.add_subparsers(dest="logs_command", required=True, parser_class=toplevel.Parser)
    imp = lsub.add_parser("import", help="exports to canonical Parquet")
    imp.add_argument("sources", nargs="+", type=Path, help=SOURCES)
    imp.add_argument("--out-dir", required=True, type=options.output_path,
                     help="output folder: one canonical .parquet per imported log (made with "
                          "its parents)")
    imp.add_argument("--vehicle", default=None,
                     help="preset name or TOML file for the steering and hitch checks, and "
                          "whose geometry derives the semitrailer's channels of a tractor-only "
                          "log (default: the steering check with the gosar2022-unloaded map, "
                          "the hitch fitted, and gosar2022-unloaded's geometry)")
    imp.add_argument("--channels", type=Path, default=None,
                     help="a channel map (.toml) for a CSV with other column names and units, "
                          "or for a ROS bag or MCAP file (topics and fields); the logs guide "
                          "of artic's documentation has examples of both")
    _add_accept(imp)
    imp.set_defaults(func=_logs_import)
    gen = lsub.add_parser("generate", help="the synthetic measured campaign")
    gen.add_argument("--seed", type=options.SEED, default=0,
                     help="the truth's draw and the sensors' noise: the same seed gives the "
                          "same logs (default: %(default)s)")
    gen.add_argument("--out-dir", type=options.output_path, default=Path("artic-out/synthetic"),
                     help="the folder of the exports and the truth files (default: "
                          "%(default)s)")
    gen.add_argument("--only", default="", help="comma-separated manoeuvre names or prefixes")
    gen.add_argument("--truth", choices=TRUTHS, default=TRUTHS[0],
                     help="the vehicle that made the logs: one with its own tyre and steering "
                          "models, the plant differing from the presets in structure, or the "
                          "first near-identical one (default: %(default)s)")
    gen.add_argument("--drift", action=argparse.BooleanOptionalAction, default=True,
                     help="let the steering column's zero drift, the vehicle's one random "
                          "process; --no-drift with --sensors ideal gives the logs the floor "
                          "replays (default: on)")
    gen.add_argument("--sensors", choices=("default", "ideal"), default="default",
                     help="the measurement chain: noisy RTK/INS/CAN models, or the truth "
                          "itself (default: %(default)s)")
    gen.add_argument("--jobs", type=options.JOBS, default=JOBS,
                     help="processes (default: the number of cores, %(default)s)")
    gen.set_defaults(func=_logs_generate)

    tyre = cmd["tyre"]
    tsub = tyre.add_subparsers(dest="tyre_command", required=True)
    tc = tsub.add_parser("curves", help="steady-state Fx, Fy and Mz curves as CSV and PNG")
    tc.add_argument("--tyre", default="artic-truck-315-80R22.5.tir",
                    help="a .tir file, or the name of one shipped with artic (default: "
                         "%(default)s)")
    tc.add_argument("--fz", default="10e3,30e3,50e3",
                    help="comma-separated vertical loads [N] (default: %(default)s)")
    tc.add_argument("--out", required=True, type=options.output_path, help="output folder")
    tc.set_defaults(func=_tyre_curves)

    camp = cmd["campaign"]
    camp.add_argument("--out-dir", type=options.output_path, default=Path("artic-out"),
                      help="output folder (default: %(default)s)")
    camp.add_argument("--models", default="kin,stm,mbd",
                      help="comma-separated: kin, stm, mbd and registered models "
                           "(default: %(default)s)")
    camp.add_argument("--seed", type=options.SEED, default=0,
                      help="seed of the synthetic campaign (with --seeds, the first)")
    camp.add_argument("--seeds", type=options.SEEDS, default=1,
                      help="trucks: one campaign per seed in OUT/seed-K and the pooled tables "
                           "and report in OUT; docs/design/speed.md gives its measured time "
                           "(default: %(default)s, the single campaign in OUT)")
    camp.add_argument("--truth", choices=TRUTHS, default=TRUTHS[0],
                      help="the synthetic campaign's truth: one with its own tyre and steering "
                           "models; the plant differing from the presets in known structural "
                           "effects (the control of the excess over the floor), or the plant "
                           "near-identical (its logs replay exactly) (default: %(default)s)")
    camp.add_argument("--sensors", choices=("default", "ideal"), default="default",
                      help="the logs' measurement chain: noisy RTK/INS/CAN models, each log "
                           "with its noise-free twin for the noise share and the findings, or "
                           "the truth itself (default: %(default)s)")
    camp.add_argument("--drift", action=argparse.BooleanOptionalAction, default=True,
                      help="let the steering column's zero drift; --sensors ideal --no-drift "
                           "runs the campaign on the logs the floor replays (default: on)")
    camp.add_argument("--tuning", choices=("default", "slaloms", "transient"),
                      default="default",
                      help="the forward manoeuvres every model is tuned on, none validated: "
                           "constant steers at 200 deg and 5 km/h and the tuning slaloms; the "
                           "tuning slaloms alone; or those with the paper's slalom and "
                           "figure-8 (default: %(default)s)")
    camp.add_argument("--oracle", action=argparse.BooleanOptionalAction, default=True,
                      help="also run KIN, the STM and the plant untuned with the truth's own "
                           "parameters (rows kin-oracle, ...), on the logs, to split each "
                           "model's error into form and parameters (default: on)")
    camp.add_argument("--gain", type=options.GAIN, default=DEFAULT_GAIN,
                      help="reversing feedback gain K [rad/rad] (default: %(default)s)")
    camp.add_argument("--sweep-models", default="kin,stm",
                      help="models in the gain sweep; empty to skip it (default: %(default)s)")
    camp.add_argument("--recordings", action=argparse.BooleanOptionalAction, default=True,
                      help="write the Rerun recordings (default: on)")
    camp.add_argument("--only", default="",
                      help="a part of the campaign: comma-separated manoeuvre names or prefixes "
                           "(include tuning manoeuvres such as 00-,01-,58-,59- to tune)")
    camp.add_argument("--remeasure", action="store_true",
                      help="compute the efficiency again from the validation runs' times on a "
                           "resumed run (it keeps the original run's figures otherwise)")
    options.add_executor_options(camp, "generation and validation")
    camp.add_argument("--jobs", type=options.JOBS, default=JOBS,
                      help="processes and threads (default: the number of cores, %(default)s)")
    camp.set_defaults(func=_campaign)

    dock_command.add_options(cmd["dock"])
    pbs_command.add_options(cmd["pbs"])
    return p


def _os_error(exc: OSError) -> str:
    where = exc.filename if exc.filename is not None else ""
    if exc.filename2 is not None:
        where = f"{where} -> {exc.filename2}"
    reason = exc.strerror or str(exc)
    return one_line(f"{where}: {reason}" if where else reason)


def _warning_line(message, category, filename, lineno, line=None) -> str:
    return f"artic: warning: {one_line(message)}\n"


def _resume_hint(args: argparse.Namespace) -> str:
    """How an interrupted command goes on: ``""`` for those that start again from scratch.

    A docking sweep keeps each finished run's file, a campaign each finished stage: the same
    command resumes them.
    """
    out = getattr(args, "out_dir", None)
    if out is None:
        return ""
    if getattr(args, "func", None) is dock_command.run and getattr(args, "sweep", None):
        from artic.validation.docking.sweep import RUNS_DIR

        return (f"; the finished runs are kept in {Path(out) / RUNS_DIR}: the same command "
                "resumes the sweep")
    if getattr(args, "func", None) is _campaign:
        return f"; the finished stages are kept in {out}: the same command resumes"
    return ""


def main(argv: Sequence[str] | None = None) -> int:
    """Entry point of ``artic``; returns the exit code."""
    try:
        args = build_parser().parse_args(argv)
    except SystemExit as exc:  # --help, or a one-line option error (exit 2)
        return int(exc.code or 0) if isinstance(exc.code, int | None) else 2
    # The process-wide settings (numba's cache folder, MuJoCo's warnings and timers),
    # made once a command is known and before it imports a compiled model: --help and
    # an option error load neither numba nor MuJoCo.
    runtime.configure()
    previous = warnings.formatwarning
    warnings.formatwarning = _warning_line
    try:
        return int(args.func(args))
    except USER_ERRORS as exc:
        print(f"artic: error: {one_line(exc)}", file=sys.stderr)
        return 2
    except BrokenPipeError:
        # The reader (head, less) left early: not an error of artic's.
        sys.stderr.close()
        return 0
    except OSError as exc:
        print(f"artic: error: {_os_error(exc)}", file=sys.stderr)
        return 2
    except MemoryError:
        print("artic: error: out of memory; give a shorter run or fewer jobs", file=sys.stderr)
        return 2
    except PlantError as exc:
        print(f"artic: simulation failed: {one_line(exc)}", file=sys.stderr)
        return 1
    except KeyboardInterrupt:  # Ctrl-C: one line, and how to go on where there is a way
        print(f"artic: interrupted{_resume_hint(args)}", file=sys.stderr)
        return 130  # the shell's code for a process ended by SIGINT
    except Exception:
        traceback.print_exc()
        print(REPORT, file=sys.stderr)
        return 3
    finally:
        warnings.formatwarning = previous


if __name__ == "__main__":  # pragma: no cover
    sys.exit(main())
