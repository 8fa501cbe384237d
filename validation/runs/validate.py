"""Validate models against logs: harness, criteria, tables.

For each (log, model) pair the model runs through the closed-loop harness
and the criteria of eqs. (8)-(10) compare it with the log, with the criteria
beyond the paper's (:mod:`artic.validation.criteria`): the articulation error,
the noise-robust ``eps_n_fixed``, the open-loop prediction errors of reverse
logs (the same model, reset at points along the log) and the dock errors of
docking and parking runs. The results are one metrics row per pair and one
run file per pair.

A pair that fails (the plant diverges, the vehicle or tyre file is refused
for that model, the steering map folds inside the log's range) does not stop
the batch: its row carries the status ``failed: ...`` or ``refused: ...``
with the message, its criteria are empty (NaN), and its run file holds no
samples, so that a resumed batch reuses the failure instead of repeating it.
"""

from __future__ import annotations

import dataclasses
import time
from collections.abc import Callable, Sequence
from concurrent.futures import Executor, ThreadPoolExecutor
from pathlib import Path
from typing import Any

import numpy as np
import pandas as pd
import pyarrow as pa
import pyarrow.parquet as pq

from artic.mjcf.errors import UserError, one_line
from artic.mjcf.vehicle import Vehicle
from artic.validation.criteria import columns as extra
from artic.validation.criteria.direction import direction_of
from artic.validation.criteria.fixedscale import Scale, campaign_scale, eps_n_fixed
from artic.validation.criteria.metrics import CRITERIA, run_metrics
from artic.validation.criteria.prediction import TruthStates, prediction_errors, truth_states
from artic.validation.harness.loop import DEFAULT_GAIN, run_closed_loop
from artic.validation.logs.runfile import (
    META_KEY,
    SINGLE_SIGNALS,
    LogError,
    Run,
    atomic_write,
    parse_meta,
    write_run,
)
from artic.validation.logs.schema import COLUMNS, MODEL_SIGNALS
from artic.validation.models import build, close, spec
from artic.validation.plumbing.budget import BUDGET
from artic.validation.plumbing.progress import Counter, stderr
from artic.validation.synthetic.floor import floor_replay

FAILED = ("failed", "refused")
"""Status prefixes of a (log, model) pair without a result."""


def is_failed(status: str) -> bool:
    """Whether a run's status says it has no result (see :data:`FAILED`)."""
    return str(status).startswith(FAILED)


@dataclasses.dataclass(frozen=True)
class RunOptions:
    """How :func:`validate_runs` runs its pairs and what it reports (see its parameters).

    One object for the options that travel together from the campaign's stages
    and the command line; :func:`validate_runs` takes them as keywords as well.
    """

    progress: Callable[[str], None] | None = None
    reuse_key: str | None = None
    jobs: int = 1
    executor: Executor | None = None
    label: str = "validation"
    scale: Scale | None = None
    samples: bool = True
    replays: dict | None = None


def run_options(options: RunOptions | None, keywords: dict) -> RunOptions:
    """``options`` with ``keywords`` (fields of :class:`RunOptions`) in place of its own.

    Raises
    ------
    TypeError
        For a keyword that is no field of :class:`RunOptions`, naming it and the fields.
    """
    fields = {f.name for f in dataclasses.fields(RunOptions)}
    wrong = sorted(set(keywords) - fields)
    if wrong:
        raise TypeError(f"validate_runs() got unexpected keyword(s) {', '.join(wrong)}; "
                        f"it takes {', '.join(sorted(fields))} (or options=RunOptions(...))")
    return dataclasses.replace(options or RunOptions(), **keywords)


def validate_runs(logs: Sequence[Run], vehicle: Vehicle | Callable[[Run], Vehicle],
                  models: Sequence[str],
                  gain: float = DEFAULT_GAIN, out_dir: Path | None = None,
                  options: RunOptions | None = None, **keywords: Any) -> pd.DataFrame:
    """Run every model on every log and compute the criteria.

    Parameters
    ----------
    logs : sequence of Run
        Measured (or synthetic) logs.
    vehicle : Vehicle or callable
        Parameters the models are built from, or a function giving them per
        log (the floor's truth, whose yard slope changes per manoeuvre).
    models : sequence of str
        Model names.
    gain : float
        Reversing feedback gain K [rad/rad].
    out_dir : Path, optional
        If given, each model run is written to ``out_dir/runs/LOG.MODEL.parquet``.
    options : RunOptions, optional
        The options below as one object; each may be given as a keyword instead
        (``jobs=4``), which takes the place of the object's.
    samples : bool
        With ``out_dir``: write the runs' samples (single precision, see
        :data:`SINGLE`); ``False`` writes only their metadata (criteria, key,
        status; ``meta["samples"]`` the rows the run had), which is all a
        resumed campaign reads (the noise-free twins' runs: the tables need
        their criteria only, and ``artic validate`` on a twin log makes a
        twin run again).
    progress : callable, optional
        Receives progress lines (counts and the time left, see
        :class:`artic.validation.plumbing.progress.Counter`), one line for the runs reused,
        and one line per run whose model had to limit something
        (:mod:`artic.validation.harness.plantnotes`) or stopped early.
    reuse_key : str, optional
        With ``out_dir``: a run file already there whose ``meta["key"]`` is
        this key plus the model is read instead of simulated again (resuming
        a campaign). New run files carry the key.
    jobs : int
        Threads; each run is independent, so the rows equal a serial run's.
    executor : concurrent.futures.Executor, optional
        Simulate there instead (see :mod:`artic.validation.campaign.executors`); files are
        written here.
    label : str
        What the progress lines call this batch (a load condition, say).
    scale : dict, optional
        The fixed scale of ``eps_n_fixed``
        (:func:`artic.validation.criteria.fixedscale.campaign_scale`); from
        ``logs`` when not given. A campaign gives the one of all its logs.
    replays : dict, optional
        The floor's replay runs of its open-loop predictions
        (:class:`artic.validation.criteria.prediction.ReplayRuns`), by log name:
        those of the floor's runs simulated here are put in it, and those it
        holds are reused where they fit (the campaign's noise-free twins reuse
        the measured logs'; the rows are the same to the bit).

    Returns
    -------
    DataFrame
        One row per (log, model): ``log, model``, the criteria and the
        :data:`artic.validation.criteria.columns.COLUMNS`, ``s_max``,
        ``status``, ``wall_s`` (the harness run, model construction and the
        open-loop predictions excluded) and ``duration_s`` (simulated time).
        ``attrs["scale"]`` holds the scale used.

    See Also
    --------
    artic.run_closed_loop : one model on one log.
    artic.run_metrics : the criteria of one run.
    artic.run_campaign : the synthetic campaign.

    Examples
    --------
    KIN and the STM on a log the STM made: the STM follows it within centimetres
    (the harness smooths the log's speed), KIN is a metre off:

    >>> import artic
    >>> vehicle = artic.load_vehicle("gosar2022-unloaded")
    >>> log = artic.simulate(artic.STM(vehicle), vehicle,
    ...                      artic.make_profile("constant-steer", speed_kph=15, duration=10.0))
    >>> log.meta["name"] = "stm-made"
    >>> table = artic.validate_runs([log], vehicle, ["kin", "stm"]).set_index("model")
    >>> bool(table.loc["stm", "eps_p"] < 0.05 < 0.5 < table.loc["kin", "eps_p"])  # [m]
    True
    """
    o = run_options(options, keywords)
    progress, reuse_key, jobs, executor = o.progress, o.reuse_key, o.jobs, o.executor
    label, scale, samples, replays = o.label, o.scale, o.samples, o.replays
    names = [log.name for log in logs]
    dupes = sorted({n for n in names if names.count(n) > 1})
    if dupes:
        raise UserError(f"logs share the name(s) {', '.join(dupes)}; their results would "
                         "overwrite each other: rename the files")
    tasks = [(log, name) for log in logs for name in models]
    if scale is None:
        scale = campaign_scale(logs)

    def probe(task):
        return _reusable(*_where(out_dir, task[0], task[1], reuse_key, gain))

    with ThreadPoolExecutor(max(1, jobs)) as pool:  # pyarrow reads without the GIL
        found = {(log.name, name): run for (log, name), run in zip(tasks, pool.map(probe, tasks),
                                                                   strict=True)}
    found = {k: run for k, run in found.items() if run is not None}
    reused = set(found)
    if progress is not None and reused:
        progress(f"{label}: {len(reused)} of {len(tasks)} runs reused from "
                 f"{Path(out_dir) / 'runs'} (made earlier with the same code and settings)")
    counter = Counter(len(tasks) - len(reused), label, progress)

    remote: dict = {}

    def one(task):
        log, name = task
        target, key = _where(out_dir, log, name, reuse_key, gain)
        meta = found.pop((log.name, name), None)
        fresh = meta is None
        if fresh:
            got = remote.pop((log.name, name), None)
            run, wall = got if got is not None else _simulate(name, log, vehicle, gain,
                                                              *_shared(replays, log, name))
            meta = run.meta
            kept = meta.get("prediction", {}).pop(REPLAYS, None)
            if kept is not None and replays is not None:
                replays[log.name] = kept
            meta["wall_s"] = wall
            if log.meta.get("accepted_checks"):
                meta["accepted_checks"] = log.meta["accepted_checks"]
            if key is not None:
                meta["key"] = key
            meta["criteria"] = _criteria(log, run, _resolve(vehicle, log))
            meta["rows"] = len(run.frame) if samples else 0
            if not samples:
                meta["samples"] = len(run.frame)
            if target is not None:
                kept = _thin_extras(run.frame) if samples else run.frame.iloc[:0]
                write_run(Run(kept, meta), target, single=SINGLE)
        wall = float(meta["wall_s"])
        criteria = dict(meta["criteria"])
        duration = criteria.pop("duration_s")
        criteria["eps_n_fixed"] = eps_n_fixed(criteria["eps_a"], criteria["eps_v"],
                                              scale.get(direction_of(log)))
        row = {"log": log.name, "model": name, **criteria,
               "status": meta["status"], "wall_s": wall, "duration_s": duration,
               "direction": log.meta.get("direction", ""),
               "manoeuvre": log.meta.get("manoeuvre", "")}
        if fresh:
            notes = [meta["status"]] if meta["status"] != "ok" else []
            if meta.get("limited"):
                notes.append("limited: " + meta["limited"])
            why = meta.get("prediction", {}).get("note", "")
            if why and why != "not a reverse log":
                notes.append("open-loop prediction: " + why)
            counter.step(f"{log.name} / {name}: eps_n = {row['eps_n']:.1f} %, eps_gamma = "
                         f"{np.degrees(row['eps_gamma']):.2f} deg ({wall:.1f} s)"
                         + "".join(f"; {n}" for n in notes), always=bool(notes))
        return row

    # The longest logs start first, so that no thread is left with one long run at the end.
    order = sorted(range(len(tasks)), key=lambda i: -_duration(tasks[i][0]))
    longest_first = [tasks[i] for i in order]
    if executor is not None:
        # Simulate remotely what cannot be reused; everything else happens here.
        todo = {}
        for log, name in longest_first:
            if (log.name, name) in reused:
                continue
            v = _resolve(vehicle, log)  # pickles
            todo[(log.name, name)] = executor.submit(_simulate_counted, name, log, v, gain,
                                                     *_shared(replays, log, name))
        for k, f in todo.items():
            run, wall, counted = f.result()
            BUDGET.merge(counted)  # what the worker simulated, in this process's count
            remote[k] = (run, wall)
        rows = [one(t) for t in tasks]
    elif jobs > 1:
        with ThreadPoolExecutor(jobs) as pool:
            done = dict(zip(order, pool.map(one, longest_first), strict=True))
        rows = [done[i] for i in range(len(tasks))]
    else:
        rows = [one(t) for t in tasks]
    cols = ["log", "model", "direction", "manoeuvre", *CRITERIA, *extra.COLUMNS, "s_max",
            "status", "wall_s", "duration_s"]
    out = pd.DataFrame(rows, columns=cols)
    out.attrs["reused"] = len(reused)
    out.attrs["scale"] = scale
    return out


REPLAYS = "replays"
"""The key of a floor's replay runs in a fresh run's ``meta["prediction"]`` (never written)."""


def _shared(replays: dict | None, log: Run, name: str) -> tuple:
    """The extra arguments of :func:`_simulate` for sharing the floor's replay runs, or none."""
    if replays is None or not spec(name).reference:
        return ()
    return (replays.get(log.name, True),)


def _resolve(vehicle: Vehicle | Callable[[Run], Vehicle], log: Run) -> Vehicle:
    """The vehicle of ``log``'s models: ``vehicle`` itself, or its value for the log."""
    return vehicle if isinstance(vehicle, Vehicle) else vehicle(log)


def _duration(log: Run) -> float:
    """A log's duration [s] (0 for one without samples)."""
    t = log.frame["t"]
    return float(t.iloc[-1] - t.iloc[0]) if len(t) else 0.0


def _where(out_dir, log: Run, name: str, reuse_key: str | None,
           gain: float) -> tuple[Path | None, str | None]:
    """Run file and reuse key of one (log, model) pair."""
    target = None if out_dir is None else Path(out_dir) / "runs" / f"{log.name}.{name}.parquet"
    key = None if reuse_key is None else f"{reuse_key}.{name}.{gain:g}"
    return target, key


def _criteria(log: Run, run: Run, vehicle: Vehicle) -> dict[str, float]:
    """The criteria of a model run against its log, and the simulated time ``duration_s``.

    The paper's, every criterion of :data:`artic.validation.criteria.columns.TABLE`
    computed from the log and the run (the articulation error, the dock errors),
    and the open-loop prediction errors the run brought in ``meta["prediction"]``
    (see :func:`_simulate`); ``eps_n_fixed`` needs the whole set's scale and is
    added per row.
    """
    t = log.frame["t"]
    nan = {c: float("nan") for c in (*CRITERIA, *extra.COLUMNS) if c != "eps_n_fixed"}
    if is_failed(run.meta["status"]) or len(run.frame) < 2:
        return nan | {"s_max": 0.0, "duration_s": 0.0}
    out = {k: float(v) for k, v in run_metrics(log.frame, run.frame, beyond=False).items()}
    out |= extra.of_run(log, run, vehicle)
    pred = run.meta.get("prediction", {})
    out |= {c: float(pred.get(c, float("nan"))) for c in extra.COLUMNS
            if extra.COMPUTE[c] == "model"}
    return out | {"duration_s": float(t.iloc[len(run.frame) - 1] - t.iloc[0])}


def _reusable(target: Path | None, key: str | None) -> dict | None:
    """The metadata of the run file at ``target`` if it was made with ``key`` (a failure's too).

    A run file carries its criteria against its log (``meta["criteria"]``),
    computed when it was simulated; the key covers the log, the code and the
    settings, so a resumed campaign takes them from the file's footer without
    reading its samples. The footer must parse (a truncated file does not) and
    its row count must be the run's; anything else is simulated again.
    """
    if target is None or key is None or not target.is_file():
        return None
    try:
        info = pq.read_metadata(target)
        raw = (info.metadata or {}).get(META_KEY)
        meta = parse_meta(raw, str(target)) if raw else {}
    except (pa.ArrowInvalid, OSError, LogError):  # unreadable or foreign: simulate again
        return None
    if meta.get("key") != key or not {"wall_s", "status", "criteria", "rows"} <= meta.keys():
        return None
    if info.num_rows != meta["rows"] or not isinstance(meta["criteria"], dict):
        return None
    return meta


def _simulate(name: str, log: Run, vehicle: Vehicle | Callable[[Run], Vehicle],
              gain: float, share=None) -> tuple[Run, float]:
    """One harness run; returns the run and its wall time without model construction [s].

    ``vehicle`` may be a function of the log (the floor's truth). A failure is
    returned as a run without samples whose status says what failed (see the
    module docstring); nothing is raised for it. What the model had to limit
    (the plant's warnings) is in ``meta["limited"]`` as one line, not printed.
    The same model then makes the open-loop predictions of a reverse log
    (:func:`artic.validation.criteria.prediction.prediction_errors`), into
    ``meta["prediction"]``; their wall time is there, not in the one returned.
    ``share``: the floor's replay runs to return (``True``) or reuse
    (:func:`artic.validation.criteria.prediction.prediction_errors`).
    """
    # Here, not at the top: the notes load MuJoCo, which a reduced model's run needs not.
    from artic.validation.harness.plantnotes import collect, summary

    t0 = time.perf_counter()
    if not isinstance(vehicle, Vehicle):
        vehicle = vehicle(log)
    try:
        with collect() as notes:
            t_build = time.perf_counter()
            model = build(name, vehicle, log)
            try:
                t0 = time.perf_counter()
                build_s = t0 - t_build
                run = run_closed_loop(model, log, vehicle, gain)
                wall = time.perf_counter() - t0
                run.meta["prediction"] = _predict(model, log, vehicle, name, share)
            finally:
                close(model)
    except (MemoryError, RecursionError):
        raise
    except ValueError as exc:  # the model refuses its input: vehicle, tyre, steering range
        return failed_run(log, name, vehicle, gain, f"refused: {one_line(exc)}"), \
            time.perf_counter() - t0
    except Exception as exc:  # noqa: BLE001 - a diverging plant, or any other failure
        what = "" if type(exc).__name__ == "PlantError" else f"{type(exc).__name__}: "
        return failed_run(log, name, vehicle, gain, f"failed: {what}{one_line(exc)}"), \
            time.perf_counter() - t0
    if notes:
        run.meta["limited"] = summary(notes)
    run.meta["build_s"] = build_s  # for the efficiency figures (campaign.efficiency)
    return run, wall


def _simulate_counted(name: str, log: Run, vehicle: Vehicle | Callable[[Run], Vehicle],
                      gain: float, *share) -> tuple[Run, float, dict]:
    """:func:`_simulate` on an executor, with what it simulated (a ``Budget.scope``)."""
    with BUDGET.scope() as counted:
        run, wall = _simulate(name, log, vehicle, gain, *share)
    return run, wall, counted


def _predict(model, log: Run, vehicle: Vehicle, name: str, share=None) -> dict:
    """:func:`prediction_errors`, or NaN with the reason when the model fails in one.

    The floor (the reference row) starts from the truth's states the log
    holds (:func:`artic.validation.criteria.prediction.truth_states`); a truth
    that has states (``set_full_state``) but whose log holds none leaves
    every start point out rather than start with its hidden states zeroed.
    Started, it replays the truth's own recorded actuation
    (:func:`artic.validation.synthetic.floor.floor_replay`); a log without one has it
    driven by the harness's speed follower, and its note says so.
    """
    replay = None
    try:
        states = truth_states(log.meta) if spec(name).reference else None
        if states is None and spec(name).reference and hasattr(model, "set_full_state"):
            states = TruthStates(np.zeros(0), np.zeros((0, 0)))
        if states is not None and states.t.size:
            replay = floor_replay(vehicle, log)  # the truth's own pedals and steering
        out = prediction_errors(replay or model, log, vehicle, states=states,
                                share=share if replay is not None else None)
        if states is not None and states.t.size and replay is None and out["starts"]:
            out["note"] = "; ".join(filter(None, [out["note"], FOLLOWED]))
        return out
    except (MemoryError, RecursionError):
        raise
    except Exception as exc:  # noqa: BLE001 - a diverging plant from one start point
        return {c: float("nan") for c in extra.COLUMNS if extra.COMPUTE[c] == "model"} | {
            "note": f"failed: {one_line(exc)}"}
    finally:
        if replay is not None:
            replay.close()


FOLLOWED = ("the floor's speed follows the log through the harness's follower: the log "
            "holds no recorded actuation of the truth (generate it again)")
"""The floor's prediction note on a log made before the truth's actuation was recorded."""


def failed_run(log: Run, name: str, vehicle: Vehicle, gain: float, status: str) -> Run:
    """A run without samples that records why the pair has no result."""
    frame = pd.DataFrame({c: np.zeros(0) for c in (*COLUMNS, *MODEL_SIGNALS)})
    frame["delta_saturated"] = frame["delta_saturated"].astype(bool)
    meta = {"name": f"{log.name}.{name}", "source": f"model:{name}", "log": log.name,
            "model": name, "gain": float(gain), "vehicle": vehicle.name,
            "vehicle_path": vehicle.path, "status": status,
            **{k: log.meta[k] for k in ("manoeuvre", "direction", "load", "accepted_checks")
               if k in log.meta}}
    return Run(frame, meta)


EXTRAS_RATE = 5.0
"""Samples per second at which run files keep the plant's extra columns [Hz].

The harness records them at every sample; the recordings draw the yard and
plot the tyres at 5 Hz (:data:`artic.validation.review.recording.YARD_RATE`),
and the full rate would make a plant run file ten times larger. The rows
between hold NaN (stored as nulls)."""


SINGLE = (*SINGLE_SIGNALS, "delta", "delta_fb")
"""A model run's columns its file stores in single precision (float32; why that
suffices: :data:`artic.validation.logs.runfile.SINGLE_SIGNALS`): every signal
but the time. Its criteria are computed from the run in double precision
before it is written (``meta["criteria"]``, what the tables read); the file
serves inspection, the recordings and the pooled criteria of ``artic
validate``. The plant's runs are stored so too, and the campaign reads them
back as the reduced models' reference (``metrics_vs_plant.csv``): the
comparisons against the plant are computed from the rounded run, the same on a
fresh and on a resumed campaign (0.03 mm on a 300 m yard: a p value of two
manoeuvres may move in its last printed digit, no interval or ranking)."""


def _thin_extras(frame: pd.DataFrame) -> pd.DataFrame:
    """``frame`` with the plant's extra columns kept at :data:`EXTRAS_RATE` only."""
    extra = [c for c in frame.columns if c not in COLUMNS and c not in MODEL_SIGNALS]
    if not extra or len(frame) < 2:
        return frame
    t = frame["t"].to_numpy()
    every = max(1, round(1.0 / (EXTRAS_RATE * float(np.median(np.diff(t))))))
    out = frame.copy()
    out.loc[np.arange(len(frame)) % every != 0, extra] = np.nan
    return out


def write_metrics(df: pd.DataFrame, path: Path) -> Path:
    """Write a metrics table as CSV, atomically."""
    return atomic_write(path, lambda p: df.to_csv(p, index=False, float_format="%.6g"))


stderr_progress = stderr
"""Print a progress line to standard error (:func:`artic.validation.plumbing.progress.stderr`)."""
