"""The synthetic measured campaign: the test matrix driven on the plant.

``artic logs generate`` drives every manoeuvre of :mod:`artic.validation.synthetic.testmatrix`
on the multibody plant in a *truth configuration*. It measures each run
through :mod:`artic.validation.synthetic.sensors` and writes it as an OXTS-style export, so
that it comes back in through the same importer as real logs.

The truth configuration, drawn once per campaign from its random seed, is
:mod:`artic.validation.synthetic.truth`'s: by default a vehicle with its own
skeleton, tyres, steering and loop, sharing no code with the plant
(:mod:`artic.validation.synthetic.yardtruth`),
which also differs from the validated presets in structure (another trailer
tyre, fifth-wheel friction, payload, sensor installation, a drifting column, a
driver on the pedals, a sloped yard); with ``--truth structural`` the same
draws on the plant itself, with ``--truth legacy`` the first, near-identical
truth. The truth of each load condition is written beside the exports as a
vehicle file, ``truth-unloaded.toml`` and ``truth-loaded.toml``, which every
command accepts.

The independent and structural truths' driver turns the steering wheel and
works the pedals (:mod:`artic.validation.synthetic.actuation`); the legacy truth
drives its speed with the plant's PI controller (``Plant(speed="drive")``).
The plant under validation follows the log's speed (see :mod:`artic.plant.plant`).
``drift=False`` (``--no-drift``) stills the column's drifting zero, the one
random process of the vehicle: with ideal sensors, such logs are what the
floor replays.

Each manoeuvre draws its own random numbers from ``(seed, index)``, so a
campaign is the same whichever manoeuvres are made, in whatever order. Each
export folder is written whole or not at all. A campaign that was cut short
resumes where it stopped. The same seed gives byte-identical files.
"""

from __future__ import annotations

import contextlib
import dataclasses
import errno
import json
import math
import os
import shutil
import tempfile
import time
import uuid
import warnings
from collections.abc import Callable, Iterator
from concurrent.futures import Executor
from pathlib import Path

import numpy as np
import pandas as pd

from artic.mjcf.errors import UserError
from artic.mjcf.files import TEMP_SUFFIX, public_mode
from artic.mjcf.interface import InitialState
from artic.mjcf.vehicle import Steering, Vehicle
from artic.validation.criteria.truthrecords import (
    ACTUATION_KEY,
    STATE_KEY,
    record_actuation,
    record_states,
)
from artic.validation.logs.oxts import export_oxts
from artic.validation.logs.runfile import Run, new_frame
from artic.validation.plumbing import fingerprint
from artic.validation.plumbing.budget import BUDGET
from artic.validation.plumbing.progress import Counter
from artic.validation.plumbing.workers import completed
from artic.validation.synthetic.actuation import PedalDriver, SteeringColumn, TruthActuation
from artic.validation.synthetic.driver import DockingDriver, drive_dock
from artic.validation.synthetic.manoeuvres import make_profile
from artic.validation.synthetic.sensors import SensorModel, measure
from artic.validation.synthetic.testmatrix import Manoeuvre, check_only, selected
from artic.validation.synthetic.truth import (
    DEFAULT,
    TRUTHS,
    slope,
    truth_configuration,
    truth_vehicle,
    write_truth_files,
)
from artic.validation.synthetic.truthmodel import timestep_for, truth_actuation, truth_model

META_FILE = "meta.json"

LONGEST_FIRST = ("docking", "parking", "figure-8", "swept-sine", "slalom", "ramp-steer-reverse",
                 "constant-steer")
"""The manoeuvre kinds, longest drive first: a docking or parking driver takes
50-210 s, a figure-of-8 two minutes, the swept sine 65 s, a ramp steer 25-55 s, a
constant steer 40 s."""

MAX_SHUFFLES = 4
"""Shuffles (pull forward, reverse again) a docking driver allows himself; the
structural truth's steering play, drift and slopes ask for more than two."""




def _drive_profile(plant: TruthActuation, vt: Vehicle, m: Manoeuvre, steering: Steering,
                   rng: np.random.Generator):
    prof = make_profile(m.kind, amplitude_deg=m.amplitude_deg, speed_kph=m.speed_kph,
                        side=m.side, delta_h_offset=steering.delta_h_offset, L1=vt.L1,
                        i_s=steering.i_s, duration=None if m.kind == "figure-8" else (
                            40.0 if m.kind == "constant-steer" else None))
    u = prof.u1.copy()
    plant.reset(InitialState(0.0, 0.0, 0.0, 0.0, u1=float(u[0])))
    # The driver brakes (1 m/s^2) at 33-40 deg, earlier the faster the
    # combination goes; the articulation grows on while it stops, to about 33-40 deg
    # (the paper's runs peaked at 45 on average).
    stop_at = math.radians(rng.uniform(33.0, 40.0) - 1.5 * (m.speed_kph - 3.0))
    n_max = prof.t.size if m.kind != "ramp-steer-reverse" else int(120 / 0.01)
    obs, dh, speed = [], [], []
    u_now, stopping, stopped_for = float(u[0]), False, 0
    for k in range(n_max):
        d_h = prof.delta_h[min(k, prof.t.size - 1)]
        o = plant.observe()
        obs.append(o)
        dh.append(d_h)
        speed.append(u_now)
        if m.kind == "ramp-steer-reverse":
            stopping = stopping or abs(o[12]) >= stop_at
            if stopping:
                stopped_for += u_now == 0.0
                if stopped_for > 100:
                    break
            target = 0.0 if stopping else float(u[min(k, u.size - 1)])
        else:
            target = float(u[min(k + 1, u.size - 1)])
        a_max = 0.01 if stopping else 0.005  # speed change per 10 ms step [m/s]
        u_next = u_now + max(-a_max, min(a_max, target - u_now))
        plant.step_steering_wheel(0.01, d_h, u_now, (u_next - u_now) / 0.01)
        u_now = u_next
    t = np.arange(len(obs)) * 0.01
    return t, np.array(obs), np.array(dh), {}


def _drive_dock(plant: TruthActuation, vt: Vehicle, m: Manoeuvre, steering: Steering,
                rng: np.random.Generator):
    sign = 1.0 if m.side == "left" else -1.0
    if m.kind == "docking":
        y0, psi0 = rng.uniform(1.5, 4.0), rng.uniform(-6.0, 6.0)
    else:
        y0, psi0 = rng.uniform(3.0, 5.5), rng.uniform(6.0, 10.0)
    driver = DockingDriver(vt, max_shuffles=MAX_SHUFFLES)
    run = drive_dock(
        plant, driver, InitialState(10.0, sign * y0, sign * math.radians(psi0), 0.0, u1=0.0))
    dist, e_y, e_psi = driver.errors(run.obs[-1])
    info = {"docked": bool(run.docked), "shuffles": driver.shuffles, "final_distance": dist,
            "final_lateral_error": e_y, "final_heading_error": e_psi,
            "start_lateral": sign * y0, "start_heading": sign * math.radians(psi0)}
    # The steering wheel the driver held from each sample (the last sample's is
    # the one he turned to as the rear reached the dock).
    return run.t, run.obs, run.delta_h, info


def measurement_chain(sensors: SensorModel, truth: dict) -> SensorModel:
    """The sensors as the truth's vehicle carries them: with its semitrailer unit's clock skew.

    Ideal sensors stay ideal, and the legacy truth has no skew. The docking
    benchmark's ``--truth`` measures its runs with the same chain.
    """
    if truth["kind"] != "legacy" and not sensors.is_ideal:
        return dataclasses.replace(sensors, trailer_skew=truth["trailer_clock_skew"])
    return sensors


def simulate_manoeuvre(m: Manoeuvre, seed: int, sensors: SensorModel | None = None,
                       truth_kind: str = DEFAULT, drift: bool = True,
                       timestep: float | None = None, twin: bool = False
                       ) -> Run | tuple[Run, Run]:
    """Drive and measure one manoeuvre; returns the measured run with its metadata.

    Pure computation, no files: it runs wherever an executor sends it.
    ``drift=False`` stills the column's drift (see the module docstring).
    The independent truth steps at its own step for the manoeuvre's kind
    (:func:`artic.validation.synthetic.truthmodel.timestep_for`); ``timestep``
    [s] overrides it, for the convergence study only. ``twin=True`` returns
    ``(measured, twin)``: the same truth run measured also with ideal sensors
    (:func:`noise_free_twin`), no second simulation.
    """
    sensors = sensors or SensorModel()
    truth = truth_configuration(seed, truth_kind, drift)
    structural = truth_kind != "legacy"
    chain = measurement_chain(sensors, truth)
    where = slope(seed, m.index, truth)
    vt = truth_vehicle(m.load, truth, seed, where)
    rng = np.random.default_rng([seed, m.index])
    steering = vt.steering_for("mbd")
    # The independent truth's play is in its compiled column; only the drift is here.
    play = 0.0 if truth_kind == "independent" else truth.get("backlash", 0.0)
    column = SteeringColumn(play, truth.get("drift_rate", 0.0))
    pedals = PedalDriver(vt.m1 + vt.m2, delay=truth["driver_delay"],
                         gain=truth["driver_gain"]) if structural else None
    h = timestep_for(m.kind) if timestep is None else timestep
    with truth_model(vt, truth, "pedals" if structural else "drive", h) as p:
        # The truth's own state at every sample of a reverse run, for the floor's
        # open-loop predictions (kept at their start points only, below).
        plant = truth_actuation(p, steering, column, pedals,
                                record=m.direction == "reverse" and hasattr(p, "full_state"))
        drive = _drive_dock if m.kind in ("docking", "parking") else _drive_profile
        # The driver may ask for more wheel angle than the linkage gives at
        # lock, as a real driver turns the wheel against its stop; the plant
        # holds the wheel at lock. That is the truth, so it is counted in the
        # metadata rather than warned about.
        with warnings.catch_warnings():
            if truth_kind != "independent":  # the plant's truths: the yard truth never loads it
                from artic.plant import PlantWarning

                warnings.simplefilter("ignore", PlantWarning)
            t, obs, delta_h, info = drive(plant, vt, m, steering, rng)
        info["steer_limited_steps"] = p.steer_limited
    true = new_frame(t, delta_h, obs)
    measured = measure(true, rng, chain)
    meta = {**m.meta(), **info, "vehicle": f"gosar2022-{m.load}", "load": m.load,
            "seed": seed, "truth": truth, "slope": where, "source": "synthetic",
            "peak_articulation": float(np.max(np.abs(obs[:, 12]))),
            "sensors": dataclasses.asdict(sensors), "generator": fingerprint.code()}
    # The noise-free measurement, where needed: the twin, and where the floor starts on
    # it (a reverse run's states are kept there too, with a twin or without).
    ideal = measure(true, np.random.default_rng(0), SensorModel.ideal()) \
        if twin or plant.states else None  # ideal sensors draw nothing
    if plant.states:
        meta[STATE_KEY] = record_states(measured, plant.states, also=[ideal])
        # What the truth was given at every step, for the floor to replay
        # (artic.validation.criteria.prediction.Replay); both drivers step 10 ms.
        meta[ACTUATION_KEY] = record_actuation(plant.held, "pedals" if structural else "drive",
                                               0.01, float(t[0]))
    run = Run(measured, meta)
    return (run, noise_free_twin(true, meta, ideal)) if twin else run


def noise_free_twin(true, meta: dict, frame: pd.DataFrame | None = None) -> Run:
    """The noise-free twin of a measured run: the same truth run through ideal sensors.

    Parameters
    ----------
    true : DataFrame
        The truth's signals as :func:`artic.validation.logs.runfile.new_frame` makes them.
    meta : dict
        The measured run's metadata.
    frame : DataFrame, optional
        ``true`` measured with ideal sensors already (what this computes).

    Returns
    -------
    Run
        The truth's motion, its driver's steering wheel and its column's drift
        as in the measured run (one simulation made both), measured without
        noise or clock skew, the steering wheel every sample, unquantised. Its
        ``meta["sensors"]`` is the ideal chain's, ``meta["twin_of"]`` the
        measured run's chain.
    """
    ideal = SensorModel.ideal()
    if frame is None:
        frame = measure(true, np.random.default_rng(0), ideal)  # ideal: draws nothing
    return Run(frame, {**meta, "sensors": dataclasses.asdict(ideal),
                       "twin_of": meta["sensors"]})


TRUTH_RECORDS = ("truth_state", "truth_actuation")
"""The metadata a twin's export leaves to its measured log's (the same truth run, 6.7 MB
in the default campaign): its ``meta.json`` names the log's in ``meta_from`` instead."""


def write_export(run: Run, out_dir: Path, name: str | None = None,
                 meta_from: Path | None = None) -> Path:
    """Export a measured run into ``out_dir/NAME``, whole or not at all.

    Parameters
    ----------
    run : Run
        The measured run.
    out_dir : Path
        Campaign folder.
    name : str, optional
        The folder's name; ``run.meta["name"]`` by default. The campaign passes
        the name of the manoeuvre it submitted, never one a worker returned.
    meta_from : Path, optional
        Another export's folder whose ``meta.json`` holds this run's
        :data:`TRUTH_RECORDS` (a twin's measured log): they are left out here
        and ``meta_from`` names that file, relative to this export, for the
        importer to read them from (:func:`artic.validation.logs.importers.import_source`).

    The CAN file is written at the rate and resolution of the run's
    measurement chain (``meta["sensors"]``): 10 Hz in 0.1 deg steps by
    default, every sample unquantised for ideal sensors, whose logs must come
    back as the truth was. The tables are gzip-compressed (``tractor.csv.gz``
    and so on: a third of the plain CSV's size, the campaign writes two per
    manoeuvre), ``meta.json`` is plain.

    The export is written into a uniquely named temporary folder and renamed
    into place. An existing export is first renamed aside under a unique
    name, so two writers of one export never delete a folder the other is
    writing: the last rename wins, and both exports are whole.
    """
    name = str(run.meta["name"] if name is None else name)
    if not name or name in (".", "..") or name.startswith(".") or any(
            c in name for c in "/\\\0"):
        raise UserError(f"export name {name!r}: not a plain folder name")
    out_dir = Path(out_dir)
    final = out_dir / name
    tmp = Path(tempfile.mkdtemp(prefix=f".{name}.", suffix=TEMP_SUFFIX, dir=out_dir))
    chain = run.meta.get("sensors") or {}
    can = {"can_rate": float(chain["can_rate"]),
           "can_step_deg": round(math.degrees(chain["can_step"]), 9)} if chain else {}
    try:
        export_oxts(run, tmp, **can, compress=True)
        meta = {**run.meta, "name": name}
        if meta_from is not None:
            meta = {k: v for k, v in meta.items() if k not in TRUTH_RECORDS}
            meta["meta_from"] = Path(os.path.relpath(Path(meta_from) / META_FILE, final)
                                     ).as_posix()
        (tmp / META_FILE).write_text(json.dumps(meta, sort_keys=True, indent=1) + "\n")
        public_mode(tmp)
        _rename_into_place(tmp, final)
    except BaseException:
        shutil.rmtree(tmp, ignore_errors=True)
        raise
    return final


def _rename_into_place(tmp: Path, final: Path) -> None:
    """Rename folder ``tmp`` to ``final``, moving an existing ``final`` aside first."""
    for _ in range(20):
        try:
            os.rename(tmp, final)
            return
        except OSError as exc:
            if exc.errno not in (errno.ENOTEMPTY, errno.EEXIST):
                raise
        old = final.parent / f".{final.name}.{uuid.uuid4().hex[:12]}.old{TEMP_SUFFIX}"
        try:
            os.rename(final, old)
        except FileNotFoundError:  # another writer moved it first
            continue
        shutil.rmtree(old, ignore_errors=True)
    raise OSError(errno.EBUSY, "other writers keep replacing the export", str(final))


def generate_manoeuvre(m: Manoeuvre, seed: int, out_dir: Path,
                       sensors: SensorModel | None = None) -> Path:
    """Drive, measure and export one manoeuvre; returns its export folder."""
    return write_export(simulate_manoeuvre(m, seed, sensors), out_dir)


def _simulate_timed(m: Manoeuvre, seed: int, sensors: SensorModel | None = None,
                    truth: str = DEFAULT, drift: bool = True, twin: bool = False
                    ) -> tuple[Run | tuple[Run, Run], float]:
    t0 = time.perf_counter()
    run = simulate_manoeuvre(m, seed, sensors, truth, drift, twin=twin)
    return run, time.perf_counter() - t0


def _same(meta_file: Path, seed: int, sensors: SensorModel, truth: dict) -> bool:
    """Whether an export's metadata says this seed, chain, truth and code made it."""
    try:
        meta = json.loads(meta_file.read_text(encoding="utf-8"))
    except (OSError, ValueError, RecursionError):
        return False
    return (isinstance(meta, dict) and meta.get("seed") == seed
            and meta.get("generator") == fingerprint.code()
            and meta.get("sensors") == dataclasses.asdict(sensors)
            and meta.get("truth") == truth)


def _same_twin(meta_file: Path, seed: int, sensors: SensorModel, truth: dict) -> bool:
    """Whether a twin export is the ideal measurement of the run ``sensors`` measured."""
    if not _same(meta_file, seed, SensorModel.ideal(), truth):
        return False
    meta = json.loads(meta_file.read_text(encoding="utf-8"))
    return meta.get("twin_of") == dataclasses.asdict(sensors)


def generate_campaign(out_dir: Path, seed: int = 0, only: list[str] | None = None,
                      progress: Callable[[str], None] | None = None,
                      jobs: int = 1, executor: Executor | None = None,
                      sensors: SensorModel | None = None,
                      truth: str = DEFAULT, drift: bool = True,
                      twins: Path | None = None) -> list[Path]:
    """Generate the campaign's exports, skipping those already complete.

    Parameters
    ----------
    out_dir : Path
        Campaign folder; one sub-folder per manoeuvre.
    seed : int
        The campaign's seed.
    only : list of str, optional
        Names (or name prefixes) of the manoeuvres to make; all by default.
    progress : callable, optional
        Receives progress lines with counts and the time left.
    jobs : int
        Processes to use. Every manoeuvre has its own random numbers, so the
        files are the same for any number of jobs.
    executor : concurrent.futures.Executor, optional
        Where to simulate instead (a Dask cluster's, see
        :mod:`artic.validation.campaign.executors`); the files are written here.
    sensors : SensorModel, optional
        The measurement chain; :class:`SensorModel` by default,
        ``SensorModel.ideal()`` for the truth itself.
    truth : str
        One of :data:`artic.validation.synthetic.truth.TRUTHS`.
    drift : bool
        ``False``: the column's zero does not drift (see the module docstring).
    twins : Path, optional
        A folder for each manoeuvre's noise-free twin (:func:`noise_free_twin`),
        exported there under the same name: the same truth run measured with
        ideal sensors, made by the same simulation. A manoeuvre whose export or
        twin is missing or stale is simulated again and both are written.

    Returns
    -------
    list of Path
        The export folders; ``truth-LOAD.toml`` files are written beside them.

    See Also
    --------
    exports_as_written : the same, each manoeuvre's folders as they are written.
    """
    for _ in exports_as_written(out_dir, seed, only, progress, jobs, executor, sensors, truth,
                                drift, twins):
        pass
    return export_folders(out_dir, only)


def export_folders(out_dir: Path, only: list[str] | None = None) -> list[Path]:
    """The export folders of the manoeuvres ``only`` selects (all if none), in the matrix's order.

    Where :func:`generate_campaign` and :func:`exports_as_written` write them under
    ``out_dir``, whether made now or reused.
    """
    return [Path(out_dir) / m.name for m in selected(only)]


def exports_as_written(out_dir: Path, seed: int = 0, only: list[str] | None = None,
                       progress: Callable[[str], None] | None = None,
                       jobs: int = 1, executor: Executor | None = None,
                       sensors: SensorModel | None = None,
                       truth: str = DEFAULT, drift: bool = True,
                       twins: Path | None = None) -> Iterator[list[Path]]:
    """Generate the campaign's exports, yielding each manoeuvre's as it is written.

    The parameters are :func:`generate_campaign`'s. A caller reads each
    export while the workers simulate the next manoeuvres (the campaign
    imports them so, instead of on one core after the last).

    Yields
    ------
    list of Path
        One manoeuvre's export folders: the export, then its twin if
        ``twins``. Not the exports reused.
    """
    sensors = sensors or SensorModel()
    out_dir = Path(out_dir)
    if truth not in TRUTHS:
        raise UserError(f"truth {truth!r}: expected one of {', '.join(TRUTHS)}")
    check_only(only)  # before anything is made
    out_dir.mkdir(parents=True, exist_ok=True)
    write_truth_files(out_dir, seed, truth)
    todo = selected(only)
    config = truth_configuration(seed, truth, drift)
    missing = []
    for m in todo:
        meta = out_dir / m.name / META_FILE
        # Reuse only what this seed and this code made (see artic.validation.plumbing.fingerprint).
        twin = twins / m.name / META_FILE if twins is not None else None
        if not (meta.is_file() and _same(meta, seed, sensors, config)) or (
                twin is not None and not (twin.is_file()
                                          and _same_twin(twin, seed, sensors, config))):
            missing.append(m)
    if progress and len(missing) < len(todo):
        progress(f"{len(todo) - len(missing)} of {len(todo)} manoeuvres already generated")
    # Each result is written under the name of the manoeuvre submitted for it.
    # The longest first, so that no worker is left with one long drive at the end.
    missing.sort(key=lambda m: LONGEST_FIRST.index(m.kind))
    if twins is not None:
        twins = Path(twins)
        twins.mkdir(parents=True, exist_ok=True)
    tasks = [(m, (m, seed, sensors, truth, drift, twins is not None)) for m in missing]
    counter = Counter(len(missing), "generated", progress)
    with contextlib.closing(completed(_simulate_timed, tasks, jobs, executor)) as done:
        for m, (result, wall) in done:
            run, twin = result if twins is not None else (result, None)
            t = run.frame["t"]
            BUDGET.add("multibody", float(t.iloc[-1] - t.iloc[0]) if len(t) > 1 else 0.0)
            if twin is not None:  # first: a complete export then implies its twin
                write_export(twin, twins, name=m.name, meta_from=out_dir / m.name)
            write_export(run, out_dir, name=m.name)
            counter.step(f"{m.name} ({wall:.1f} s)")
            yield [out_dir / m.name] + ([twins / m.name] if twin is not None else [])
