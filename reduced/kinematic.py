"""KIN: the single-axle kinematic tractor-semitrailer model, eq. (1).

No axle slips sideways: the tractor turns about a point on its drive-axle
line and the semitrailer about a point on its equivalent axle, ``L2`` behind
the kingpin. With the fifth wheel ``L1c`` ahead of the drive axle,

    psi_1_dot = u1 tan(delta) / L1
    gamma_dot = -u1 sin(gamma) / L2 + (1 - L1c cos(gamma) / L2) u1 tan(delta) / L1

Derivation: the hitch moves at ``(u1, r1 L1c)`` in tractor axes. The trailer
axle does not slip, so the trailer yaw rate is the hitch velocity across the
trailer, ``u1 sin(gamma) + r1 L1c cos(gamma)``, over ``L2``; and
``gamma_dot = r1 - r2``.

State: ``[X, Y, psi_1, gamma]`` with ``(X, Y)`` the drive-axle centre [m].
"""

from __future__ import annotations

import math

import numpy as np
from numba import njit

from mjcf.vehicle import Vehicle
from reduced.sensors import sensor_signals


@njit(cache=True)
def kin_rhs(x, u1, u1_dot, delta, P):
    """Time derivative of the KIN state, eq. (1).

    Parameters
    ----------
    x : ndarray, shape (4,)
        ``[X, Y, psi_1, gamma]`` [m, m, rad, rad].
    u1 : float
        Drive-axle longitudinal speed [m/s].
    u1_dot : float
        Its rate [m/s^2] (unused: KIN has no inertia).
    delta : float
        Road-wheel angle [rad].
    P : ndarray
        ``[L1, L1c, L2]`` [m], see :func:`kin_parameters`.
    """
    L1, L1c, L2 = P[0], P[1], P[2]
    psi, gamma = x[2], x[3]
    r1 = u1 * math.tan(delta) / L1
    out = np.empty(4)
    out[0] = u1 * math.cos(psi)
    out[1] = u1 * math.sin(psi)
    out[2] = r1
    out[3] = -u1 * math.sin(gamma) / L2 + (1.0 - L1c * math.cos(gamma) / L2) * r1
    return out


@njit(cache=True)
def kin_observe(x, u1, delta, P, s1, s2):
    """Signals at the two sensor points, in ``OBSERVATION`` order.

    Parameters
    ----------
    x : ndarray, shape (4,)
        State.
    u1 : float
        Drive-axle longitudinal speed [m/s].
    delta : float
        Road-wheel angle [rad].
    P : ndarray
        ``[L1, L1c, L2]`` [m].
    s1 : ndarray, shape (2,)
        Tractor sensor ``(x, y)`` from the drive axle [m].
    s2 : ndarray, shape (2,)
        Semitrailer sensor ``(x, y)`` from the kingpin [m].
    """
    L1, L1c, L2 = P[0], P[1], P[2]
    gamma = x[3]
    r1 = u1 * math.tan(delta) / L1
    r2 = (u1 * math.sin(gamma) + r1 * L1c * math.cos(gamma)) / L2
    return sensor_signals(x[0], x[1], x[2], gamma, u1, 0.0, r1, r2, L1c, s1, s2)


def kin_parameters(vehicle: Vehicle) -> np.ndarray:
    """Pack a vehicle into KIN's parameter array ``[L1, L1c, L2]`` [m]."""
    return np.array([vehicle.L1, vehicle.L1c, vehicle.L2])
