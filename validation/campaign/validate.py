"""Validate models against logs: harness, criteria, tables.

For each (log, model) pair the model runs through the closed-loop harness
and the criteria of eqs. (8)-(10) compare it with the log. The results are
one metrics row per pair and one run file per pair.
"""

from __future__ import annotations

import sys
import threading
import time
from collections.abc import Callable, Sequence
from concurrent.futures import Executor, ThreadPoolExecutor
from pathlib import Path

import pandas as pd

from mjcf.vehicle import Vehicle
from validation.harness import DEFAULT_GAIN, run_closed_loop
from validation.logs.runfile import Run, atomic_write, read_run, write_run
from validation.metrics import CRITERIA, run_metrics
from validation.models import build


def validate_runs(logs: Sequence[Run], vehicle: Vehicle | Callable[[Run], Vehicle],
                  models: Sequence[str],
                  gain: float = DEFAULT_GAIN, out_dir: Path | None = None,
                  progress: Callable[[str], None] | None = None,
                  reuse_key: str | None = None, jobs: int = 1,
                  executor: Executor | None = None) -> pd.DataFrame:
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
    progress : callable, optional
        Receives one line per finished run.
    reuse_key : str, optional
        With ``out_dir``: a run file already there whose ``meta["key"]`` is
        this key plus the model is read instead of simulated again (resuming
        a campaign). New run files carry the key.
    jobs : int
        Threads; each run is independent, so the rows equal a serial run's.
    executor : concurrent.futures.Executor, optional
        Simulate there instead (see :mod:`validation.campaign.executors`); files are
        written here.

    Returns
    -------
    DataFrame
        One row per (log, model): ``log, model``, the criteria, ``s_max``,
        ``status``, ``wall_s`` (the harness run, model construction excluded)
        and ``duration_s`` (simulated time).
    """
    names = [log.name for log in logs]
    dupes = sorted({n for n in names if names.count(n) > 1})
    if dupes:
        raise ValueError(f"logs share the name(s) {', '.join(dupes)}; their results would "
                         "overwrite each other: rename the files")
    tasks = [(log, name) for log in logs for name in models]
    done = [0]
    lock = threading.Lock()

    remote: dict = {}

    def one(task):
        log, name = task
        target, key = _where(out_dir, log, name, reuse_key, gain)
        run = _reusable(target, key)
        if run is None:
            got = remote.pop((log.name, name), None)
            run, wall = got if got is not None else _simulate(name, log, vehicle, gain)
            run.meta["wall_s"] = wall
            if key is not None:
                run.meta["key"] = key
            if target is not None:
                write_run(run, target)
        wall = float(run.meta["wall_s"])
        t = log.frame["t"]
        row = {"log": log.name, "model": name, **run_metrics(log.frame, run.frame),
               "status": run.meta["status"], "wall_s": wall,
               "duration_s": float(t.iloc[len(run.frame) - 1] - t.iloc[0]),
               "direction": log.meta.get("direction", ""),
               "manoeuvre": log.meta.get("manoeuvre", "")}
        if progress is not None:
            with lock:
                done[0] += 1
                note = "" if run.meta["status"] == "ok" else f" - {run.meta['status']}"
                progress(f"[{done[0]}/{len(tasks)}] {log.name} / {name}: eps_p = "
                         f"{row['eps_p']:.3f} m, eps_n = {row['eps_n']:.1f} %, J_steer = "
                         f"{row['J_steer']:.1f} % ({wall:.2f} s){note}")
        return row

    if executor is not None:
        # Simulate remotely what cannot be reused; everything else happens here.
        todo = {}
        for task in tasks:
            log, name = task
            target, key = _where(out_dir, log, name, reuse_key, gain)
            if _reusable(target, key) is None:
                v = vehicle if isinstance(vehicle, Vehicle) else vehicle(log)  # pickles
                todo[(log.name, name)] = executor.submit(_simulate, name, log, v, gain)
        remote.update({k: f.result() for k, f in todo.items()})
        rows = [one(t) for t in tasks]
    elif jobs > 1:
        with ThreadPoolExecutor(jobs) as pool:
            rows = list(pool.map(one, tasks))
    else:
        rows = [one(t) for t in tasks]
    cols = ["log", "model", "direction", "manoeuvre", *CRITERIA, "s_max", "status", "wall_s",
            "duration_s"]
    return pd.DataFrame(rows, columns=cols)


def _where(out_dir, log: Run, name: str, reuse_key: str | None,
           gain: float) -> tuple[Path | None, str | None]:
    """Run file and reuse key of one (log, model) pair."""
    target = None if out_dir is None else Path(out_dir) / "runs" / f"{log.name}.{name}.parquet"
    key = None if reuse_key is None else f"{reuse_key}.{name}.{gain:g}"
    return target, key


def _reusable(target: Path | None, key: str | None) -> Run | None:
    """The run file at ``target`` if it was made with ``key``."""
    if target is None or key is None or not target.is_file():
        return None
    try:
        run = read_run(target)
    except ValueError:  # unreadable or foreign: simulate again, overwrite
        return None
    return run if run.meta.get("key") == key and "wall_s" in run.meta else None


def _simulate(name: str, log: Run, vehicle: Vehicle | Callable[[Run], Vehicle],
              gain: float) -> tuple[Run, float]:
    """One harness run; returns the run and its wall time without model construction [s]."""
    if not isinstance(vehicle, Vehicle):
        vehicle = vehicle(log)
    model = build(name, vehicle)
    try:
        t0 = time.perf_counter()
        run = run_closed_loop(model, log, vehicle, gain)
        return run, time.perf_counter() - t0
    finally:
        model.close()


def write_metrics(df: pd.DataFrame, path: Path) -> Path:
    """Write a metrics table as CSV, atomically."""
    return atomic_write(path, lambda p: df.to_csv(p, index=False, float_format="%.6g"))


def stderr_progress(line: str) -> None:
    """Print a progress line to standard error."""
    print(line, file=sys.stderr, flush=True)
