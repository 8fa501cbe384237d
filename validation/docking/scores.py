"""Scores of a docking run, and the table over seeded starts with 95 % intervals.

Per run (:func:`score`), from the plant's true signals (the controller's
noisy ones never enter a score):

- ``success``: no failure (collision, jackknife, timeout, no plan, a diverged
  plant or a controller error), the controller said it was done, and the
  rear came to rest at the door: at most :data:`DOCKED` short of the face,
  off its centre line and askew. A run that stops outside them fails as
  ``missed the door``. (The gates are the benchmark's: what a dock
  leveller's lip and the door's seals take up.)
- final ``lateral_error_m`` (positive: left of the line, seen from the
  dock), ``longitudinal_error_m`` (positive: short of the face) of the
  semitrailer's rear centre, and ``heading_error_deg`` of the semitrailer;
- ``max_gamma_deg`` and its ``gamma_margin_deg`` to the vehicle's limit;
- ``direction_changes``: sign changes of the tractor's speed beyond 5 cm/s;
- ``time_s`` to rest; ``path_length_m``: the drive axle's travel;
- ``swept_area_m2``: the ground the two outlines covered (0.1 m grid), and
  ``swept_width_m``: that area less the start's footprint, per metre of the
  semitrailer axle's travel: the outline's width when reversing straight,
  wider in a turn;
- ``solve_ms_p50``, ``solve_ms_p99``: the controller's compute time per command
  (the row also carries every command's, ``solve_ms``, which
  :func:`compute_times` pools over runs; it is not a column of ``dock.csv``);
  ``late_commands``: how many commands (the first left out) took longer than
  the sample period. A run with too many fails as ``not real-time``
  (:data:`artic.validation.docking.run.REALTIME_LATE`) unless ``artic dock
  --no-realtime``.
- ``success_test``, ``success_rl``, ``success_artic``: success at the three
  tolerances of :data:`TIERS` (a driving test's, reinforcement-learning
  environments', artic's), each on a run that came to rest at the dock without
  another failure (a run that ``missed the door`` may pass the driving test's).

The table (:func:`table`) groups by scenario, vehicle and controller: the
success rate with its Wilson 95 % interval, and the means of the errors
over the successes with the project's 95 % intervals, printed to the digits
the interval supports (:mod:`artic.validation.criteria.statistics`).
:mod:`artic.validation.docking.pairs` compares controllers over the same starts.
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np
import pandas as pd
from scipy import stats

from artic.mjcf.interface import OBS_INDEX
from artic.mjcf.vehicle import Vehicle
from artic.validation.criteria.statistics import CONFIDENCE, Interval, format_ci, mean_ci
from artic.validation.docking.geometry import Frames, swept_cells

DOCKED = (0.3, 0.3, math.radians(3.0))
"""Largest distance short of the face [m], offset from the centre line [m] and
heading error [rad] of a docked rear."""

REVERSING = 0.05
"""Speed beyond which the tractor counts as moving in a direction [m/s]."""

SWEPT_CELL = 0.1
"""Grid of the swept area [m]."""

COLUMNS = ("scenario", "vehicle", "controller", "plant", "seed", "success", "failure",
           "success_test", "success_rl", "success_artic",
           "lateral_error_m", "longitudinal_error_m", "heading_error_deg", "max_gamma_deg",
           "gamma_margin_deg", "direction_changes", "time_s", "path_length_m", "swept_width_m",
           "swept_area_m2", "solve_ms_p50", "solve_ms_p99", "late_commands", "plan_ms",
           "plan_expansions", "plan_direction_changes", "plan_length_m", "start_x_m", "start_y_m",
           "start_heading_deg", "start_gamma_deg")
"""Columns of ``dock.csv``, in order."""
COLUMNS += ("trailer", "l2_nominal_m", "l2_true_m", "l2_identified_m", "l2_updates",
            "trailer_length_error_m", "trailer_kingpin_error_m", "trailer_payload_kg",
            "trailer_payload_x_m", "trailer_tyre_scale")
# The semitrailer (artic.validation.docking.variants, .identify): which (--trailer), its
# effective wheelbase in the vehicle file, in the plant and as identified at the stop [m],
# the identifier's updates, and the draw of --trailer unknown (zero with the file's).

ESTIMATE_COLUMNS = ("sensors", "gamma_est_rms_deg", "gamma_est_stop_deg", "rear_est_rms_m",
                    "rear_est_stop_m")
"""The sensor set and the errors of what the controller saw (:func:`estimate_scores`)."""

COLUMNS = COLUMNS + ESTIMATE_COLUMNS


@dataclass(frozen=True)
class Tier:
    """A tolerance on where a docked rear stands.

    Parameters
    ----------
    name : str
        The column is ``success_NAME``.
    label : str
        For tables.
    lateral, longitudinal : float
        Largest offset from the door's centre line and distance short of the face [m]
        (``inf``: not bounded).
    heading : float
        Largest heading error [rad] (``inf``: not bounded).
    distance : float
        Largest distance of the rear's centre from the door's point on the face [m]
        (``inf``: not bounded).
    gated : bool
        Whether the benchmark's own gates (:data:`DOCKED`) must hold too.
    """

    name: str
    label: str
    lateral: float = math.inf
    longitudinal: float = math.inf
    heading: float = math.inf
    distance: float = math.inf
    gated: bool = False

    @property
    def column(self) -> str:
        """Its column of ``dock.csv``."""
        return f"success_{self.name}"

    def passed(self, row: dict) -> bool:
        """Whether the run ``row`` (with :func:`score`'s errors and failure) meets the tier."""
        failure = str(row.get("failure") or "")
        if failure and not failure.startswith(MISSED):
            return False
        if self.gated and not row.get("success"):
            return False
        lat, lon = float(row["lateral_error_m"]), float(row["longitudinal_error_m"])
        head = math.radians(float(row["heading_error_deg"]))
        return bool(abs(lat) <= self.lateral and abs(lon) <= self.longitudinal
                    and abs(head) <= self.heading and math.hypot(lat, lon) <= self.distance)


MISSED = "missed the door"
"""How the failure of a run that came to rest outside :data:`DOCKED` begins."""

TIERS = (
    Tier("test", "driving test 0.91 m", lateral=0.91, longitudinal=0.91),
    Tier("rl", "RL 15 cm, 0.1 rad", heading=0.1, distance=0.15),
    Tier("artic", "artic 10 cm, 1 deg", lateral=0.10, heading=math.radians(1.0), gated=True),
)
"""Success at three tolerances, loosest first:

- ``test``: a driving test's alley dock (the 3 ft, 0.91 m, a commercial driving test
  allows between the trailer's rear and the line, here the face, and off the door's
  line); no heading bound;
- ``rl``: the reinforcement-learning truck backer-upper environments' goal: the rear
  within 15 cm of the target point and 0.1 rad of its heading;
- ``artic``: the benchmark's gates (:data:`DOCKED`) and artic's bar on a docked run,
  10 cm off the line and 1 deg askew (the dashed box of ``dock_errors.png``).

The benchmark's ``success`` stays its gates alone (30 cm, 3 deg): today's rates stand."""


def tiers(row: dict) -> dict[str, bool]:
    """The run's success at each of :data:`TIERS`, by column."""
    return {t.column: t.passed(row) for t in TIERS}


def score(trace, yard, vehicle: Vehicle, frames: Frames, start) -> dict:
    """The scores of one run (see the module docstring).

    Parameters
    ----------
    trace : artic.validation.docking.run.Trace
        What happened.
    yard : Yard
        The dock.
    vehicle : Vehicle
        Its ``gamma_max``.
    frames : Frames
        Its geometry.
    start : Start
        Where it started.
    """
    a = trace.arrays()
    row = {"success": False, "failure": trace.failure, **{t.column: False for t in TIERS},
           "start_x_m": start.x_r - yard.x_dock, "start_y_m": start.y_r - yard.y_dock,
           "start_heading_deg": math.degrees(start.psi_2),
           "start_gamma_deg": math.degrees(start.gamma)}
    nan = math.nan
    row.update({k: nan for k in COLUMNS if k.endswith(("_m", "_deg", "_s", "_m2", "_ms_p50",
                                                       "_ms_p99")) and k not in row})
    row["direction_changes"] = 0
    solve = a["solve_ms"]
    row["solve_ms"] = solve
    if solve.size:
        row["solve_ms_p50"] = float(np.percentile(solve, 50))
        row["solve_ms_p99"] = float(np.percentile(solve, 99))
    true = a["true"]
    if true.shape[0] == 0:
        return row
    x_r, y_r, psi_2 = frames.rear_of_signals(true[-1])
    lon, lat = float(x_r - yard.x_dock), float(y_r - yard.y_dock)
    head = float(math.remainder(psi_2, 2 * math.pi))
    gamma = np.abs(true[:, OBS_INDEX["gamma"]])
    row.update({"lateral_error_m": lat, "longitudinal_error_m": lon,
                "heading_error_deg": math.degrees(head),
                "max_gamma_deg": math.degrees(float(gamma.max())),
                "gamma_margin_deg": math.degrees(vehicle.gamma_max - float(gamma.max())),
                "time_s": float(a["t"][-1])})
    v = true[:, OBS_INDEX["v_x_1"]]
    moving = np.sign(v[np.abs(v) > REVERSING])
    row["direction_changes"] = int(np.count_nonzero(np.diff(moving))) if moving.size else 0
    tractor, trailer = frames.unit_poses_of_signals(true)
    row["path_length_m"] = float(np.sum(np.hypot(*np.diff(tractor[:, :2], axis=0).T)))
    axle = trailer[:, :2] - frames.kin.params.L2 * np.column_stack([np.cos(trailer[:, 2]),
                                                           np.sin(trailer[:, 2])])
    axle_travel = float(np.sum(np.hypot(*np.diff(axle, axis=0).T)))
    area, footprint = swept_area(tractor, trailer, frames)
    row["swept_area_m2"] = area
    row["swept_width_m"] = (area - footprint) / axle_travel if axle_travel > 1.0 else nan
    if not trace.failure:
        if not trace.done:
            row["failure"] = "the controller never finished"
        elif not (-DOCKED[0] <= lon <= DOCKED[0] and abs(lat) <= DOCKED[1]
                  and abs(head) <= DOCKED[2]):
            row["failure"] = (f"{MISSED}: rear {100 * lon:.0f} cm from the face, "
                              f"{100 * lat:.0f} cm off the line, "
                              f"{math.degrees(head):.1f} deg askew")
        else:
            row["success"] = True
    row.update(tiers(row))
    return row


def swept_area(tractor: np.ndarray, trailer: np.ndarray, frames: Frames,
               every: int = 5) -> tuple[float, float]:
    """Ground covered by the outlines over a run, and by them at the start alone [m^2].

    Parameters
    ----------
    tractor, trailer : ndarray, shape (n, 3)
        Drive-axle and kingpin poses per plant step.
    frames : Frames
        The outlines.
    every : int
        Use every ``every``-th pose (at 10 ms steps and 6 km/h, 5 steps are 8 cm).
    """
    sel = np.r_[np.arange(0, len(tractor), every), len(tractor) - 1]
    t, k = tractor[sel], trailer[sel]
    reach = float(frames.trailer_box[1] + abs(frames.trailer_box[0]) + frames.tractor_box[1]
                  + abs(frames.tractor_box[0]) + 2.0)
    x0 = float(min(t[:, 0].min(), k[:, 0].min()) - reach)
    y0 = float(min(t[:, 1].min(), k[:, 1].min()) - reach)
    nx = int((max(t[:, 0].max(), k[:, 0].max()) + reach - x0) / SWEPT_CELL) + 1
    ny = int((max(t[:, 1].max(), k[:, 1].max()) + reach - y0) / SWEPT_CELL) + 1
    cell2 = SWEPT_CELL ** 2
    all_ = swept_cells(t, k, frames.tractor_box, frames.trailer_box, x0, y0, SWEPT_CELL, nx, ny)
    first = swept_cells(t[:1], k[:1], frames.tractor_box, frames.trailer_box, x0, y0,
                        SWEPT_CELL, nx, ny)
    return float(all_.sum() * cell2), float(first.sum() * cell2)


def estimate_scores(trace, seen: Frames, true: Frames) -> dict:
    """The errors of what the controller saw, at its samples, against the plant then.

    With ``artic dock --sensors full`` the measured signals; with ``tractor`` or
    ``camera`` the estimator's (:mod:`artic.validation.docking.estimator`).

    - ``gamma_est_rms_deg``: RMS of the articulation's error over the run;
      ``gamma_est_stop_deg``: its error (seen minus true) at the last sample,
      where the controller stopped;
    - ``rear_est_rms_m``, ``rear_est_stop_m``: the same of the distance between
      the semitrailer's rear (the dock point) where the controller placed it,
      by the vehicle file's geometry on the signals it saw, and where it was.

    Parameters
    ----------
    trace : artic.validation.docking.run.Trace
        The run: ``measured`` and ``seen_at`` (the plant step of each sample).
    seen : Frames
        The geometry the controller knows (the vehicle file's).
    true : Frames
        The plant's.
    """
    a = trace.arrays()
    m = a["measured"]
    if m.shape[0] == 0:
        return dict.fromkeys(ESTIMATE_COLUMNS[1:], math.nan)
    t = a["true"][np.asarray(trace.seen_at, dtype=int)]
    g = OBS_INDEX["gamma"]
    dg = np.degrees(np.remainder(m[:, g] - t[:, g] + np.pi, 2 * np.pi) - np.pi)
    d = np.hypot(*(rear_point(seen, m) - rear_point(true, t)).T)
    return {"gamma_est_rms_deg": float(np.sqrt(np.mean(dg ** 2))),
            "gamma_est_stop_deg": float(dg[-1]),
            "rear_est_rms_m": float(np.sqrt(np.mean(d ** 2))), "rear_est_stop_m": float(d[-1])}


def rear_point(frames: Frames, signals: np.ndarray) -> np.ndarray:
    """The semitrailer's rear ``(x, y)`` [m] of signals ``(n, 13)``, by its unit's signals.

    The dock point, where ``frames``' geometry places it: the estimate's, with the
    geometry the controller knows; the plant's, with the plant's.
    """
    _, k = frames.unit_poses_of_signals(signals)
    return k[:, :2] - frames.rear * np.column_stack([np.cos(k[:, 2]), np.sin(k[:, 2])])


# ---------------------------------------------------------------- statistics
def rate_ci(k: int, n: int) -> Interval:
    """Success rate ``k / n`` and its Wilson 95 % interval.

    Wilson's interval rather than the normal approximation: it stays inside
    [0, 1] and keeps its coverage at 10 of 10, where the normal one has no width.
    """
    if n == 0:
        return Interval(math.nan, math.nan, math.nan, 0, "none")
    ci = stats.binomtest(int(k), int(n)).proportion_ci(CONFIDENCE, method="wilson")
    return Interval(k / n, float(ci.low), float(ci.high), int(n), "Wilson")


TABLE_METRICS = (("|lateral| [cm]", "lateral_error_m", 100.0, True),
                 ("|longitudinal| [cm]", "longitudinal_error_m", 100.0, True),
                 ("|heading| [deg]", "heading_error_deg", 1.0, True),
                 ("max |gamma| [deg]", "max_gamma_deg", 1.0, False),
                 ("direction changes", "direction_changes", 1.0, False),
                 ("time [s]", "time_s", 1.0, False),
                 ("path [m]", "path_length_m", 1.0, False),
                 ("swept width [m]", "swept_width_m", 1.0, False))
"""The table's means over successes: label, column, scale, and whether of the magnitude."""


def table(rows: pd.DataFrame) -> pd.DataFrame:
    """One row per scenario, vehicle and controller (see the module docstring)."""
    out = []
    for (scen, veh, ctrl), g in rows.groupby(["scenario", "vehicle", "controller"], sort=False):
        ok = g[g["success"].astype(bool)]
        rec = {"scenario": scen, "vehicle": veh, "controller": ctrl, "runs": len(g),
               "docked": len(ok), "success [95 % CI]": format_ci(rate_ci(len(ok), len(g)))}
        for t in TIERS:
            if t.column in g:
                k = int(g[t.column].astype(bool).sum())
                rec[f"{t.label} [95 % CI]"] = format_ci(rate_ci(k, len(g)))
        for label, col, scale, absolute in TABLE_METRICS:
            x = scale * ok[col].to_numpy(dtype=float)
            rec[label] = format_ci(mean_ci(np.abs(x) if absolute else x))
        for label, col in (("max |lateral| [cm]", "lateral_error_m"),
                           ("max |heading| [deg]", "heading_error_deg")):
            x = np.abs(ok[col].to_numpy(dtype=float)) * (100.0 if "cm" in label else 1.0)
            rec[label] = f"{x.max():.1f}" if x.size else "-"
        rec["jackknifes"] = int(g["failure"].astype(str).str.startswith("jackknife").sum())
        rec["collisions"] = int(g["failure"].astype(str).str.startswith("collision").sum())
        rec["solve p50 [ms]"] = f"{g['solve_ms_p50'].median():.2g}"
        rec["solve p99 [ms]"] = f"{g['solve_ms_p99'].max():.2g}"
        out.append(rec)
    return pd.DataFrame(out)


def compute_times(rows) -> pd.DataFrame:
    """Each controller's compute time per command, the commands of all its runs pooled.

    The 99th percentile of a run's few hundred commands is its third
    largest; pooled over a benchmark's runs it is the figure a real-time
    budget is held to. Measured in the benchmark's worker processes: on a
    core of its own (``taskset -c 0 artic dock --jobs 1 ...``) it is the
    controller's; with other work on the core, that work's too.

    Parameters
    ----------
    rows : sequence of dict
        Rows of :func:`score` (with their ``solve_ms``).

    Returns
    -------
    DataFrame
        ``controller``, ``commands``, ``p50 [ms]``, ``p99 [ms]``, ``max [ms]``.
    """
    pooled: dict[str, list[np.ndarray]] = {}
    for r in rows:
        pooled.setdefault(r["controller"], []).append(np.asarray(r.get("solve_ms", ()),
                                                                 dtype=float))
    out = []
    for ctrl, parts in pooled.items():
        x = np.concatenate(parts) if parts else np.empty(0)
        rec = {"controller": ctrl, "commands": int(x.size)}
        for label, q in (("p50 [ms]", 50), ("p99 [ms]", 99), ("max [ms]", 100)):
            rec[label] = f"{np.percentile(x, q):.2g}" if x.size else "-"
        out.append(rec)
    return pd.DataFrame(out, columns=["controller", "commands", "p50 [ms]", "p99 [ms]",
                                      "max [ms]"])


def markdown(t: pd.DataFrame) -> str:
    """The table as GitHub Markdown (each cell escaped: a ``|`` in a name stays in its cell)."""
    from artic.validation.review.tables import escape

    cols = list(t.columns)
    lines = ["| " + " | ".join(escape(c) for c in cols) + " |", "|" + "---|" * len(cols)]
    lines += ["| " + " | ".join(escape(v) for v in r) + " |"
              for r in t.itertuples(index=False)]
    return "\n".join(lines) + "\n"
