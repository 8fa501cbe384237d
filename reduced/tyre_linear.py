"""Linear axle tyre of the single-track model, eq. (14), with transient slip.

Force: ``F_y = f * Fz * alpha'``. The axle cornering stiffness ``C = f * Fz``
scales with the static axle load, as the paper's normalised stiffness does.
The force is linear: no saturation.

Slip from the travel direction. The steady-state slip angle is
``alpha = -atan2(v_lat, |v_long|)`` in the axle's own frame. The ``|v_long|``
makes it oppose the lateral velocity in reverse as well as forward. A plain
``-v_lat / v_long`` would push the wrong way in reverse.

Zero speed. The slip angle is undefined at standstill, and a tyre without
lag becomes infinitely stiff as the speed goes to zero. The model lags the
slip angle instead, over a relaxation length ``sigma`` [m]:

    d alpha' / dt = (|v| / sigma) * (alpha - alpha')

with ``|v|`` the axle's speed over ground. For small slip this is the
classic ``sigma alpha'_dot + |v_long| alpha' = -v_lat``. The rate is bounded
by ``pi |v| / sigma``, so nothing is singular at ``v = 0``: the slip state, and
with it the force, freezes while the axle stands still and picks up again as
it rolls, in either direction.
"""

from __future__ import annotations

import math

from numba import njit


@njit(cache=True, inline="always")
def slip_angle(v_long: float, v_lat: float) -> float:
    """Steady-state slip angle from the travel direction [rad].

    Parameters
    ----------
    v_long, v_lat : float
        Axle-centre velocity along and across the wheel plane [m/s].

    Returns
    -------
    float
        In [-pi/2, pi/2]; positive when the axle slides to the right (a
        positive slip angle gives a positive, leftward force). 0 at standstill.
    """
    return -math.atan2(v_lat, abs(v_long))


@njit(cache=True, inline="always")
def slip_rate(v_long: float, v_lat: float, alpha_lag: float, sigma: float) -> float:
    """Rate of the lagged slip angle ``alpha'`` [rad/s].

    Parameters
    ----------
    v_long, v_lat : float
        Axle-centre velocity in the wheel frame [m/s].
    alpha_lag : float
        Current lagged slip angle [rad].
    sigma : float
        Relaxation length [m].
    """
    speed = math.sqrt(v_long * v_long + v_lat * v_lat)
    return speed / sigma * (slip_angle(v_long, v_lat) - alpha_lag)
