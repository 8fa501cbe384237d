"""Averages over the distance travelled: eq. (8)'s trapezoidal weights, RMS and mean.

Every criterion of artic averages over the tractor sensor's path length ``s``,
not over time (:mod:`artic.validation.criteria.metrics`); these are its pieces.
"""

from __future__ import annotations

import numpy as np
import pandas as pd


def distance_weights(t: np.ndarray, speed: np.ndarray) -> np.ndarray:
    """Trapezoidal weights ``w_k`` with ``integral g ds ~ sum_k w_k g_k`` [m].

    Parameters
    ----------
    t : ndarray
        Time [s], increasing.
    speed : ndarray
        Speed over ground, any sign [m/s]; its magnitude is used.

    Returns
    -------
    ndarray
        Weights; they sum to the distance travelled ``s_max``.
    """
    v = np.abs(np.asarray(speed, dtype=float))
    ds = 0.5 * (v[1:] + v[:-1]) * np.diff(np.asarray(t, dtype=float))
    w = np.zeros_like(v)
    w[:-1] += 0.5 * ds
    w[1:] += 0.5 * ds
    return w


def travelled(frame: pd.DataFrame) -> np.ndarray:
    """Running distance of the tractor sensor, ``integral |v| dt`` (trapezoidal) [m].

    The same integral as :func:`distance_weights`; its last value is ``s_max``.
    """
    v = np.hypot(frame["v_x_1"], frame["v_y_1"]).to_numpy()
    ds = 0.5 * (v[1:] + v[:-1]) * np.diff(frame["t"].to_numpy())
    return np.concatenate([[0.0], np.cumsum(ds)])


def distance_rms(eps: np.ndarray, w: np.ndarray) -> float:
    """Eq. (8): ``sqrt(integral eps**2 ds / s_max)``."""
    s_max = float(np.sum(w))
    if s_max <= 0.0:
        return float("nan")
    return float(np.sqrt(np.sum(w * np.square(eps)) / s_max))


def distance_mean_abs(x: np.ndarray, w: np.ndarray) -> float:
    """Distance-averaged mean of ``|x|``."""
    s_max = float(np.sum(w))
    return float(np.sum(w * np.abs(x)) / s_max) if s_max > 0 else float("nan")
