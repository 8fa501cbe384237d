"""The reduced models behind the harness's model interface (see :mod:`artic.mjcf.interface`).

The equations live in :mod:`artic.reduced.kinematic` and :mod:`artic.reduced.single_track`,
the stepping in :mod:`artic.reduced.integrate`.
"""

from __future__ import annotations

import math

import numpy as np

from artic.mjcf.interface import InitialState, rotate, wrap_angle
from artic.mjcf.plausible import check_tyre_data
from artic.mjcf.vehicle import Vehicle
from artic.reduced.integrate import KIN, STM, observe, rk4_step
from artic.reduced.kinematic import kin_parameters, wheelbases
from artic.reduced.single_track import N_BODY, axle_velocities, stm_parameters, stm_unpack
from artic.reduced.tyre_linear import slip_angle

U_SLIP_KNOWN = 0.5
"""Axle speed above which a log's initial slip angle is taken as known [m/s]."""


class CompiledModel:
    """What both reduced models share: compiled stepping and observing.

    A subclass sets ``kind`` (:data:`artic.reduced.integrate.KIN` or ``STM``), ``name``,
    and in its constructor ``P`` (parameters), ``x`` (state) and the sensors
    ``_s1``, ``_s2``; it places the state in ``reset``.
    """

    kind: int
    name: str
    P: np.ndarray
    x: np.ndarray
    _s1: np.ndarray
    _s2: np.ndarray
    _u1: float = 0.0
    _delta: float = 0.0

    def step(self, dt: float, delta: float, u1: float, u1_dot: float) -> None:
        """Advance ``dt`` [s]; see :mod:`artic.mjcf.interface`."""
        self.x = rk4_step(self.kind, self.x, dt, u1, u1_dot, delta, self.P)
        self._u1 = u1 + u1_dot * dt
        self._delta = delta

    def observe(self, delta: float | None = None) -> np.ndarray:
        """Signals at the sensor points, in ``OBSERVATION`` order.

        Parameters
        ----------
        delta : float, optional
            Road-wheel angle about to be held [rad]; KIN's yaw rates follow it
            at once (the STM's velocities are states and do not jump). The
            last applied angle by default.
        """
        d = self._delta if delta is None else delta
        y = observe(self.kind, self.x, self._u1, d, self.P, self._s1, self._s2)
        y[12] = wrap_angle(y[12])
        return y

    def compiled(self) -> tuple:
        """Model kind, state, parameters and sensors, for compiled loops.

        See :mod:`artic.reduced.integrate` and :mod:`artic.validation.harness.loop`.
        """
        return self.kind, self.x.copy(), self.P, self._s1, self._s2

    def closed_loop(self) -> None:
        """No loop of its own: the harness's compiled loop runs :meth:`compiled`."""
        return None

    def close(self) -> None:
        """Nothing to release: a reduced model holds only arrays."""

    @property
    def gamma(self) -> float:
        """Articulation angle [rad]."""
        return float(wrap_angle(self.x[3]))


class KinematicModel(CompiledModel):
    """KIN, eq. (1), behind the harness's model interface.

    Parameters
    ----------
    vehicle : Vehicle
        Geometry, static axle loads and sensor positions. KIN has one
        equivalent axle per unit.
    wheelbase : str
        ``"equivalent"`` (default): each unit's axle group enters through its
        no-slip point, so a tag axle or a tridem counts; ``"paper"``: the drive
        axle and the middle trailer axle, as the paper has it. See
        :mod:`artic.reduced.kinematic`.
    """

    name = "kin"
    kind = KIN

    def __init__(self, vehicle: Vehicle, wheelbase: str = "equivalent") -> None:
        self.vehicle = vehicle
        self.wheelbase = wheelbase
        self.P = kin_parameters(vehicle, wheelbase)
        x_rear = wheelbases(vehicle, wheelbase)[2]
        # The state's point is the (equivalent) rear axle: the sensor from there.
        self._s1 = np.array([vehicle.sensor1[0] - x_rear, vehicle.sensor1[1]])
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


class SingleTrackModel(CompiledModel):
    """STM, eq. (2), behind the harness's model interface.

    Parameters
    ----------
    vehicle : Vehicle
        Masses, inertias, every axle, ``f`` and ``sigma_alpha``.
    f : float, optional
        Override of the normalised cornering stiffness [1/rad].
    trailer_axles : ndarray, optional
        Override of the trailer axle distances behind the kingpin [m].
    """

    name = "stm"
    kind = STM

    def __init__(self, vehicle: Vehicle, f: float | None = None,
                 trailer_axles: np.ndarray | None = None) -> None:
        check_tyre_data(vehicle, "stm")  # a scale model may have none: refused, by key
        self.vehicle = vehicle
        self.P = stm_parameters(vehicle, f, trailer_axles)
        self.n_axles = int(self.P[7] + self.P[8])
        self._s1 = np.array([vehicle.sensor1[0] - vehicle.b1, vehicle.sensor1[1]])
        self._s2 = np.array(vehicle.sensor2[:2])
        self.x = np.zeros(N_BODY + self.n_axles)
        self._u1 = 0.0
        self._delta = 0.0

    def reset(self, initial: InitialState) -> None:
        """Place the combination at ``initial``, tyres at steady-state slip.

        The steady-state slip angle is the travel direction's, which a
        measured velocity only gives when the axle moves well above the
        sensors' noise: with 1 cm/s of noise it is uncertain by 45 deg at
        1 cm/s and by 1 deg at 0.5 m/s. So the initial lagged slip is the
        steady-state one scaled by ``min(1, |v| / U_SLIP_KNOWN)``: relaxed
        tyres for a log that starts at rest, steady state for one that starts
        rolling. (Steady-state slip from a noisy 1 cm/s start gives slip
        angles near 90 deg and an oscillation of metres per second.)
        """
        s1x, s1y = self._s1
        dx, dy = rotate(initial.psi_1, s1x, s1y)
        v = initial.v_y_1 - initial.r_1 * s1x
        x = np.zeros(N_BODY + self.n_axles)
        x[:N_BODY] = [initial.x_1 - dx, initial.y_1 - dy, initial.psi_1,
                      wrap_angle(initial.gamma), v, initial.r_1, initial.r_1 - initial.r_2]
        # the steered axles' slip at the log's first road-wheel angle: a log that
        # starts in a turn would otherwise start with its slip off by that angle
        v_long, v_lat = self.axle_velocities(x, initial.u1, initial.delta)
        x[N_BODY:] = [slip_angle(a, b) * min(1.0, math.hypot(a, b) / U_SLIP_KNOWN)
                      for a, b in zip(v_long, v_lat, strict=True)]
        self.x = x
        self._u1 = initial.u1
        self._delta = initial.delta

    def axle_velocities(self, x: np.ndarray, u1: float, delta: float):
        """Axle-centre velocities ``(v_long, v_lat)`` in wheel frames [m/s]."""
        _, _, _, _, Lc, _, _, ax_x, ax_steer, tr_l, _ = stm_unpack(self.P)
        return axle_velocities(u1, x[4], x[5], x[3], x[6], delta, ax_x, ax_steer, tr_l, Lc)

    @property
    def tyre_forces(self) -> np.ndarray:
        """Lateral force of every axle, tractor first [N]."""
        return stm_unpack(self.P)[10] * self.x[N_BODY:]
