"""Signals at the two sensor points from the rigid-body motion of both units.

Both reduced models describe the tractor by a reference point on its centre
line (KIN: the drive axle; STM: the centre of gravity) and the semitrailer by
its yaw. The hitch lies ``x_h`` ahead of the reference point. Everything a
log shows follows from rigid-body kinematics:

- tractor sensor ``s1`` (from the reference point): velocity
  ``(u1 - r1 s1y, v_ref + r1 s1x)`` in tractor axes;
- hitch velocity ``(u1, v_ref + r1 x_h)`` in tractor axes, turned by ``-gamma``
  into semitrailer axes;
- semitrailer sensor ``s2`` (from the kingpin): hitch velocity plus
  ``r2 x s2``.
"""

from __future__ import annotations

import math

import numpy as np
from numba import njit


@njit(cache=True)
def sensor_signals(X, Y, psi1, gamma, u1, v_ref, r1, r2, x_h, sensors):
    """The 13 observed signals, in ``OBSERVATION`` order.

    Parameters
    ----------
    X, Y : float
        Reference point in the earth-fixed plane [m].
    psi1, gamma : float
        Tractor yaw and articulation [rad].
    u1, v_ref : float
        Reference point velocity in tractor axes [m/s].
    r1, r2 : float
        Yaw rates of tractor and semitrailer [rad/s].
    x_h : float
        Hitch position ahead of the reference point [m] (negative: behind).
    sensors : tuple of ndarray
        ``(s1, s2)``, each shape (2,): the tractor's sensor from the reference
        point, the semitrailer's from the kingpin, in their unit's axes [m].
    """
    s1, s2 = sensors
    c1, sn1 = math.cos(psi1), math.sin(psi1)
    psi2 = psi1 - gamma
    c2, sn2 = math.cos(psi2), math.sin(psi2)
    sg, cg = math.sin(gamma), math.cos(gamma)
    kx, ky = X + c1 * x_h, Y + sn1 * x_h
    vh = v_ref + r1 * x_h
    vhx = u1 * cg - vh * sg
    vhy = u1 * sg + vh * cg
    out = np.empty(13)
    out[0] = X + c1 * s1[0] - sn1 * s1[1]
    out[1] = Y + sn1 * s1[0] + c1 * s1[1]
    out[2] = psi1
    out[3] = u1 - r1 * s1[1]
    out[4] = v_ref + r1 * s1[0]
    out[5] = r1
    out[6] = kx + c2 * s2[0] - sn2 * s2[1]
    out[7] = ky + sn2 * s2[0] + c2 * s2[1]
    out[8] = psi2
    out[9] = vhx - r2 * s2[1]
    out[10] = vhy + r2 * s2[0]
    out[11] = r2
    out[12] = gamma
    return out
