"""The campaign's Rerun recordings, drawn on worker processes while the tables are made.

One ``.rrd`` per validated manoeuvre from its run files (and a plot of the
first docking and constant steer). Drawing them is Python work that holds the
GIL, so it runs on new local worker processes (``spawn``: not forks of the
campaign's process and its memory), local even with a Dask executor, whose
workers need not share this file system.

The recordings read only the logs, the tuned vehicles and the run files of the
validation and references stages. :class:`Recordings` therefore starts them
as soon as those exist, before the tables stage, which computes on one core
for about ten seconds: the workers draw on the other core meanwhile, and the
recordings stage then collects what they drew. What a recording holds does
not depend on when it is drawn.
"""

from __future__ import annotations

import contextlib
import multiprocessing
import os
from collections.abc import Sequence
from concurrent.futures import Future, ProcessPoolExecutor, as_completed
from pathlib import Path

import pandas as pd

from artic.mjcf.vehicle import Vehicle
from artic.validation.logs.runfile import Run, read_run
from artic.validation.plumbing.progress import Counter
from artic.validation.plumbing.workers import init_worker
from artic.validation.runs.validate import is_failed, stderr_progress


def record_one(target: Path, log: Run, run_paths: dict[str, Path], vehicle: Vehicle,
               rows: pd.DataFrame) -> int:
    """Write one manoeuvre's recording from its run files; returns its size [bytes]."""
    from artic.validation.review.recording import record_manoeuvre

    loaded = {m: read_run(p) for m, p in run_paths.items()}
    record_manoeuvre(target, log, loaded, vehicle, rows)
    return target.stat().st_size


class Recordings:
    """The recordings of a campaign's validated manoeuvres, drawn on worker processes.

    Parameters
    ----------
    out_dir : Path
        The campaign's output folder: run files in ``runs``, recordings to
        ``recordings``, plots to ``plots``.
    metrics : DataFrame
        The metrics against the logs (one row per log and model).
    logs : dict
        The logs by name.
    vehicles : dict
        The tuned vehicle of each load.
    models : sequence of str
        The campaign's models.
    jobs : int
        Worker processes.

    A recording newer than all its runs is kept. Construction starts the
    workers on what is left; :meth:`collect` waits for them; :meth:`close`
    (also on leaving a ``with`` block) stops them, cancelling what has not
    started.
    """

    def __init__(self, out_dir: Path, metrics: pd.DataFrame, logs: dict[str, Run],
                 vehicles: dict[str, Vehicle], models: Sequence[str], jobs: int = 1) -> None:
        self.out_dir = out_dir
        self.logs = logs
        names = list(dict.fromkeys(metrics["log"]))
        failed = {(r.log, r.model) for r in metrics.itertuples() if is_failed(r.status)}
        self.made: dict[str, Path] = {}
        self.todo: list[tuple[str, dict[str, Path], Path]] = []
        for name in names:
            runs = {m: out_dir / "runs" / f"{name}.{m}.parquet" for m in models
                    if (name, m) not in failed}
            if not runs:
                continue
            target = out_dir / "recordings" / f"{name}.rrd"
            self.made[name] = target
            newest = max(p.stat().st_mtime for p in runs.values())
            if not (target.is_file() and target.stat().st_mtime >= newest):
                self.todo.append((name, runs, target))
        self.kept = len(names) - len(self.todo)
        self._pool: ProcessPoolExecutor | None = None
        self._futures: dict[Future, Path] = {}
        if self.todo:
            self._pool = ProcessPoolExecutor(
                max_workers=max(1, min(jobs, len(self.todo))),
                mp_context=multiprocessing.get_context("spawn"),
                initializer=init_worker, initargs=(os.getpid(),))
            for name, runs, target in self.todo:
                log = logs[name]
                rows = metrics[metrics["log"] == name]
                vehicle = vehicles[log.meta.get("load", "unloaded")]
                self._futures[self._pool.submit(record_one, target, log, runs, vehicle,
                                                rows)] = target

    def collect(self) -> dict[str, Path]:
        """Wait for every recording, then draw the plots; every validated one by name."""
        from artic.validation.review.plots import plot_manoeuvre

        if self.kept:
            stderr_progress(f"{self.kept} of {self.kept + len(self.todo)} recordings reused "
                            f"from {self.out_dir / 'recordings'} (newer than their runs)")
        counter = Counter(len(self.todo), "recordings", stderr_progress)
        with contextlib.closing(self):
            for f in as_completed(self._futures):
                size = f.result()
                counter.step(f"{self._futures[f].name} ({size / 1e6:.1f} MB)")
        for name, runs, _ in self.todo:  # a plot of the first manoeuvre of each kind drawn
            log = self.logs[name]
            plot = self.out_dir / "plots" / f"{log.meta.get('manoeuvre')}.png"
            if log.meta.get("manoeuvre") in ("docking", "constant-steer") \
                    and not plot.is_file():
                plot_manoeuvre(plot, log, {m: read_run(p) for m, p in runs.items()})
        return self.made

    def close(self) -> None:
        """Stop the workers; recordings not yet started are not drawn."""
        if self._pool is not None:
            self._pool.shutdown(cancel_futures=True)
            self._pool = None

    def __enter__(self) -> Recordings:
        return self

    def __exit__(self, *exc: object) -> None:
        self.close()
