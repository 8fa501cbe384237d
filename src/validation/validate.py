"""Validate models against logs: harness, criteria, tables.

For each (log, model) pair the model runs through the closed-loop harness
and the criteria of eqs. (8)-(10) compare it with the log. The results are
one metrics row per pair and one run file per pair.
"""

from __future__ import annotations

import sys
import time
from collections.abc import Callable, Sequence
from pathlib import Path

import pandas as pd

from mjcf.vehicle import Vehicle
from reduced import MODELS as REDUCED_MODELS
from reduced.interface import Model
from validation.harness import DEFAULT_GAIN, run_closed_loop
from validation.logio import Run, atomic_write, write_run
from validation.metrics import CRITERIA, run_metrics


def model_factory(name: str) -> Callable[[Vehicle], Model]:
    """Constructor of a model by name: ``kin``, ``stm`` or ``mbd``.

    Raises
    ------
    ValueError
        For an unknown name.
    """
    if name in REDUCED_MODELS:
        return REDUCED_MODELS[name]
    if name == "mbd":
        from plant import Plant

        return Plant
    raise ValueError(f"unknown model {name!r}; choose from kin, stm, mbd")


def parse_models(text: str) -> list[str]:
    """Split ``"kin,stm"`` into model names and check each."""
    names = [m.strip() for m in text.split(",") if m.strip()]
    if not names:
        raise ValueError("no model given; use for example --models kin,stm")
    for n in names:
        model_factory(n)
    return names


def validate_runs(logs: Sequence[Run], vehicle: Vehicle, models: Sequence[str],
                  gain: float = DEFAULT_GAIN, out_dir: Path | None = None,
                  progress: Callable[[str], None] | None = None) -> pd.DataFrame:
    """Run every model on every log and compute the criteria.

    Parameters
    ----------
    logs : sequence of Run
        Measured (or synthetic) logs.
    vehicle : Vehicle
        Parameters the models are built from.
    models : sequence of str
        Model names.
    gain : float
        Reversing feedback gain K [rad/rad].
    out_dir : Path, optional
        If given, each model run is written to ``out_dir/runs/LOG.MODEL.parquet``.
    progress : callable, optional
        Receives one line per finished run.

    Returns
    -------
    DataFrame
        One row per (log, model): ``log, model``, the criteria, ``s_max``,
        ``status`` and ``wall_s``.
    """
    names = [log.name for log in logs]
    dupes = sorted({n for n in names if names.count(n) > 1})
    if dupes:
        raise ValueError(f"logs share the name(s) {', '.join(dupes)}; their results would "
                         "overwrite each other: rename the files")
    rows = []
    total = len(logs) * len(models)
    for i, log in enumerate(logs):
        for j, name in enumerate(models):
            t0 = time.perf_counter()
            model = model_factory(name)(vehicle)
            try:
                run = run_closed_loop(model, log, vehicle, gain)
            finally:
                close = getattr(model, "close", None)
                if close is not None:
                    close()
            wall = time.perf_counter() - t0
            row = {"log": log.name, "model": name, **run_metrics(log.frame, run.frame),
                   "status": run.meta["status"], "wall_s": wall,
                   "direction": log.meta.get("direction", ""),
                   "manoeuvre": log.meta.get("manoeuvre", "")}
            rows.append(row)
            if out_dir is not None:
                write_run(run, Path(out_dir) / "runs" / f"{log.name}.{name}.parquet")
            if progress is not None:
                k = i * len(models) + j + 1
                note = "" if run.meta["status"] == "ok" else f" - {run.meta['status']}"
                progress(f"[{k}/{total}] {log.name} / {name}: eps_p = {row['eps_p']:.3f} m, "
                         f"eps_n = {row['eps_n']:.1f} %, J_steer = {row['J_steer']:.1f} % "
                         f"({wall:.2f} s){note}")
    cols = ["log", "model", "direction", "manoeuvre", *CRITERIA, "s_max", "status", "wall_s"]
    return pd.DataFrame(rows, columns=cols)


def write_metrics(df: pd.DataFrame, path: Path) -> Path:
    """Write a metrics table as CSV, atomically."""
    return atomic_write(path, lambda p: df.to_csv(p, index=False, float_format="%.6g"))


def summary_table(metrics: pd.DataFrame, columns: Sequence[str]) -> pd.DataFrame:
    """Mean of the chosen criteria per model, as the seed's Tables 2 and 3."""
    return metrics.groupby("model", sort=False)[list(columns)].mean()


def markdown_table(df: pd.DataFrame, digits: int = 4) -> str:
    """Render a small frame as a Markdown table (no extra dependency)."""
    head = [df.index.name or "", *map(str, df.columns)]
    lines = ["| " + " | ".join(head) + " |", "|" + "---|" * len(head)]
    for idx, row in df.iterrows():
        cells = [f"{v:.{digits}g}" if isinstance(v, float) else str(v) for v in row]
        lines.append("| " + " | ".join([str(idx), *cells]) + " |")
    return "\n".join(lines)


def stderr_progress(line: str) -> None:
    """Print a progress line to standard error."""
    print(line, file=sys.stderr, flush=True)
