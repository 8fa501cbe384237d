"""The distance-based error criteria, eqs. (8)-(10).

Every error is averaged over the distance travelled, not over time:

    eps_bar = sqrt( (1 / s_max) * integral eps**2 ds )              (8)

``s`` is the measured tractor sensor's path length. It always increases,
reversing included: ``ds = |v| dt`` with ``|v| = hypot(v_x_1, v_y_1)``. The
integral is the trapezoidal rule over the samples, so a constant error gives
back exactly that constant.

- Lateral position errors ``eps_y1``, ``eps_y2``: the shortest distance from
  each model sensor point to the measured sensor path, as a polyline.
- Yaw-rate errors ``eps_r1``, ``eps_r2`` and lateral-velocity errors
  ``eps_vy1``, ``eps_vy2``: model minus measurement at the same time.
- Totals (9): ``eps_p = eps_y1 + eps_y2``, ``eps_a = eps_r1 + eps_r2``,
  ``eps_v = eps_vy1 + eps_vy2``.
- ``eps_n`` [%]: ``eps_a`` and ``eps_v`` each divided by the distance-averaged
  mean of the absolute measured signals they compare (the sum of the two units'
  means), then added. Absolute values, because a slalom's plain mean is about
  zero. If a run has no yaw or lateral motion to speak of, the division means
  nothing and ``eps_n`` is NaN.
- ``J_steer`` [%] (10): the distance-RMS of the steering the harness added,
  ``delta - delta_center``, over the distance-averaged mean of
  ``|delta_center|``: both road-wheel angles.
"""

from __future__ import annotations

import numpy as np
import pandas as pd

from artic.validation.criteria.articulation import eps_gamma
from artic.validation.criteria.coverage import eps_cover
from artic.validation.criteria.distance import (
    distance_mean_abs,
    distance_rms,
    distance_weights,
)
from artic.validation.criteria.pathdist import distance_to_polyline

CRITERIA = ("eps_y1", "eps_y2", "eps_p", "eps_r1", "eps_r2", "eps_a",
            "eps_vy1", "eps_vy2", "eps_v", "eps_n", "J_steer")
"""Columns of a metrics row, in order."""

UNITS = {"eps_y1": "m", "eps_y2": "m", "eps_p": "m", "eps_r1": "rad/s", "eps_r2": "rad/s",
         "eps_a": "rad/s", "eps_vy1": "m/s", "eps_vy2": "m/s", "eps_v": "m/s",
         "eps_n": "%", "J_steer": "%"}

NOISE_FLOOR = {"r": 1e-3, "v_y": 1e-3}
"""Mean absolute signal [rad/s, m/s] below which normalising by it means nothing."""


def run_metrics(measured: pd.DataFrame, model: pd.DataFrame,
                positions: bool = True, beyond: bool = True) -> dict[str, float]:
    """Error criteria of one model run against its measured log.

    Parameters
    ----------
    measured : DataFrame
        The log, in the signal schema.
    model : DataFrame
        The model's run from the harness, sample for sample; if it stopped
        early, only its rows are compared.
    positions : bool
        Compute the lateral position errors (``eps_y1``, ``eps_y2``,
        ``eps_p``), the path distances that are most of this function's
        work; NaN when ``False`` (the gain sweep reports none of them).
    beyond : bool
        Add the criteria beyond the paper's that catch a model that does not follow the
        run: ``eps_gamma`` [rad] (:mod:`artic.validation.criteria.articulation`) and
        ``eps_cover`` [m] (:mod:`artic.validation.criteria.coverage`; NaN without
        ``positions``). The batch runs compute them with the rest of their table.

    Returns
    -------
    dict
        The :data:`CRITERIA`, ``eps_gamma`` and ``eps_cover`` (with ``beyond``), and
        ``s_max`` [m] (distance compared).

    See Also
    --------
    artic.run_closed_loop : the run it scores.
    artic.validate_runs : the criteria of many runs.

    Examples
    --------
    >>> import artic
    >>> vehicle = artic.load_vehicle("gosar2022-unloaded")
    >>> kin = artic.build_model("kin", vehicle)
    >>> log = artic.simulate(kin, vehicle, artic.make_profile("constant-steer", duration=8.0))
    >>> scores = artic.run_metrics(log.frame, artic.run_closed_loop(kin, log, vehicle).frame)
    >>> bool(scores["eps_p"] < 1e-6), bool(scores["s_max"] > 5.0)  # [m], [m]
    (True, True)
    >>> bool(scores["eps_cover"] < 1e-6), bool(scores["eps_gamma"] < 1e-6)  # [m], [rad]
    (True, True)
    """
    n = len(model)
    meas = measured.iloc[:n]
    col = {c: meas[c].to_numpy(dtype=float) for c in meas.columns if c != "delta_saturated"}
    sim = {c: model[c].to_numpy(dtype=float) for c in model.columns if c != "delta_saturated"}
    w = distance_weights(col["t"], np.hypot(col["v_x_1"], col["v_y_1"]))
    out: dict[str, float] = {}
    for i in (1, 2):
        pts = np.column_stack([sim[f"x_{i}"], sim[f"y_{i}"]])
        path = np.column_stack([col[f"x_{i}"], col[f"y_{i}"]])
        out[f"eps_y{i}"] = (distance_rms(distance_to_polyline(pts, path), w) if positions
                            else float("nan"))
        out[f"eps_r{i}"] = distance_rms(sim[f"r_{i}"] - col[f"r_{i}"], w)
        out[f"eps_vy{i}"] = distance_rms(sim[f"v_y_{i}"] - col[f"v_y_{i}"], w)
    out["eps_p"] = out["eps_y1"] + out["eps_y2"]
    out["eps_a"] = out["eps_r1"] + out["eps_r2"]
    out["eps_v"] = out["eps_vy1"] + out["eps_vy2"]
    r_mean = distance_mean_abs(col["r_1"], w) + distance_mean_abs(col["r_2"], w)
    vy_mean = distance_mean_abs(col["v_y_1"], w) + distance_mean_abs(col["v_y_2"], w)
    if r_mean > NOISE_FLOOR["r"] and vy_mean > NOISE_FLOOR["v_y"]:
        out["eps_n"] = 100.0 * (out["eps_a"] / r_mean + out["eps_v"] / vy_mean)
    else:
        out["eps_n"] = float("nan")
    if "delta_fb" in sim:
        delta_c = sim["delta"] - sim["delta_fb"]
        mean_c = distance_mean_abs(delta_c, w)
        out["J_steer"] = (100.0 * distance_rms(sim["delta_fb"], w) / mean_c
                          if mean_c > 0 else float("nan"))
    else:
        out["J_steer"] = float("nan")
    result = {k: out[k] for k in CRITERIA}
    if beyond:
        result["eps_gamma"] = eps_gamma(meas, model) if n else float("nan")
        result["eps_cover"] = eps_cover(meas, model) if positions else float("nan")
    result["s_max"] = float(np.sum(w))
    return result
