"""The steering correction ``steer_fb`` [deg]: ``J_steer``'s numerator in absolute units.

    steer_fb = degrees( sqrt( (1 / s_max) * integral delta_fb**2 ds ) )

``delta_fb`` is the part of the **road-wheel angle** that the harness's
feedback added, ``delta - delta_center`` (eqs. 5-7), averaged over the
measured distance travelled as eq. (8), with the distance weights of the
paper's criteria (:func:`artic.validation.criteria.metrics.distance_weights`).
``J_steer`` (eq. 10) divides the same RMS by the distance-averaged mean of
``|delta_center|``: a manoeuvre steered gently (a ramp steer whose mean road-wheel
angle is about a degree) turns a fraction of a degree of correction into tens of
points, where a docking manoeuvre with ten times the steering scores the same
correction ten times lower. ``steer_fb`` states the correction itself, so that
manoeuvre classes can be compared. A run without feedback (forward, where the
harness steers open loop) has none: ``steer_fb`` is 0 there, NaN where the run
records no ``delta_fb`` at all.

A distance-RMS of one column, it pools over the segments of a log split at its
gaps exactly as the paper's errors do (``"rms"`` in
:data:`artic.validation.criteria.columns.TABLE`).
"""

from __future__ import annotations

import math
from typing import TYPE_CHECKING

import numpy as np
import pandas as pd

from artic.validation.criteria.distance import distance_rms, distance_weights

if TYPE_CHECKING:
    from artic.mjcf.vehicle import Vehicle
    from artic.validation.logs.runfile import Run

UNIT = "deg"


def steer_fb(measured: pd.DataFrame, model: pd.DataFrame) -> float:
    """The RMS feedback part of the road-wheel angle over the distance travelled [deg].

    Parameters
    ----------
    measured : DataFrame
        The log, in the signal schema (its speed gives the distance weights).
    model : DataFrame
        The model's run through the harness, with ``delta_fb`` [rad]; if it
        stopped early, only its rows count.

    Returns
    -------
    float
        ``steer_fb`` [deg]; NaN without ``delta_fb`` or without distance travelled.
    """
    if "delta_fb" not in model:
        return math.nan
    n = len(model)
    meas = measured.iloc[:n]
    w = distance_weights(meas["t"].to_numpy(dtype=float),
                         np.hypot(meas["v_x_1"].to_numpy(dtype=float),
                                  meas["v_y_1"].to_numpy(dtype=float)))
    return math.degrees(distance_rms(model["delta_fb"].to_numpy(dtype=float), w))


def of_run(log: Run, run: Run, vehicle: Vehicle) -> dict[str, float]:
    """``steer_fb`` of a model run against its log [deg], as the runs compute it."""
    return {"steer_fb": steer_fb(log.frame, run.frame)}
