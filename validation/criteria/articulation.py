"""The articulation error ``eps_gamma``: eq. (8) applied to the articulation angle.

    eps_gamma = sqrt( (1 / s_max) * integral wrap(gamma_model - gamma_meas)**2 ds )

with the distance weights of the paper's criteria
(:func:`artic.validation.criteria.metrics.distance_weights`), over the samples the
model computed. The difference is wrapped to (-pi, pi], so that an
articulation measured at +179 deg and modelled at -179 deg is 2 deg off, not
358. Forward and reverse alike; it needs nothing but the hitch angle, which
many real rigs measure and little else.
"""

from __future__ import annotations

from typing import TYPE_CHECKING

import numpy as np
import pandas as pd

from artic.mjcf.interface import wrap_angle
from artic.validation.criteria.distance import distance_rms, distance_weights

if TYPE_CHECKING:
    from artic.mjcf.vehicle import Vehicle
    from artic.validation.logs.runfile import Run

UNIT = "rad"


def eps_gamma(measured: pd.DataFrame, model: pd.DataFrame) -> float:
    """The articulation error of a model run against its log [rad].

    Parameters
    ----------
    measured : DataFrame
        The log, in the signal schema.
    model : DataFrame
        The model's run, sample for sample; if it stopped early, only its rows count.
    """
    n = len(model)
    meas = measured.iloc[:n]
    w = distance_weights(meas["t"].to_numpy(dtype=float),
                         np.hypot(meas["v_x_1"].to_numpy(dtype=float),
                                  meas["v_y_1"].to_numpy(dtype=float)))
    e = wrap_angle(model["gamma"].to_numpy(dtype=float) - meas["gamma"].to_numpy(dtype=float))
    return distance_rms(np.atleast_1d(e), w)


def of_run(log: Run, run: Run, vehicle: Vehicle) -> dict[str, float]:
    """``eps_gamma`` of a model run against its log [rad], as the runs compute it.

    The form every row of :data:`artic.validation.criteria.columns.TABLE` computed
    from a log and a run has; ``vehicle`` is not needed here.
    """
    return {"eps_gamma": eps_gamma(log.frame, run.frame)}
