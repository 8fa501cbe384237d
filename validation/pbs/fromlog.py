"""The low-speed measures of any run that has the motion: a measured log, and each model on it.

A measured run has no prescribed path, so its own steer axle's path is the
reference (:class:`PolylinePath`, the path coordinates of a polyline), for the
log and for every model run on it alike:

- ``swept_width`` [m]: the widest cross-section of the ground both bodies
  passed over (:mod:`artic.validation.pbs.sweep`), across the log's steer-axle path;
- ``max_offtracking`` [m]: the largest distance of the semitrailer axle
  group's centre from that path.

A run needs the tractor sensor's position and both headings (``x_1``, ``y_1``,
``psi_1``, ``psi_2``); the geometry is the vehicle's
(:class:`artic.validation.pbs.motion.Motion`). :func:`write_validate_table`
writes, for ``artic validate``, each (log, model) pair's measures, the log's,
and the model's error on each (``pbs_measures.csv``, atomically).
"""

from __future__ import annotations

from collections.abc import Sequence
from pathlib import Path

import numpy as np
import pandas as pd
from scipy.spatial import cKDTree

from artic.mjcf.vehicle import Vehicle
from artic.validation.logs.runfile import Run, atomic_write
from artic.validation.pbs.motion import Motion
from artic.validation.pbs.sweep import swept

STEP = 0.05
"""Travel between the samples the measures keep [m]: the body points move at
most this much between kept samples, half the swept path's bin."""

MEASURES = {"swept_width": "m", "max_offtracking": "m"}

FILE = "pbs_measures.csv"


class PolylinePath:
    """Path coordinates along a polyline: station ``s`` and offset ``n`` to its left [m].

    The first and last segments extend beyond the ends, so that a point behind
    the start has a negative station.

    Parameters
    ----------
    xy : ndarray, shape (K, 2)
        The polyline's vertices, at least two distinct [m].
    """

    def __init__(self, xy: np.ndarray) -> None:
        xy = np.asarray(xy, dtype=float)
        keep = np.r_[True, np.hypot(*np.diff(xy, axis=0).T) > 1e-9]
        self.xy = xy[keep]
        seg = np.diff(self.xy, axis=0)
        self.length_of = np.hypot(seg[:, 0], seg[:, 1])
        self.unit = seg / self.length_of[:, None]
        self.station = np.r_[0.0, np.cumsum(self.length_of)]
        self.length = float(self.station[-1])
        self._tree = cKDTree(self.xy)

    def frenet(self, x: np.ndarray, y: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
        """Station and left offset [m] of points ``(x, y)``.

        Each point is projected on the nearer of its nearest vertex's two segments.
        """
        p = np.c_[np.ravel(x), np.ravel(y)]
        _, i = self._tree.query(p)
        k = len(self.length_of)
        best_s = np.full(len(p), np.nan)
        best_n = np.full(len(p), np.nan)
        best_d = np.full(len(p), np.inf)
        for j in (np.clip(i - 1, 0, k - 1), np.clip(i, 0, k - 1)):
            d = p - self.xy[j]
            along = np.einsum("ij,ij->i", d, self.unit[j])
            lo = np.where(j == 0, -np.inf, 0.0)
            hi = np.where(j == k - 1, np.inf, self.length_of[j])
            a = np.clip(along, lo, hi)
            foot = self.xy[j] + a[:, None] * self.unit[j]
            dist = np.hypot(*(p - foot).T)
            n = self.unit[j][:, 0] * d[:, 1] - self.unit[j][:, 1] * d[:, 0]
            better = dist < best_d
            best_d = np.where(better, dist, best_d)
            best_s = np.where(better, self.station[j] + a, best_s)
            best_n = np.where(better, n, best_n)
        return best_s.reshape(np.shape(x)), best_n.reshape(np.shape(x))


def _kept(frame: pd.DataFrame) -> np.ndarray:
    """Rows at least :data:`STEP` of travel apart (the first always)."""
    xy = frame[["x_1", "y_1"]].to_numpy(dtype=float)
    travel = np.r_[0.0, np.cumsum(np.hypot(*np.diff(xy, axis=0).T))]
    return np.flatnonzero(np.r_[True, np.diff(np.floor(travel / STEP)) > 0])


def motion_of(frame: pd.DataFrame, vehicle: Vehicle) -> Motion:
    """The motion of a run's frame, at the kept rows."""
    f = frame.iloc[_kept(frame)]
    return Motion.from_signals(vehicle, f["t"], f["x_1"], f["y_1"], f["psi_1"], f["psi_2"])


def measures(motion: Motion, reference: PolylinePath) -> dict[str, float]:
    """The measures of a motion across ``reference`` [m] (see the module docstring)."""
    sw = swept(reference, motion.body_points()).widest(0.0, reference.length)
    a = motion.trailer_axle
    _, n = reference.frenet(a[:, 0], a[:, 1])
    s, _ = reference.frenet(a[:, 0], a[:, 1])
    inside = (s >= 0.0) & (s <= reference.length)
    ot = float(np.max(np.abs(n[inside]))) if inside.any() else float("nan")
    return {"swept_width": sw, "max_offtracking": ot}


def reference_of(log: Run, vehicle: Vehicle) -> PolylinePath | None:
    """The log's steer-axle path, or None where it travelled less than a metre."""
    m = motion_of(log.frame, vehicle)
    front = m.steer_axle
    if len(front) < 2 or np.hypot(*np.ptp(front, axis=0)) < 1.0:
        return None
    return PolylinePath(front)


def validate_table(logs: Sequence[Run], vehicle: Vehicle,
                   runs: dict[tuple[str, str], Run]) -> pd.DataFrame:
    """One row per (log, model): the model's measures, the log's, and the errors [m]."""
    rows = []
    for log in logs:
        ref = reference_of(log, vehicle)
        if ref is None:
            continue
        of_log = measures(motion_of(log.frame, vehicle), ref)
        for (name, model), run in runs.items():
            if name != log.name:
                continue
            of_model = measures(motion_of(run.frame, vehicle), ref)
            row = {"log": log.name, "model": model}
            for c in MEASURES:
                row[c] = of_model[c]
                row[f"{c}_log"] = of_log[c]
                row[f"{c}_err"] = abs(of_model[c] - of_log[c])
            rows.append(row)
    return pd.DataFrame(rows)


def write_validate_table(out_dir: Path, logs: Sequence[Run], vehicle: Vehicle,
                         pairs: Sequence[tuple[str, str]]) -> Path | None:
    """Write ``pbs_measures.csv`` from the runs ``artic validate`` left in ``out_dir/runs``.

    Parameters
    ----------
    out_dir : Path
        The validation's output folder.
    logs : sequence of Run
        The measured logs.
    vehicle : Vehicle
        The vehicle the logs and runs are of.
    pairs : sequence of (str, str)
        The (log, model) pairs with a result; a failed pair's run file holds no
        samples and is not read, nor is a pair without a run file (a pooled
        segment's row).

    Returns
    -------
    Path or None
        The table, or None where no row remains.
    """
    from artic.validation.logs.runfile import read_run

    files = {(name, m): Path(out_dir) / "runs" / f"{name}.{m}.parquet" for name, m in pairs}
    runs = {pair: read_run(p) for pair, p in files.items() if p.exists()}
    df = validate_table(logs, vehicle, runs)
    if df.empty:
        return None
    return atomic_write(Path(out_dir) / FILE, lambda p: df.to_csv(p, index=False))
