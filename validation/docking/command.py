"""``artic dock``: the docking benchmark on the command line.

- ``artic dock --list``: the scenarios, the built-in controllers and the presets;
- ``artic dock [--scenario NAME,...] [--vehicle V,...] [--controller NAME,...]
  [--seeds N] [--sensors full|tractor|camera] [--trailer nominal|unknown] [--truth]
  [--jobs J] --out-dir D``: every scenario x vehicle x seed with each controller, seeing
  the sensor set's signals (:data:`artic.validation.docking.sensing.SENSOR_SETS`; ``full``
  by default); with ``--trailer unknown`` the plant's semitrailer is drawn per start
  (:mod:`artic.validation.docking.variants`). Writes
  ``D/dock.csv`` (one row per run, the columns of
  :data:`artic.validation.docking.scores.COLUMNS`), ``D/dock_table.csv`` and
  ``D/dock_table.md`` (success rates and errors with 95 % intervals; with
  two controllers or more, ``D/dock_pairs.csv`` and the Markdown compare every
  two over the same starts, after Holm's correction:
  :mod:`artic.validation.docking.pairs`), ``D/dock_errors.png`` (the final errors) and,
  unless ``--no-recordings``, ``D/recordings/SCENARIO-VEHICLE-CONTROLLER-SEED.rrd``.
  The Markdown ends with each controller's compute time per command over all
  its runs (median, 99th percentile, largest): for the controller's own, run
  it on one core, ``taskset -c 0 artic dock --no-recordings ...`` (``--jobs``
  follows the process's cores). A controller slower than the 0.1 s sample
  period is named in a warning and in ``late_commands``; a run with too many
  late commands fails as ``not real-time`` unless ``--no-realtime``.

- ``artic dock --sweep AXIS=L1,L2,... [...] --out-dir D``: a robustness sweep
  (:mod:`artic.validation.docking.sweep`): the runs at each level of one axis,
  on ``--jobs`` local processes or ``--executor dask`` (``--scheduler``, TLS
  options), each written as it finishes so that a killed sweep resumes; writes
  ``D/sweep.csv``, ``D/sweep_pairs.csv``, ``D/sweep.md``, ``D/sweep.png`` and
  ``D/sweep_runs.csv``. With ``--backend warp [--device cuda|cpu]`` the reference
  controller's runs go to the Warp plant in batches
  (:mod:`artic.validation.docking.warp_dock`; the gpu extra), into the same tables.

A name given twice in a list is refused (its runs would count twice). A
controller module that cannot be imported is one line naming the module and
the error; a controller that exits, crashes or hangs fails its run and the
benchmark goes on. Temporaries of an interrupted benchmark, and recordings of
runs the new table does not list, are removed. The exit is 1, after the tables,
when no run docked or a recording could not be written (a full disk: the run
keeps its scores).

The parser is built without importing the benchmark (numba, the plant), so
that every other command starts as fast as before.
"""

from __future__ import annotations

import argparse
import os
import sys
from pathlib import Path

from artic.mjcf.errors import UserError

DEFAULT_VEHICLES = "gosar2022-unloaded,gosar2022-loaded,six-axle"


def add_options(p) -> None:
    """Add ``artic dock``'s options to its subparser ``p``.

    The subparser comes from :func:`artic.validation.cli.toplevel.parser`.
    """
    from artic.validation.plumbing import options

    p.add_argument("--list", action="store_true",
                   help="name the scenarios, controllers and vehicle presets, and exit")
    p.add_argument("--scenario", default="all",
                   help="comma-separated scenario names, or all (default: %(default)s)")
    p.add_argument("--vehicle", default=DEFAULT_VEHICLES,
                   help="comma-separated presets or vehicle files (default: %(default)s)")
    p.add_argument("--controller", default="reference",
                   help="comma-separated: built-in names or package.module:Class "
                        "(default: %(default)s)")
    p.add_argument("--seeds", type=options.number(1, 10000, integer=True), default=10,
                   help="seeded starts per scenario and vehicle, 0 to N-1 (default: %(default)s)")
    p.add_argument("--out-dir", type=options.output_path, default=None,
                   help="output folder (required, unless --list)")
    p.add_argument("--jobs", type=options.JOBS, default=_cores(),
                   help="processes (default: the cores this process may run on, %(default)s; "
                        "under taskset -c 0, one, so that the compute times are the "
                        "controllers' own)")
    p.add_argument("--truth", action="store_true",
                   help="drive the synthetic campaign's truth (seed 0) instead of the plant built "
                        "from the vehicle file; gosar2022 presets only")
    p.add_argument("--sensors", default="full", metavar="{full,tractor,camera}",
                   help="what the controllers see: full, RTK/INS on both units; tractor, the "
                        "tractor's RTK/INS and a hitch encoder; camera, the tractor's RTK/INS "
                        "and a rear camera's articulation; with tractor and camera an "
                        "estimator gives the semitrailer's pose (default: %(default)s)")
    p.add_argument("--trailer", default="nominal",
                   help="the plant's semitrailer: nominal (the vehicle file's) or unknown (drawn "
                        "per start: bogie position, fifth wheel, payload, tyres; the planner and "
                        "the controllers still know only the file) (default: %(default)s)")
    p.add_argument("--realtime", action=argparse.BooleanOptionalAction, default=True,
                   help="fail a run whose controller takes longer than the 0.1 s sample period "
                        "for more than one command in twenty (default: on; --no-realtime "
                        "only counts them, in dock.csv's late_commands)")
    p.add_argument("--recordings", action=argparse.BooleanOptionalAction, default=True,
                   help="write one Rerun recording per run in OUT_DIR/recordings, about 1 MB "
                        "a minute of driving (default: on)")
    p.add_argument("--sweep", action="append", default=None, metavar="AXIS=L1,L2,...",
                   help="a robustness sweep: every run at each level of one axis (artic dock "
                        "--list names the axes); writes sweep.csv, sweep_pairs.csv, sweep.md "
                        "and sweep.png, and resumes an interrupted sweep in the same folder")
    p.add_argument("--backend", choices=("cpu", "warp"), default="cpu",
                   help="the plant a sweep's runs drive: cpu, the C plant on --jobs processes; "
                        "warp, the reference controller's runs batched on the Warp plant "
                        "(pip install \"artic[gpu]\"; no recordings) (default: %(default)s)")
    p.add_argument("--device", choices=("cpu", "cuda"), default=None,
                   help="with --backend warp: Warp's device, cuda (a GPU) or cpu (slow, for "
                        "checks) (default: cuda)")
    options.add_executor_options(p, "a sweep's runs")
    p.set_defaults(func=run)


def check_backend(args: argparse.Namespace, controllers: list[str],
                  axis: str | None = None) -> str | None:
    """The Warp device of ``--backend warp``, or ``None`` for the CPU plant.

    Raises
    ------
    UserError
        One line for what the Warp backend does not run, or a missing gpu extra.
    """
    if args.backend == "cpu":
        if args.device is not None:
            raise UserError("--device picks the Warp plant's device: add --backend warp, or "
                            "leave --device out")
        return None
    if args.sweep is None:
        raise UserError("--backend warp runs sweeps: add --sweep AXIS=L1,L2,... (the "
                        "benchmark itself runs on the CPU plant)")
    others = [c for c in controllers if c != "reference"]
    if others:
        raise UserError(f"--controller {others[0]}: runs only on the CPU backend; the Warp "
                        "backend batches the reference controller alone (leave --backend warp "
                        "out, or give --controller reference)")
    for flag, bad in (("--truth", args.truth), ("--executor dask", args.executor != "local"),
                      (f"--sensors {args.sensors}", args.sensors != "full"),
                      (f"--sweep {axis}", axis in ("delay", "sensors", "articulation_noise"))):
        if bad:
            raise UserError(f"{flag}: runs only on the CPU backend; leave it out with "
                            "--backend warp")
    import importlib.util

    missing = [m for m in ("warp", "mujoco_warp") if importlib.util.find_spec(m) is None]
    if missing:
        raise UserError(f"--backend warp needs the gpu extra ({', '.join(missing)} is not "
                        'installed): pip install "artic[gpu]"')
    device = args.device or "cuda"
    from artic.plant.warp_plant import find_device

    find_device(device)  # a missing GPU is one line now, before any run is planned
    return device


def _cores() -> int:
    """The cores this process may run on (its affinity, e.g. one under ``taskset -c 0``)."""
    try:
        return len(os.sched_getaffinity(0)) or 1
    except AttributeError:  # pragma: no cover - no affinity on this platform
        return os.cpu_count() or 1


def _names(text: str, option: str) -> list[str]:
    names = [n.strip() for n in text.split(",") if n.strip()]
    if not names:
        raise UserError(f"{option}: no name given")
    _once(names, option)
    return names


def _once(names: list[str], option: str, given: list[str] | None = None) -> None:
    """Refuse a name given twice: its runs would be counted twice in every rate."""
    seen: dict[str, str] = {}
    for name, text in zip(names, given or names, strict=True):
        if name in seen:
            both = text if text == seen[name] else f"{seen[name]} and {text}"
            raise UserError(f"{option} {','.join(given or names)}: {both} named twice; each "
                             "start would be counted twice in the success rates: name it once")
        seen[name] = text


def list_all() -> str:
    """The text of ``artic dock --list``."""
    from artic.mjcf.vehicle import preset_names
    from artic.validation.docking.controllers import BUILTIN
    from artic.validation.docking.scenarios import SCENARIOS

    width = max(len(n) for n in [*SCENARIOS, *BUILTIN])  # one column for the descriptions
    lines = ["scenarios:"]
    lines += [f"  {s.name:<{width}}  {s.description}" for s in SCENARIOS.values()]
    lines += ["controllers (or package.module:Class):"]
    lines += [f"  {n:<{width}}  {text}" for n, (_, text) in BUILTIN.items()]
    lines += ["vehicles (or a vehicle file):"]
    lines += [f"  {n}{_cannot_dock(n)}" for n in preset_names()]
    from artic.validation.docking.sweep import AXES

    width = max(len(n) for n in AXES)
    lines += ["sweep axes (--sweep AXIS=L1,L2,...):"]
    for a in AXES.values():
        unit = f" [{a.unit}]" if a.unit and a.unit != "-" else ""
        why = a.missing()
        lines.append(f"  {a.name:<{width}}  {a.description}{unit}; nominal {a.shown_nominal()}"
                     + (f" (not available yet: {why})" if why else ""))
    return "\n".join(lines)


NO_PLANT = ("artic dock drives the plant: give a vehicle file with tyre data that fits it "
            "(artic dock --list marks the presets that cannot dock)")
"""The end of the refusal of a vehicle the plant cannot be built for."""


def _cannot_dock(preset: str) -> str:
    """``""``, or why the plant cannot be built for ``preset`` (for ``--list``)."""
    from artic.mjcf.plausible import check_tyre_data
    from artic.mjcf.schema import VehicleFileError
    from artic.mjcf.vehicle import load_vehicle

    try:
        check_tyre_data(load_vehicle(preset), "mbd", "")
    except VehicleFileError as exc:
        why = str(exc).split("; ", 1)[0].split("': ", 1)[-1]
        return f"  (cannot dock: {why}; the plant needs one)"
    return ""


def run(args: argparse.Namespace) -> int:
    """Run ``artic dock``."""
    if args.list:
        print(list_all())
        return 0
    sweep = None
    if args.sweep is not None:
        from artic.validation.docking.sweep import parse_sweep

        sweep = parse_sweep(args.sweep)
        from artic.validation.docking.sweep import check_base

        check_base(sweep[0], args.sensors, args.trailer)
        if args.truth and sweep[0].name in ("friction", "grade"):
            raise UserError(f"--sweep {sweep[0].name} acts on the plant built from the vehicle "
                            "file; the truth has its own tyres and slope: leave --truth out")
    from artic.validation.plumbing.executors import DaskOptions

    dask = DaskOptions(timeout=args.scheduler_timeout, tls_ca_file=args.tls_ca_file,
                       tls_cert=args.tls_cert, tls_key=args.tls_key)
    dask.check(args.executor, args.scheduler)
    if args.executor != "local" and sweep is None:
        raise UserError("--executor dask spreads a sweep's runs: add --sweep AXIS=L1,L2,... "
                        "(the benchmark itself runs on --jobs local processes)")
    if args.out_dir is None:
        raise UserError("artic dock: give --out-dir (or --list)")
    import pandas as pd

    from artic.mjcf.plausible import check_tyre_data
    from artic.mjcf.vehicle import load_vehicle
    from artic.validation.docking import pairs as dock_pairs
    from artic.validation.docking.controllers import load
    from artic.validation.docking.plots import plot_errors
    from artic.validation.docking.run import benchmark, run_name
    from artic.validation.docking.scenarios import SCENARIOS, scenario
    from artic.validation.docking.scores import COLUMNS, compute_times, markdown, table
    from artic.validation.docking.sensing import SENSOR_SETS, sensor_set
    from artic.validation.logs.runfile import atomic_write, atomic_write_text
    from artic.validation.plumbing.outputs import OutDirLock, check_output_dir, clean_stale
    from artic.validation.plumbing.progress import stderr

    sensors = sensor_set(args.sensors)  # a bad name is one line, before any run
    scenarios = (list(SCENARIOS) if args.scenario.strip() == "all"
                 else [scenario(n).name for n in _names(args.scenario, "--scenario")])
    vehicles = _names(args.vehicle, "--vehicle")
    loaded = []
    for v in vehicles:
        vehicle = load_vehicle(v)  # a bad name or file is one line now, not in a worker
        loaded.append(vehicle.name)
        if args.truth:
            from artic.validation.docking.run import truth_yard

            truth_yard(vehicle, 0, 0, 0)
        else:  # the plant needs tyre data that fits: refused now, not in every run
            check_tyre_data(vehicle, "mbd", NO_PLANT)
    _once(loaded, "--vehicle", vehicles)  # a preset and its file are one vehicle
    from artic.validation.docking.variants import check_trailer

    check_trailer(args.trailer)
    if args.trailer != "nominal" and args.truth:
        raise UserError("--trailer unknown: the synthetic truth (--truth) has its own "
                        "semitrailer; leave one of them out")
    if args.trailer == "unknown":  # a vehicle the ranges do not fit is one line now
        import numpy as np

        from artic.validation.docking.variants import draw_semitrailer

        for v in vehicles:
            draw_semitrailer(load_vehicle(v), np.random.default_rng(0))
    controllers = _names(args.controller, "--controller")
    device = check_backend(args, controllers, None if sweep is None else sweep[0].name)
    classes = [load(c) for c in controllers]
    _once([f"{c.__module__}:{c.__qualname__}" for c in classes], "--controller", controllers)
    out = check_output_dir(args.out_dir)
    if sweep is not None:
        return _run_sweep(args, out, sweep, (scenarios, vehicles, controllers), dask, device)
    rows = []
    with OutDirLock(out, "dock"):
        stale = clean_stale(out)
        if stale:
            stderr(f"removed {len(stale)} temporary file(s) left by an interrupted run")
        for c in controllers:
            rows += benchmark(scenarios, vehicles, c, range(args.seeds), jobs=args.jobs,
                              progress=stderr,
                              recordings=out / "recordings" if args.recordings else None,
                              truth=0 if args.truth else None, realtime=args.realtime,
                              sensor_set=sensors, trailer=args.trailer)
        _warn_late(rows, args.realtime)
        frame = pd.DataFrame(rows)[list(COLUMNS)]
        csv = atomic_write(out / "dock.csv",
                           lambda p: frame.to_csv(p, index=False, float_format="%.6g"))
        t = table(frame)
        atomic_write(out / "dock_table.csv", lambda p: t.to_csv(p, index=False))
        md = markdown(t)
        if sensors != "full":  # the default's table stays as it was
            md = (f"Sensors: {sensors}, {SENSOR_SETS[sensors]}; the semitrailer's pose from the "
                  "estimator (dock.csv: gamma_est_*, rear_est_*).\n\n" + md)
        if len(controllers) > 1:
            found = dock_pairs.compare(frame, controllers,
                                       metrics=dock_pairs.ERRORS + (dock_pairs.TIME,))
            atomic_write(out / "dock_pairs.csv",
                         lambda p: found.to_csv(p, index=False, float_format="%.6g"))
            md += dock_pairs.markdown(found)
        md += ("\nCompute time per command, every run's commands pooled, in "
               f"{args.jobs} process{'es' if args.jobs > 1 else ''} on {_cores()} "
               f"core{'s' if _cores() > 1 else ''}:\n\n" + markdown(compute_times(rows)))
        atomic_write_text(out / "dock_table.md", md)
        plot_errors(frame, out / "dock_errors.png")
        orphans = _orphan_recordings(out / "recordings", [
            run_name(sc, v, c, seed) for c in controllers for sc in scenarios for v in vehicles
            for seed in range(args.seeds)])
        if orphans:
            stderr(f"removed {len(orphans)} recording(s) in {out / 'recordings'} of runs that "
                   f"dock.csv does not list (an earlier benchmark's): "
                   f"{', '.join(p.name for p in orphans[:3])}"
                   + (", ..." if len(orphans) > 3 else ""))
    docked = int(frame["success"].sum())
    print(md, end="")
    print(f"wrote {csv}: {docked} of {len(frame)} runs docked; {out / 'dock_table.md'}")
    return _exit_code(rows, out)


def _run_sweep(args: argparse.Namespace, out: Path, sweep, names: tuple, dask,
               device: str | None) -> int:
    """``artic dock --sweep``: the runs (resumed), then sweep.csv, its pairs, .md and .png.

    ``names`` are the scenarios, vehicles and controllers; ``device`` the Warp plant's
    (``--backend warp``), or ``None`` for the CPU's.
    """
    scenarios, vehicles, controllers = names
    import dataclasses

    import pandas as pd

    from artic.validation.docking import sweep as sw
    from artic.validation.docking.plots import plot_sweep
    from artic.validation.docking.scores import COLUMNS
    from artic.validation.docking.sensing import sensor_set
    from artic.validation.docking.variants import check_trailer
    from artic.validation.logs.runfile import atomic_write, atomic_write_text
    from artic.validation.plumbing.outputs import OutDirLock, clean_stale
    from artic.validation.plumbing.progress import stderr

    axis, levels = sweep
    specs = sw.plan(axis, levels, scenarios, vehicles, controllers, range(args.seeds),
                    truth=0 if args.truth else None, realtime=args.realtime,
                    sensors=sensor_set(args.sensors), trailer=check_trailer(args.trailer))
    if args.backend != "cpu":  # a run on the other plant is another run on resumption
        specs = [dataclasses.replace(s, backend=args.backend) for s in specs]
    with OutDirLock(out, "dock"):
        stale = clean_stale(out)
        if stale:
            stderr(f"removed {len(stale)} temporary file(s) left by an interrupted run")
        if device is not None and args.recordings:
            stderr("--backend warp writes no recordings (the CPU backend does)")
        rows = sw.sweep(specs, out, jobs=args.jobs, executor=args.executor,
                        scheduler=args.scheduler, dask=dask,
                        recordings=out / "recordings" if args.recordings else None,
                        progress=stderr, device=device)
        _warn_late(rows, args.realtime)
        frame = pd.DataFrame(rows).reindex(columns=["axis", "level", *COLUMNS])
        atomic_write(out / "sweep_runs.csv",
                     lambda p: frame.to_csv(p, index=False, float_format="%.6g"))
        summary = sw.summarise(frame)
        csv = atomic_write(out / "sweep.csv",
                           lambda p: summary.to_csv(p, index=False, float_format="%.6g"))
        pairs = sw.compare(frame, controllers)
        atomic_write(out / "sweep_pairs.csv",
                     lambda p: pairs.to_csv(p, index=False, float_format="%.6g"))
        md = sw.markdown(summary, pairs)
        atomic_write_text(out / "sweep.md", md)
        plot_sweep(summary, out / "sweep.png")
    print(md, end="")
    print(f"wrote {csv}: {int(frame['success'].sum())} of {len(frame)} runs docked; "
          f"{out / 'sweep_pairs.csv'}, {out / 'sweep.md'}, {out / 'sweep.png'}")
    return _exit_code(rows, out)


def _exit_code(rows: list[dict], out: Path) -> int:
    """0, or 1 with one line when the command did not produce what it was asked for.

    A recording that could not be written (a full disk) is an output error: its run keeps
    its scores. A benchmark in which no run docked measured nothing but the failure: the
    tables are written, and the first failure is named (a missing dependency, a controller
    that fails at once).
    """
    from artic.validation.docking.run import RECORDING_ERROR

    unwritten = [r[RECORDING_ERROR] for r in rows if r.get(RECORDING_ERROR)]
    if unwritten:
        print(f"artic: error: {len(unwritten)} of {len(rows)} recording(s) not written "
              f"(first: {unwritten[0]}); the runs' scores are in {out}: free space there, "
              "or give --no-recordings", file=sys.stderr)
        return 1
    if rows and not any(bool(r["success"]) for r in rows):
        print(f"artic: error: none of the {len(rows)} run(s) docked (first: "
              f"{rows[0]['failure']}); see {out / 'dock.csv'}", file=sys.stderr)
        return 1
    return 0


def _warn_late(rows: list[dict], realtime: bool) -> None:
    """One warning per controller whose commands took longer than the sample period."""
    from artic.validation.docking.run import DT

    late: dict[str, list[int]] = {}
    for r in rows:
        n = int(r.get("late_commands") or 0)
        if n:
            late.setdefault(r["controller"], []).append(n)
    for ctrl, counts in late.items():
        judged = ("those with too many failed as not real-time" if realtime
                  else "counted only (--no-realtime)")
        print(f"artic: warning: controller {ctrl}: {sum(counts)} command(s) in {len(counts)} "
              f"run(s) took longer than the {DT:g} s sample period; {judged}", file=sys.stderr)


def _orphan_recordings(folder: Path, runs: list[str]) -> list[Path]:
    """Remove the recordings in ``folder`` of runs other than ``runs``; return them.

    An earlier benchmark into the same folder (other scenarios, seeds or
    controllers) left them; beside the new table they would pass for its runs.
    """
    if not folder.is_dir():
        return []
    keep = {f"{r}.rrd" for r in runs}
    removed = []
    for p in sorted(folder.glob("*.rrd")):
        if p.name not in keep:
            p.unlink(missing_ok=True)
            removed.append(p)
    return removed
