"""Velocities and yaw rates of a pose-only log: a smoothing differentiator.

Motion trackers and many GNSS receivers log positions and headings only. The
derivatives are then taken here, on artic's uniform 100 Hz base (never on the
raw, possibly bursty stamps, so that a 1 ms interval cannot turn noise into a
rate), one gap-free segment at a time, with a quadratic Savitzky-Golay filter
of window ``W`` seconds (``[derive] window`` in the channel map, default
:data:`WINDOW`):

- the derivative is the slope at the centre of the least-squares quadratic
  over the window: exact for any quadratic motion (constant acceleration,
  steady turning), with no lag;
- a sinusoid of period ``T`` is differentiated with the gain
  ``3 (sin x - x cos x) / x**3 ~ 1 - x**2 / 10``, ``x = pi W / T`` (the
  continuous least-squares slope over ``+-W/2``): 1 % low at ``T = 10 W``;
- white noise of ``sigma`` on the samples becomes about
  ``sigma sqrt(12 / (n**3 dt**2))`` on the derivative with ``n = W / dt``
  samples: 1 cm of position noise gives about 1 cm/s at ``W = 0.5 s``, 100 Hz;
- at a segment's ends the quadratic fitted to its first or last window is
  differentiated (``mode="interp"``); a segment shorter than the window uses
  its whole length (at least :data:`MIN_SAMPLES` samples).

From the pose ``(x_i, y_i, psi_i)`` of unit ``i``: ``r_i = d psi_i / dt``;
the velocity in the plane ``(dx/dt, dy/dt)`` turned into the unit's axes by
``-psi_i`` gives ``v_x_i`` (forward) and ``v_y_i`` (left).
"""

from __future__ import annotations

import math

import numpy as np

from artic.mjcf.errors import UserError

WINDOW = 0.5
"""Default window of the differentiator [s]."""

MIN_SAMPLES = 5
"""Fewest samples a quadratic derivative is fitted to."""


def window_samples(dt: float, window: float, n: int) -> int:
    """The filter's odd window length in samples for a step ``dt`` [s] and ``n`` samples.

    Raises
    ------
    ValueError
        If the segment has fewer than :data:`MIN_SAMPLES` samples.
    """
    if n < MIN_SAMPLES:
        raise UserError(f"{n} samples are too few to differentiate (at least {MIN_SAMPLES})")
    k = max(MIN_SAMPLES, int(round(window / dt)))
    k = min(k, n)
    return k if k % 2 else k - 1


def derivative(t: np.ndarray, x: np.ndarray, window: float = WINDOW) -> np.ndarray:
    """Savitzky-Golay (quadratic) derivative of ``x`` on a uniform time base ``t``.

    Parameters
    ----------
    t : ndarray
        Time [s], uniform.
    x : ndarray
        Signal, any unit; an angle must be unwrapped.
    window : float
        Window [s].

    Returns
    -------
    ndarray
        ``dx/dt`` [unit/s].
    """
    from scipy.signal import savgol_filter

    t = np.asarray(t, dtype=float)
    dt = float(t[1] - t[0])
    k = window_samples(dt, window, t.size)
    return savgol_filter(np.asarray(x, dtype=float), k, 2, deriv=1, delta=dt, mode="interp")


def rates_from_pose(t: np.ndarray, x: np.ndarray, y: np.ndarray, psi: np.ndarray,
                    window: float = WINDOW) -> dict[str, np.ndarray]:
    """Velocity in the unit's axes and yaw rate from its pose.

    Parameters
    ----------
    t : ndarray
        Uniform time [s] of one gap-free segment.
    x, y : ndarray
        Position in the plane [m].
    psi : ndarray
        Yaw, unwrapped [rad].
    window : float
        Window of the differentiator [s].

    Returns
    -------
    dict
        ``v_x`` and ``v_y`` [m/s], ``r`` [rad/s].
    """
    ve, vn = derivative(t, x, window), derivative(t, y, window)
    c, s = np.cos(psi), np.sin(psi)
    return {"v_x": c * ve + s * vn, "v_y": -s * ve + c * vn, "r": derivative(t, psi, window)}


def sinusoid_gain(window: float, period: float) -> float:
    """The differentiator's gain on a sinusoid of ``period`` [s] (see the module docstring)."""
    x = math.pi * window / period
    return 3.0 * (math.sin(x) - x * math.cos(x)) / x ** 3 if x > 1e-6 else 1.0


SPEED_WINDOW = 0.5
"""Length of the window [s] over which the harness smooths a log's speed
(:mod:`artic.validation.harness.loop`, :func:`smooth_speed`)."""


def smooth_speed(t: np.ndarray, u: np.ndarray, window: float = SPEED_WINDOW) -> np.ndarray:
    """Quadratic Savitzky-Golay smoothing of a speed signal sampled at ``t`` [m/s].

    The log's time base is uniform (the importers make it so); the window is
    the odd number of samples nearest to ``window`` seconds. Logs shorter
    than the window are returned unchanged.
    """
    if u.size < 5:
        return u.copy()
    n = int(round(window / float(np.median(np.diff(t)))))
    n += 1 - n % 2
    if n < 5 or n > u.size:
        return u.copy()
    from scipy.signal import savgol_filter  # here: scipy.signal takes a second to import

    return savgol_filter(u, n, 2, mode="interp")
