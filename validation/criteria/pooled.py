"""The criteria of a log split at its gaps, pooled over its segments by distance.

A mapped log with gaps is imported as gap-free segments
(:mod:`artic.validation.logs.assemble`), each validated on its own: every
model starts each segment from the measured state, as it starts every log.
The log's criteria are then those of eqs. (8)-(10) over all its segments
together, each segment weighted by the distance ``s_k`` it covers (the
integrals of eq. (8) add over disjoint stretches of road):

- a distance-RMS error: ``eps = sqrt(sum s_k eps_k**2 / sum s_k)``, exact;
- the totals of eq. (9): sums of the pooled components;
- ``eps_n``: the pooled ``eps_a`` and ``eps_v`` over the pooled
  distance-means of ``|r|`` and ``|v_y|`` (``sum s_k m_k / sum s_k``);
- ``J_steer``: the pooled distance-RMS of ``delta_fb`` over the pooled
  distance-mean of ``|delta_center|``;
- the criteria beyond the paper's as their row of
  :data:`artic.validation.criteria.columns.TABLE` says: ``eps_gamma`` is a
  distance-RMS error like the others; ``eps_n_fixed`` comes from the pooled
  ``eps_a`` and ``eps_v`` on the set's fixed scale; the open-loop prediction
  errors ``pred_*`` are means over start points placed every
  :data:`artic.validation.criteria.prediction.SPACING` metres, so their count
  is the distance's and the pooled mean is the distance-weighted mean of the
  segments' (those with a value); the dock errors ``dock_*`` are the last
  segment's, where the log ends at the dock.

The distance-means are taken from the segments' logs and run files over the
samples each run compared.
"""

from __future__ import annotations

import math
from collections.abc import Sequence
from pathlib import Path

import numpy as np
import pandas as pd

from artic.validation.criteria import columns as extra
from artic.validation.criteria.fixedscale import eps_n_fixed
from artic.validation.criteria.metrics import (
    CRITERIA,
    NOISE_FLOOR,
    distance_mean_abs,
    distance_weights,
)
from artic.validation.logs.runfile import LogError, Run, read_run

RMS = ("eps_y1", "eps_y2", "eps_r1", "eps_r2", "eps_vy1", "eps_vy2",
       *(c for c in extra.COLUMNS if extra.POOL[c] == "rms"))
"""The criteria that are distance-RMS errors, eq. (8)."""

POOLED = (*CRITERIA, *extra.COLUMNS)
"""Every criterion column a pooled row has."""


def segment_of(log: Run) -> dict | None:
    """The ``meta["segment"]`` of a log split at its gaps (``log``, ``index``, ``of``), or None."""
    seg = log.meta.get("segment")
    return seg if isinstance(seg, dict) and "log" in seg else None


def _means(log: Run, runs_dir: Path | None, model: str, n: int) -> dict[str, float]:
    """Distance-means of ``|r|``, ``|v_y|`` and ``|delta_center|`` over a run's first n samples."""
    f = log.frame.iloc[:n]
    w = distance_weights(f["t"].to_numpy(float), np.hypot(f["v_x_1"], f["v_y_1"]).to_numpy())
    out = {"r": sum(distance_mean_abs(f[f"r_{i}"].to_numpy(float), w) for i in (1, 2)),
           "v_y": sum(distance_mean_abs(f[f"v_y_{i}"].to_numpy(float), w) for i in (1, 2)),
           "delta_c": math.nan}
    path = None if runs_dir is None else Path(runs_dir) / f"{log.name}.{model}.parquet"
    if path is not None and path.is_file():
        try:
            run = read_run(path, check=False, columns=["delta", "delta_fb"]).frame.iloc[:n]
        except LogError:
            return out
        dc = (run["delta"] - run["delta_fb"]).to_numpy(float)
        out["delta_c"] = distance_mean_abs(dc, w[:dc.size])
    return out


def pool(parts: Sequence[dict], scale: dict | None = None) -> dict[str, float]:
    """Pooled criteria of segments (see the module docstring).

    Parameters
    ----------
    parts : sequence of dict
        Per segment: the :data:`artic.validation.criteria.metrics.CRITERIA`, ``s_max`` [m],
        and the distance-means ``r`` [rad/s], ``v_y`` [m/s] and ``delta_c`` [rad];
        in segment order.
    scale : dict, optional
        The direction's fixed scale of ``eps_n_fixed``
        (:func:`artic.validation.criteria.fixedscale.campaign_scale`).

    Returns
    -------
    dict
        The criteria and ``s_max``, the total distance.
    """
    s = np.array([p["s_max"] for p in parts], dtype=float)
    total = float(s.sum())
    if total <= 0:
        return dict.fromkeys(POOLED, math.nan) | {"s_max": total}

    def mean(key: str) -> float:
        return float(np.sum(s * np.array([p[key] for p in parts], dtype=float)) / total)

    def rms(values) -> float:
        return float(np.sqrt(np.sum(s * np.square(np.asarray(values, dtype=float))) / total))

    out = {c: rms([p.get(c, math.nan) for p in parts]) for c in RMS}
    out["eps_p"] = out["eps_y1"] + out["eps_y2"]
    out["eps_a"] = out["eps_r1"] + out["eps_r2"]
    out["eps_v"] = out["eps_vy1"] + out["eps_vy2"]
    r_mean, vy_mean = mean("r"), mean("v_y")
    out["eps_n"] = (100.0 * (out["eps_a"] / r_mean + out["eps_v"] / vy_mean)
                    if r_mean > NOISE_FLOOR["r"] and vy_mean > NOISE_FLOOR["v_y"] else math.nan)
    dc = mean("delta_c")
    fb = rms([p["J_steer"] * p["delta_c"] / 100.0 for p in parts])
    out["J_steer"] = 100.0 * fb / dc if dc > 0 else math.nan
    out["eps_n_fixed"] = eps_n_fixed(out["eps_a"], out["eps_v"], scale)
    for c in extra.COLUMNS:
        if extra.POOL[c] == "mean":
            v = np.array([p.get(c, math.nan) for p in parts], dtype=float)
            ok = np.isfinite(v) & (s > 0)
            out[c] = float(np.sum(s[ok] * v[ok]) / np.sum(s[ok])) if ok.any() else math.nan
        elif extra.POOL[c] == "last":
            out[c] = float(parts[-1].get(c, math.nan))
    return {c: out.get(c, math.nan) for c in POOLED} | {"s_max": total}


def pool_segments(metrics: pd.DataFrame, logs: Sequence[Run],
                  runs_dir: Path | None = None) -> pd.DataFrame:
    """The metrics with one pooled row per (log split at gaps, model) added.

    Parameters
    ----------
    metrics : DataFrame
        From :func:`artic.validation.runs.validate.validate_runs`.
    logs : sequence of Run
        The logs validated.
    runs_dir : Path, optional
        Where the model runs were written (``OUT_DIR/runs``), for ``J_steer``.

    Returns
    -------
    DataFrame
        ``metrics`` with a ``segment`` column (``"k/N"`` for a segment's row,
        ``"pooled N"`` for the pooled row named after the whole log, empty for
        a log without gaps) and the pooled rows after their segments'.
    """
    out = metrics.copy()
    by_name = {log.name: log for log in logs}
    segs = {name: segment_of(log) for name, log in by_name.items()}
    out["segment"] = [f"{segs[n]['index']}/{segs[n]['of']}" if segs.get(n) else ""
                      for n in out["log"]]
    groups: dict[tuple[str, str], list] = {}
    rows_in_order = sorted(out.itertuples(index=False),
                           key=lambda r: segs[r.log]["index"] if segs.get(r.log) else 0)
    for row in rows_in_order:
        seg = segs.get(row.log)
        if seg is not None:
            groups.setdefault((seg["log"], row.model), []).append(row)
    pooled = []
    for (name, model), rows in groups.items():
        ok = [r for r in rows if str(r.status) == "ok"]
        parts = []
        for r in ok:
            log = by_name[r.log]
            n = int(np.searchsorted(log.frame["t"].to_numpy(), r.duration_s + 1e-9))
            parts.append({**{c: getattr(r, c) for c in POOLED if hasattr(r, c)},
                          "s_max": r.s_max,
                          **_means(log, runs_dir, model, min(n, len(log.frame)))})
        scale = (metrics.attrs.get("scale") or {}).get(rows[0].direction)
        crit = (pool(parts, scale) if parts
                else dict.fromkeys(POOLED, math.nan) | {"s_max": 0.0})
        of = segs[rows[0].log]["of"]
        status = "ok" if len(ok) == of else (
            f"partial: pooled over {len(ok)} of {of} segments" if ok
            else f"failed: every segment failed ({rows[0].status})")
        pooled.append({"log": name, "model": model, "direction": rows[0].direction,
                       "manoeuvre": rows[0].manoeuvre, **crit, "status": status,
                       "wall_s": float(sum(r.wall_s for r in rows)),
                       "duration_s": float(sum(r.duration_s for r in rows)),
                       "segment": f"pooled {of}"})
    if pooled:
        out = pd.concat([out, pd.DataFrame(pooled, columns=out.columns)], ignore_index=True)
    out.attrs = dict(metrics.attrs)
    return out


def whole_logs(metrics: pd.DataFrame) -> pd.DataFrame:
    """The rows of whole logs: logs without gaps and the pooled rows, not the segments'."""
    if "segment" not in metrics:
        return metrics
    return metrics[~metrics["segment"].astype(str).str.contains("/")]
