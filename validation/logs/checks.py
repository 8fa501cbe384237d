"""Checks and repairs of raw channels before they become a canonical log.

Each check either leaves the data alone, repairs it and says so in the
report, or raises :class:`artic.validation.logs.runfile.LogError` naming the file, the
channel, the time and the fix. No row disappears without a line in the
report. What is repaired:

- exact duplicate samples (same time, same values): the copies are dropped;
- NaN runs up to :data:`MAX_NAN_GAP` seconds: linearly interpolated.

What is refused:

- a missing channel; time that goes backwards, or repeats with different
  values; a gap longer than :data:`MAX_GAP`; a NaN run longer than
  :data:`MAX_NAN_GAP`;
- a position jump that the measured velocity cannot explain (a GNSS
  jump), larger than :data:`MAX_JUMP`.

Whether the channels describe one motion (units, signs, the hitch) is
checked on the canonical log by :mod:`artic.validation.logs.consistency`.
"""

from __future__ import annotations

from dataclasses import dataclass, field

import numpy as np
import pandas as pd

from artic.validation.logs.runfile import LogError

MAX_GAP = 0.05
"""Longest gap between inertial samples accepted [s] (five samples at 100 Hz)."""

MAX_GAP_CAN = 0.25
"""Longest gap between CAN samples accepted [s] (2.5 samples at 10 Hz)."""

MAX_NAN_GAP = 0.1
"""Longest run of NaN repaired by interpolation [s]."""

MAX_JUMP = 0.5
"""Largest position step beyond what the velocity explains [m]."""


@dataclass
class Report:
    """What an import changed or noticed, line by line."""

    source: str
    lines: list[str] = field(default_factory=list)

    def add(self, line: str) -> None:
        """Record one repair or observation."""
        self.lines.append(f"{self.source}: {line}")


def require(df: pd.DataFrame, channels: dict[str, tuple[str, ...]], source: str) -> dict[str, str]:
    """Find each wanted channel among its accepted names.

    Parameters
    ----------
    df : DataFrame
        Raw table.
    channels : dict
        Wanted channel to the names it may have, first preferred.
    source : str
        File, for the message.

    Returns
    -------
    dict
        Wanted channel to the column that holds it.

    Raises
    ------
    LogError
        Naming the first missing channel and the names accepted for it.
    """
    found = {}
    for want, names in channels.items():
        col = next((n for n in names if n in df.columns), None)
        if col is None:
            raise LogError(f"{source}: missing channel {want}: expected a column named "
                           f"{' or '.join(names)}; the file has {', '.join(map(str, df.columns))}")
        found[want] = col
    return found


def clean_time(df: pd.DataFrame, time: str, report: Report,
               max_gap: float = MAX_GAP) -> pd.DataFrame:
    """Drop exact duplicate samples; refuse backward time, conflicting duplicates and gaps.

    Parameters
    ----------
    max_gap : float
        Longest time between samples accepted [s].
    """
    t = pd.to_numeric(df[time], errors="coerce").to_numpy(dtype=float)
    if np.isnan(t).any():
        i = int(np.argmax(np.isnan(t)))
        raise LogError(f"{report.source}: channel {time}: row {i} has no valid time; "
                       "repair or remove it")
    dt = np.diff(t)
    if np.any(dt < 0):
        i = int(np.argmax(dt < 0)) + 1
        raise LogError(f"{report.source}: channel {time}: time goes back at row {i} "
                       f"({t[i - 1]:g} -> {t[i]:g}); the file may be two runs joined: split it")
    dup = np.flatnonzero(dt == 0) + 1
    if dup.size:
        same = df.iloc[dup].reset_index(drop=True).equals(df.iloc[dup - 1].reset_index(drop=True))
        if not same:
            raise LogError(f"{report.source}: channel {time}: {dup.size} repeated time stamp(s) "
                           f"with different values, first at t = {t[dup[0]]:g} s; the export is "
                           "ambiguous there")
        df = df.drop(df.index[dup]).reset_index(drop=True)
        report.add(f"dropped {dup.size} exact duplicate sample(s), first at t = {t[dup[0]]:g} s")
        t = df[time].to_numpy(dtype=float)
        dt = np.diff(t)
    if dt.size and dt.max() > max_gap:
        i = int(np.argmax(dt))
        raise LogError(f"{report.source}: channel {time}: {dt[i]:.3f} s without samples after "
                       f"t = {t[i]:g} s (more than {max_gap} s); cut the run there")
    return df


def fill_nan_runs(df: pd.DataFrame, columns: list[str], time: str,
                  report: Report) -> pd.DataFrame:
    """Interpolate short NaN runs; refuse long ones."""
    t = df[time].to_numpy(dtype=float)
    df = df.copy()
    for c in columns:
        x = pd.to_numeric(df[c], errors="coerce").to_numpy(dtype=float, copy=True)
        bad = ~np.isfinite(x)
        if not bad.any():
            df[c] = x
            continue
        if bad.all():
            raise LogError(f"{report.source}: channel {c}: no valid value at all")
        edges = np.diff(np.concatenate([[0], bad.astype(int), [0]]))
        starts, ends = np.flatnonzero(edges == 1), np.flatnonzero(edges == -1)
        for a, b in zip(starts, ends, strict=True):
            t0 = t[a - 1] if a > 0 else t[a]
            t1 = t[b] if b < len(t) else t[b - 1]
            edge = a == 0 or b == len(t)
            if edge or t1 - t0 > MAX_NAN_GAP:
                where = ", at the edge of the run" if edge else ""
                raise LogError(f"{report.source}: channel {c}: {b - a} missing value(s) from "
                               f"t = {t[a]:g} ({t1 - t0:.3f} s{where}); runs up to "
                               f"{MAX_NAN_GAP} s inside a run are interpolated, longer ones "
                               "must be cut")
        x[bad] = np.interp(t[bad], t[~bad], x[~bad])
        df[c] = x
        report.add(f"channel {c}: interpolated {int(bad.sum())} missing value(s) in "
                   f"{starts.size} run(s)")
    return df


def check_jumps(t: np.ndarray, x: np.ndarray, y: np.ndarray, vx: np.ndarray, vy: np.ndarray,
                report: Report, max_jump: float = MAX_JUMP) -> None:
    """Refuse position steps the velocity cannot explain (GNSS jumps).

    Parameters
    ----------
    x, y : ndarray
        Position in the local plane [m].
    vx, vy : ndarray
        Velocity in the same plane [m/s].
    max_jump : float
        Largest step accepted [m]: :data:`MAX_JUMP`, scaled with the vehicle
        (:mod:`artic.validation.logs.scale`).
    """
    dt = np.diff(t)
    step = np.hypot(np.diff(x) - 0.5 * (vx[1:] + vx[:-1]) * dt,
                    np.diff(y) - 0.5 * (vy[1:] + vy[:-1]) * dt)
    if step.size and step.max() > max_jump:
        i = int(np.argmax(step))
        raise LogError(f"{report.source}: position jumps {step[i]:.2f} m at t = {t[i + 1]:g} s "
                       f"more than the velocity explains (limit {max_jump:.3g} m): a GNSS jump; "
                       "cut the run there or correct the position, or pass --accept jump")
