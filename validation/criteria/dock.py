"""Dock errors: where a model leaves the semitrailer's rear at the end of a docking or parking run.

For the manoeuvres that end at a dock (:data:`KINDS`), the semitrailer's rear
edge centre (the point that meets the dock face: the outline's rear end on
the centre line, :func:`artic.validation.criteria.points.rear_x`) at the last
sample of the model's run, against the same point of the measured
semitrailer at the log's last sample:

- ``dock_lon`` [m]: the model's rear ahead (+) of or behind (-) the measured
  one, along the measured semitrailer's x-axis at the end (forward positive,
  so + means the model stopped short of the dock);
- ``dock_lat`` [m]: to its left (+) or right (-), along its y-axis;
- ``dock_psi`` [rad]: the model's semitrailer heading minus the measured
  one, wrapped to (-pi, pi].

The errors are signed, so that a model that always stops short shows as a
bias; average their magnitudes to rank models. They are NaN for other kinds
of manoeuvre and for a run that stopped before the log's end (it never
reached the dock). Both positions come from each run's own semitrailer sensor
with the same lever arm (:mod:`artic.validation.criteria.points`), so the
error is that of one body point.
"""

from __future__ import annotations

import math
from typing import TYPE_CHECKING

import numpy as np
import pandas as pd

from artic.mjcf.interface import wrap_angle
from artic.mjcf.vehicle import Vehicle
from artic.validation.criteria.points import rear_x, trailer_point

if TYPE_CHECKING:
    from artic.validation.logs.runfile import Run

KINDS = ("docking", "parking")
"""Manoeuvres that end at a dock."""

COLUMNS = ("dock_lat", "dock_lon", "dock_psi")
UNITS = {"dock_lat": "m", "dock_lon": "m", "dock_psi": "rad"}


def end_pose_error(measured_end: pd.Series, model_end: pd.Series,
                   vehicle: Vehicle) -> dict[str, float]:
    """Rear-point and heading error of one model sample against one measured sample.

    Parameters
    ----------
    measured_end, model_end : Series
        One row each of the signal schema (``x_2``, ``y_2``, ``psi_2``).
    vehicle : Vehicle
        For the semitrailer's outline and sensor lever arm.

    Returns
    -------
    dict
        ``dock_lat``, ``dock_lon`` [m] in the measured semitrailer's frame, ``dock_psi`` [rad].
    """
    x = rear_x(vehicle)
    psi_m = float(measured_end["psi_2"])
    xm, ym = trailer_point(vehicle, x, measured_end["x_2"], measured_end["y_2"], psi_m)
    xs, ys = trailer_point(vehicle, x, model_end["x_2"], model_end["y_2"], model_end["psi_2"])
    dx, dy = float(xs - xm), float(ys - ym)
    c, s = math.cos(psi_m), math.sin(psi_m)
    return {"dock_lat": -s * dx + c * dy, "dock_lon": c * dx + s * dy,
            "dock_psi": float(wrap_angle(float(model_end["psi_2"]) - psi_m))}


def dock_errors(measured: pd.DataFrame, model: pd.DataFrame, vehicle: Vehicle,
                manoeuvre: str) -> dict[str, float]:
    """The dock errors of a model run (see the module docstring).

    Parameters
    ----------
    measured : DataFrame
        The log, in the signal schema.
    model : DataFrame
        The model's run through the harness, sample for sample.
    vehicle : Vehicle
        The vehicle the model was built from: its outline and sensor lever arm.
    manoeuvre : str
        The log's kind; the errors are NaN unless it is one of :data:`KINDS`.
    """
    nan = {c: float("nan") for c in COLUMNS}
    if manoeuvre not in KINDS or len(model) < len(measured) or len(measured) == 0:
        return nan
    out = end_pose_error(measured.iloc[-1], model.iloc[len(measured) - 1], vehicle)
    return out if all(np.isfinite(v) for v in out.values()) else nan


def of_run(log: Run, run: Run, vehicle: Vehicle) -> dict[str, float]:
    """The dock errors of a model run against its log, as the runs compute them.

    :func:`dock_errors` for the log's manoeuvre (its metadata's), in the form of
    :data:`artic.validation.criteria.columns.TABLE`.
    """
    return dock_errors(log.frame, run.frame, vehicle, str(log.meta.get("manoeuvre", "")))
