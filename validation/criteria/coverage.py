"""The progress term ``eps_cover``: how far the measured path lies from the model's.

The paper's position error ``eps_p`` (eq. 9) measures one direction of a path
distance: each *model* point's distance to the *measured* path. A model that
never leaves its start sits on the measured path (it starts where the log
starts) and scores nearly zero there, better than any model that drives. The
missing direction is the coverage of the measured path: each *measured* point's
distance to the path the model drove,

    d_k = dist(p_1(k), model path 1) + dist(p_2(k), model path 2)

summed over the tractor's and the semitrailer's sensor points as ``eps_p``
sums them, averaged over the distance travelled as eq. (8):

    eps_cover = sqrt( (1 / s_max) * integral d**2 ds )

over the measured samples the model computed, with the measured path's
distance weights (:func:`artic.validation.criteria.metrics.distance_weights`).
Each path is the polyline through a run's samples and the distance to it is
exact (:func:`artic.validation.criteria.pathdist.distance_to_polyline`).

Why coverage rather than the distance error at matched travelled distance.
The harness drives a model at the log's speed, so a model that follows the
run is where the truck was up to its lateral error, and its ``eps_cover`` is
about its ``eps_p`` (equal for a constant lateral offset along a straight
path). A model that stops, or stops early, leaves the rest of the measured
path uncovered and its ``eps_cover`` grows with the distance it did not drive:
standing still at the start of a straight run of length ``L`` scores
``2 L / sqrt(3)``, stopping after a fraction ``q`` of it
``2 L sqrt((1 - q)^3 / 3)``. The coverage is a set distance, like ``eps_p``:
it does not care when the model passed a place, so it is not confused by
loops, by a figure-8 crossing itself or by a shuffle at the dock, and it adds
no along-track timing error to what ``eps_p`` measures. A distance error at
matched travelled distance would need the model's point at every measured
distance: a model that never moves has none past its start (and, matched by
its own travelled distance, it is compared with the log's start only and
scores zero), and matched by time it becomes the position error at equal
time, which a heading error of a fraction of a degree makes grow linearly
along the path: it would rank heading drift, which ``eps_a`` and ``eps_p``
measure already, not progress.

A distance-RMS error of one column, it pools over the segments of a log split
at its gaps exactly as the paper's errors do (``"rms"`` in
:data:`artic.validation.criteria.columns.TABLE`).
"""

from __future__ import annotations

from typing import TYPE_CHECKING

import numpy as np
import pandas as pd

from artic.validation.criteria.distance import distance_rms, distance_weights
from artic.validation.criteria.pathdist import distance_to_polyline

if TYPE_CHECKING:
    from artic.mjcf.vehicle import Vehicle
    from artic.validation.logs.runfile import Run

UNIT = "m"

FOLLOW_BOUND = 7.0
"""Largest ``eps_cover`` of a run that follows its log [m]: a lane's width, 3.5 m,
per sensor point.

``eps_cover`` sums the tractor's and the semitrailer's distances from the
measured path to the model's. A model that drives the run stays, for each of
the two points, within its lateral error of where the truck went, which the
harness keeps to metres (KIN on the constant steer: 2.8 m, reversing 1.4 m,
both units together); a model that stops, or turns off, leaves places of the
run farther than a traffic lane (3.5 m, the usual width of a road's lane) from
anything it drove. Standing still at the start of a straight run of ``L``
scores ``2 L / sqrt(3)``, beyond this bound from ``L`` = 6.1 m on. The tables
mark a run beyond it and put it last on the path criteria
(:func:`artic.validation.review.tables.progress`); ``assert_tracks`` fails it
(:data:`artic.validation.testing.COVER_LIMIT`)."""

PATH_CRITERIA = ("eps_y1", "eps_y2", "eps_p")
"""The path criteria a run that does not follow its log cannot win: the paper's
position errors, one direction of the path distance (each model point's distance
to the measured path), which a model that never leaves the start scores near zero."""


def eps_cover(measured: pd.DataFrame, model: pd.DataFrame) -> float:
    """The progress term of a model run against its log [m] (see the module docstring).

    Parameters
    ----------
    measured : DataFrame
        The log, in the signal schema.
    model : DataFrame
        The model's run, sample for sample; if it stopped early, only its rows
        count, of the model and of the log.

    Returns
    -------
    float
        ``eps_cover`` [m]; NaN without two samples or without a finite model point.
    """
    n = len(model)
    if n < 2:
        return float("nan")
    meas = measured.iloc[:n]
    w = distance_weights(meas["t"].to_numpy(dtype=float),
                         np.hypot(meas["v_x_1"].to_numpy(dtype=float),
                                  meas["v_y_1"].to_numpy(dtype=float)))
    d = np.zeros(n)
    for i in (1, 2):
        path = np.column_stack([model[f"x_{i}"].to_numpy(dtype=float),
                                model[f"y_{i}"].to_numpy(dtype=float)])
        path = path[np.all(np.isfinite(path), axis=1)]
        if len(path) == 0:
            return float("nan")
        pts = np.column_stack([meas[f"x_{i}"].to_numpy(dtype=float),
                               meas[f"y_{i}"].to_numpy(dtype=float)])
        d += distance_to_polyline(pts, path)
    return distance_rms(d, w)


def of_run(log: Run, run: Run, vehicle: Vehicle) -> dict[str, float]:
    """``eps_cover`` of a model run against its log [m], as the runs compute it.

    The form of a row of :data:`artic.validation.criteria.columns.TABLE`;
    ``vehicle`` is not needed here.
    """
    return {"eps_cover": eps_cover(log.frame, run.frame)}
