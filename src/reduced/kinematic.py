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
from reduced.integrate import make_rk4
from reduced.interface import InitialState, rotate, wrap_angle
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
    P : tuple
        ``(L1, L1c, L2)`` [m].
    """
    L1, L1c, L2 = P
    psi, gamma = x[2], x[3]
    r1 = u1 * math.tan(delta) / L1
    out = np.empty(4)
    out[0] = u1 * math.cos(psi)
    out[1] = u1 * math.sin(psi)
    out[2] = r1
    out[3] = -u1 * math.sin(gamma) / L2 + (1.0 - L1c * math.cos(gamma) / L2) * r1
    return out


kin_step = make_rk4(kin_rhs)
"""One RK4 step of :func:`kin_rhs`: ``kin_step(x, dt, u1, u1_dot, delta, P)``."""


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
    P : tuple
        ``(L1, L1c, L2)`` [m].
    s1 : ndarray, shape (2,)
        Tractor sensor ``(x, y)`` from the drive axle [m].
    s2 : ndarray, shape (2,)
        Semitrailer sensor ``(x, y)`` from the kingpin [m].
    """
    L1, L1c, L2 = P
    gamma = x[3]
    r1 = u1 * math.tan(delta) / L1
    r2 = (u1 * math.sin(gamma) + r1 * L1c * math.cos(gamma)) / L2
    return sensor_signals(x[0], x[1], x[2], gamma, u1, 0.0, r1, r2, L1c, s1, s2)


class KinematicModel:
    """KIN, eq. (1), behind the harness's model interface.

    Parameters
    ----------
    vehicle : Vehicle
        Uses ``L1``, ``L1c``, ``L2`` and the sensor positions. KIN has one
        equivalent axle per unit: the drive axle and the trailer axle group's
        centre; further tractor axles (a tag axle) are not represented.
    """

    name = "kin"

    def __init__(self, vehicle: Vehicle) -> None:
        self.vehicle = vehicle
        self.P = (vehicle.L1, vehicle.L1c, vehicle.L2)
        self._s1 = np.array(vehicle.sensor1[:2])
        self._s2 = np.array(vehicle.sensor2[:2])
        self.x = np.zeros(4)
        self._u1 = 0.0
        self._delta = 0.0

    def reset(self, initial: InitialState) -> None:
        """Place the drive axle so that the tractor sensor is at ``(x_1, y_1)``."""
        dx, dy = rotate(initial.psi_1, self._s1[0], self._s1[1])
        self.x = np.array([initial.x_1 - dx, initial.y_1 - dy, initial.psi_1,
                           wrap_angle(initial.gamma)])
        self._u1 = initial.u1
        self._delta = 0.0

    def step(self, dt: float, delta: float, u1: float, u1_dot: float) -> None:
        """Advance ``dt`` [s]; see :mod:`reduced.interface`."""
        self.x = kin_step(self.x, dt, u1, u1_dot, delta, self.P)
        self._u1 = u1 + u1_dot * dt
        self._delta = delta

    def observe(self, delta: float | None = None) -> np.ndarray:
        """Signals at the sensor points, in ``OBSERVATION`` order.

        Parameters
        ----------
        delta : float, optional
            Road-wheel angle about to be held [rad]; KIN's yaw rates follow it
            at once. The last applied angle by default.
        """
        d = self._delta if delta is None else delta
        y = kin_observe(self.x, self._u1, d, self.P, self._s1, self._s2)
        y[12] = wrap_angle(y[12])
        return y

    def compiled(self) -> tuple:
        """Compiled step and observe functions, state, parameters and sensors.

        For the harness's compiled closed loop; see :mod:`validation.harness`.
        """
        return kin_step, kin_observe, self.x.copy(), self.P, self._s1, self._s2

    @property
    def gamma(self) -> float:
        """Articulation angle [rad]."""
        return float(wrap_angle(self.x[3]))
