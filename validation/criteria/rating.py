"""ISO/TS 18571's rating of a model run's signals against its log, as criteria ``iso_gap_*``.

Each of the signals of the paper's criteria and the articulation, ``r_1``,
``r_2`` [rad/s], ``v_y_1``, ``v_y_2`` [m/s] and ``gamma`` [rad], is rated
against the log's by :func:`artic.validation.criteria.iso18571.rate` (the
log's signal the reference ``T``, the model's the comparison ``C``), over the
samples the model computed. A criterion is an error (the tables rank every
column lower-is-better), so each column is the rating's shortfall
``1 - R`` [-]: 0 for a signal the model reproduces exactly, 1 for none of it;
``iso_gap`` is the mean over the five signals, the rating of the run as a
whole. The standard's grades read on ``R = 1 - iso_gap``: excellent above 0.94
(a gap under 0.06), good above 0.8, fair above 0.58.

**Sampling.** The standard's 10 kHz fits crash tests; a truck's yaw rates and
articulation at walking pace change over seconds (the fastest manoeuvre, the
8 km/h slalom, has a period of 11 s), and the magnitude score's time warping
costs the square of the samples. The signals are resampled to
:data:`RATE_HZ` by linear interpolation in time: 100 samples per period of the
fastest steering the campaign drives, and the slope score's 9-sample average
spans 0.9 s; at the logs' 100 Hz the sensor noise would weigh more in the
slope score's derivatives (a central difference of white noise grows with the
rate) and the warping would cost 100 times more.
"""

from __future__ import annotations

import math
from typing import TYPE_CHECKING

import numpy as np

from artic.mjcf.interface import wrap_angle
from artic.validation.criteria.iso18571 import rate

if TYPE_CHECKING:
    from artic.mjcf.vehicle import Vehicle
    from artic.validation.logs.runfile import Run

RATE_HZ = 10.0
"""Rate the signals are rated at [Hz] (see the module's note)."""

SIGNALS = {"iso_gap_r1": "r_1", "iso_gap_r2": "r_2", "iso_gap_vy1": "v_y_1",
           "iso_gap_vy2": "v_y_2", "iso_gap_gamma": "gamma"}
"""Each column and the signal it rates."""

COLUMNS = (*SIGNALS, "iso_gap")
"""The columns, in ``metrics.csv`` order."""

UNITS = dict.fromkeys(COLUMNS, "-")
"""Unit of each column: a shortfall of a rating in [0, 1]."""


def resampled(t: np.ndarray, *signals: np.ndarray) -> tuple[np.ndarray, ...]:
    """``signals`` on a grid of :data:`RATE_HZ` from ``t[0]`` to ``t[-1]`` [s]; the grid first."""
    grid = t[0] + np.arange(int(math.floor((t[-1] - t[0]) * RATE_HZ + 1e-9)) + 1) / RATE_HZ
    return (grid, *(np.interp(grid, t, s) for s in signals))


def gaps(log: Run, run: Run) -> dict[str, float]:
    """``1 - R`` per signal of a model run against its log, and their mean [-].

    NaN for a signal whose reference is flat (no amplitude or no slope, the
    standard's scores divide by both) or a run shorter than 3 samples at
    :data:`RATE_HZ`.
    """
    n = len(run.frame)
    meas = log.frame.iloc[:n]
    t = meas["t"].to_numpy(dtype=float)
    out = dict.fromkeys(COLUMNS, math.nan)
    if n < 2 or (t[-1] - t[0]) * RATE_HZ < 2.0:
        return out
    for column, name in SIGNALS.items():
        ref = meas[name].to_numpy(dtype=float)
        model = run.frame[name].to_numpy(dtype=float)
        if name == "gamma":  # the model's articulation on the log's side of the cut at +-pi
            model = ref + wrap_angle(model - ref)
        ok = np.isfinite(ref) & np.isfinite(model)
        if ok.sum() < 2:
            continue
        _, ref_s, model_s = resampled(t[ok], ref[ok], model[ok])
        if ref_s.size >= 3:
            out[column] = 1.0 - rate(ref_s, model_s, 1.0 / RATE_HZ).overall
    rated = [out[c] for c in SIGNALS if math.isfinite(out[c])]
    out["iso_gap"] = float(np.mean(rated)) if rated else math.nan
    return out


def of_run(log: Run, run: Run, vehicle: Vehicle) -> dict[str, float]:
    """The ``iso_gap_*`` columns of a model run against its log, as the runs compute them.

    ``vehicle`` is not needed here.
    """
    return gaps(log, run)
