"""Computational efficiency: wall time per simulated second of each model.

The paper reports its kinematic model 90 % and its single-track model 60 %
faster than its multibody model, that is wall-time ratios KIN/MBD = 0.1 and
STM/MBD = 0.4. Here every model runs the same logs through the same harness,
so the ratios come from one run on one machine.

The figures time the validation runs themselves, which the campaign makes
anyway: each (log, model) run records the wall time of its harness run
(``wall_s`` in ``metrics.csv`` and in its run file) and of building its model
(``build_s`` in the run file's metadata), and the stage adds them up per
model over every validated log. No run is made for the figures alone. The
runs are those of the validation, ``jobs`` at a time on as many threads:
each is timed on its own thread, whose core it has to itself when there are
as many cores as jobs (the plant's compiled loop runs without the GIL; two
threads run 1.95 times as fast as one, ``docs/design/speed.md``).
"""

from __future__ import annotations

from collections.abc import Sequence
from pathlib import Path

import numpy as np
import pandas as pd
import pyarrow as pa
import pyarrow.parquet as pq

from artic.validation.logs.runfile import META_KEY, LogError, parse_meta

PAPER_RATIO = {"kin": 0.1, "stm": 0.4, "mbd": 1.0}
"""Wall-time ratio to the multibody model reported by the paper (90 % and 60 % faster)."""


def build_time(path: Path) -> float:
    """The model construction time a run file records (``meta["build_s"]``) [s]; NaN if none."""
    try:
        raw = (pq.read_metadata(path).metadata or {}).get(META_KEY)
        meta = parse_meta(raw, str(path)) if raw else {}
    except (pa.ArrowInvalid, OSError, LogError):
        return float("nan")
    value = meta.get("build_s")
    return float(value) if isinstance(value, int | float) else float("nan")


def from_runs(metrics: pd.DataFrame, models: Sequence[str],
              runs_dir: Path | None = None) -> pd.DataFrame:
    """Each model's efficiency from the validation runs' own times.

    Parameters
    ----------
    metrics : DataFrame
        Validation rows (``metrics.csv``): ``log``, ``model``, ``status``,
        ``wall_s`` (the harness run, construction excluded) and
        ``duration_s`` (its simulated time).
    models : sequence of str
        Models to report, one row each (a model without a timed run has NaN).
    runs_dir : Path, optional
        The run files' folder (``OUT/runs``), for the construction times.

    Returns
    -------
    DataFrame
        Per model: ``runs`` (timed runs), ``simulated_s``, ``build_s``
        (construction, mean per run), ``wall_s`` (stepping), ``wall_per_sim_s``,
        ``real_time_factor``, and ``ratio_to_mbd`` with the paper's
        ``paper_ratio`` beside it.
    """
    from artic.validation.runs.validate import is_failed

    rows = []
    for name in models:
        part = metrics[(metrics["model"] == name) & ~metrics["status"].map(is_failed)
                       & (metrics["duration_s"] > 0)]
        sim, wall = float(part["duration_s"].sum()), float(part["wall_s"].sum())
        builds = [build_time(Path(runs_dir) / f"{log}.{name}.parquet")
                  for log in part["log"]] if runs_dir is not None else []
        build = float(np.nanmean(builds)) if np.isfinite(builds).any() else float("nan")
        rows.append({"model": name, "runs": len(part), "simulated_s": sim, "build_s": build,
                     "wall_s": wall,
                     "wall_per_sim_s": wall / sim if sim > 0 else float("nan"),
                     "real_time_factor": sim / wall if wall > 0 else float("nan")})
    out = pd.DataFrame(rows).set_index("model")
    if "mbd" in out.index:
        out["ratio_to_mbd"] = out["wall_per_sim_s"] / out.loc["mbd", "wall_per_sim_s"]
        out["paper_ratio"] = [PAPER_RATIO.get(m, float("nan")) for m in out.index]
    return out
