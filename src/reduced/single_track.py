"""STM: the non-linear single-track tractor-semitrailer model, eq. (2).

Generalised speeds ``w = (u, v, r, gamma_dot)``: the tractor centre of gravity's
velocity in tractor axes, the tractor yaw rate ``r = psi_1_dot`` and the
articulation rate. The trailer yaw rate is ``r - gamma_dot``.

Derivation (Kane's method). The trailer centre of gravity lies ``a2`` behind the
hitch, which lies ``Lc`` behind the tractor's. In tractor axes its velocity is

    V2 = (u - a2 w2 sin(gamma),  v - r Lc - a2 w2 cos(gamma)),    w2 = r - gamma_dot,

so its partial velocities, the columns of ``dV2/dw``, are ``(1, 0)``,
``(0, 1)``, ``(-a2 sin, -Lc - a2 cos)`` and ``(a2 sin, a2 cos)``. Then

    M_jk = m1 dV1_j . dV1_k + m2 dV2_j . dV2_k + J1 dw1_j dw1_k + J2 dw2_j dw2_k
    h_j  = m1 dV1_j . a1(w) + m2 dV2_j . a2(w)

with ``a(w)`` the velocity-product part of each acceleration, including the
rotating frame's ``r x V``. The equations ``M w_dot + h = Q`` reproduce the
seed's (11) and (13). Its (12) agrees once the printed ``psi_1_ddot`` in the
first row is read as ``psi_1_dot**2``.

The speed ``u`` is prescribed, so the first row only sets the traction force.
The other three give ``(v_dot, r_dot, gamma_ddot)``, and in them the
``M[1:, 0] * u_dot`` terms stay: ``-m2 a2 sin(gamma) u_dot`` (yaw row) and
``+m2 a2 sin(gamma) u_dot`` (articulation row).

Any number of axles per unit. Each axle's lateral force acts at its centre,
and its generalised force is its partial velocity dotted with the force.

State: ``[X, Y, psi_1, gamma, v, r, gamma_dot, alpha'_1 ... alpha'_n]``, with
``(X, Y)`` the tractor centre of gravity [m] and ``alpha'`` the lagged slip
angle of every axle in file order (see :mod:`reduced.tyre_linear`).
"""

from __future__ import annotations

import math

import numpy as np
from numba import njit

from mjcf.vehicle import Vehicle
from reduced.integrate import make_rk4
from reduced.interface import InitialState, rotate, wrap_angle
from reduced.sensors import sensor_signals
from reduced.tyre_linear import slip_angle, slip_rate

N_BODY = 7
"""Number of rigid-body states before the slip states."""


@njit(cache=True)
def mass_and_bias(gamma, u, v, r, gamma_dot, m1, J1, m2, J2, Lc, a2):
    """Mass matrix ``M(gamma)`` and velocity-product vector ``h(gamma, w)``.

    Both cover all four generalised speeds ``(u, v, r, gamma_dot)``, so the
    free system (``u`` not prescribed) can be integrated too.

    Returns
    -------
    M : ndarray, shape (4, 4)
        [kg, kg m, kg m^2].
    h : ndarray, shape (4,)
        [N, N m].
    """
    s, c = math.sin(gamma), math.cos(gamma)
    w2 = r - gamma_dot
    V2x = u - a2 * w2 * s
    V2y = v - r * Lc - a2 * w2 * c
    px = (1.0, 0.0, -a2 * s, a2 * s)
    py = (0.0, 1.0, -Lc - a2 * c, a2 * c)
    # Velocity-product accelerations of both centres of gravity, tractor axes.
    a1x, a1y = -r * v, r * u
    a2x = -a2 * w2 * c * gamma_dot - r * V2y
    a2y = a2 * w2 * s * gamma_dot + r * V2x
    M = np.empty((4, 4))
    h = np.empty(4)
    for i in range(4):
        for k in range(4):
            M[i, k] = m2 * (px[i] * px[k] + py[i] * py[k])
        h[i] = m2 * (px[i] * a2x + py[i] * a2y)
    M[0, 0] += m1
    M[1, 1] += m1
    M[2, 2] += J1 + J2
    M[3, 3] += J2
    M[2, 3] -= J2
    M[3, 2] -= J2
    h[0] += m1 * a1x
    h[1] += m1 * a1y
    return M, h


@njit(cache=True)
def axle_velocities(u, v, r, gamma, gamma_dot, delta, ax_x, ax_steer, tr_l, Lc):
    """Axle-centre velocities in each axle's wheel frame [m/s].

    Parameters
    ----------
    ax_x : ndarray
        Tractor axle positions from the tractor centre of gravity [m].
    ax_steer : ndarray
        1.0 for steered tractor axles, else 0.0.
    tr_l : ndarray
        Trailer axle distances behind the kingpin [m].

    Returns
    -------
    v_long, v_lat : ndarray
        Tractor axles first, then trailer axles.
    """
    n1, n2 = ax_x.size, tr_l.size
    v_long = np.empty(n1 + n2)
    v_lat = np.empty(n1 + n2)
    cd, sd = math.cos(delta), math.sin(delta)
    for i in range(n1):
        vy = v + r * ax_x[i]
        if ax_steer[i] > 0.5:
            v_long[i] = u * cd + vy * sd
            v_lat[i] = -u * sd + vy * cd
        else:
            v_long[i] = u
            v_lat[i] = vy
    s, c = math.sin(gamma), math.cos(gamma)
    w2 = r - gamma_dot
    vh = v - r * Lc
    for k in range(n2):
        v_long[n1 + k] = u * c - vh * s
        v_lat[n1 + k] = u * s + vh * c - w2 * tr_l[k]
    return v_long, v_lat


@njit(cache=True)
def generalised_forces(F, gamma, delta, ax_x, ax_steer, tr_l, Lc):
    """Generalised forces of the axles' lateral forces, ``Q`` of eq. (13).

    Parameters
    ----------
    F : ndarray
        Lateral force of every axle in its wheel frame [N], tractor first.

    Returns
    -------
    ndarray, shape (4,)
        ``(Q_u, Q_v, Q_r, Q_gamma_dot)`` [N, N, N m, N m].
    """
    n1 = ax_x.size
    Q = np.zeros(4)
    cd, sd = math.cos(delta), math.sin(delta)
    for i in range(n1):
        if ax_steer[i] > 0.5:
            Q[0] -= F[i] * sd
            Q[1] += F[i] * cd
            Q[2] += ax_x[i] * F[i] * cd
        else:
            Q[1] += F[i]
            Q[2] += ax_x[i] * F[i]
    s, c = math.sin(gamma), math.cos(gamma)
    for k in range(tr_l.size):
        f = F[n1 + k]
        Q[0] += f * s
        Q[1] += f * c
        Q[2] -= (Lc * c + tr_l[k]) * f
        Q[3] += tr_l[k] * f
    return Q


@njit(cache=True)
def solve3(A, b):
    """Solve the 3x3 system ``A x = b`` by Cramer's rule (``A`` is the SPD mass block)."""
    c00 = A[1, 1] * A[2, 2] - A[1, 2] * A[2, 1]
    c01 = A[1, 2] * A[2, 0] - A[1, 0] * A[2, 2]
    c02 = A[1, 0] * A[2, 1] - A[1, 1] * A[2, 0]
    det = A[0, 0] * c00 + A[0, 1] * c01 + A[0, 2] * c02
    c10 = A[0, 2] * A[2, 1] - A[0, 1] * A[2, 2]
    c11 = A[0, 0] * A[2, 2] - A[0, 2] * A[2, 0]
    c12 = A[0, 1] * A[2, 0] - A[0, 0] * A[2, 1]
    c20 = A[0, 1] * A[1, 2] - A[0, 2] * A[1, 1]
    c21 = A[0, 2] * A[1, 0] - A[0, 0] * A[1, 2]
    c22 = A[0, 0] * A[1, 1] - A[0, 1] * A[1, 0]
    out = np.empty(3)
    out[0] = (c00 * b[0] + c10 * b[1] + c20 * b[2]) / det
    out[1] = (c01 * b[0] + c11 * b[1] + c21 * b[2]) / det
    out[2] = (c02 * b[0] + c12 * b[1] + c22 * b[2]) / det
    return out


@njit(cache=True)
def stm_rhs(x, u1, u1_dot, delta, P):
    """Time derivative of the STM state with ``u`` prescribed.

    Parameters
    ----------
    x : ndarray
        State, see the module docstring.
    u1, u1_dot : float
        Tractor longitudinal speed [m/s] and its rate [m/s^2].
    delta : float
        Road-wheel angle [rad].
    P : tuple
        ``(m1, J1, m2, J2, Lc, a2, sigma, ax_x, ax_steer, tr_l, C)``.
    """
    m1, J1, m2, J2, Lc, a2, sigma, ax_x, ax_steer, tr_l, C = P
    psi, gamma, v, r, gd = x[2], x[3], x[4], x[5], x[6]
    alpha = x[N_BODY:]
    v_long, v_lat = axle_velocities(u1, v, r, gamma, gd, delta, ax_x, ax_steer, tr_l, Lc)
    Q = generalised_forces(C * alpha, gamma, delta, ax_x, ax_steer, tr_l, Lc)
    M, h = mass_and_bias(gamma, u1, v, r, gd, m1, J1, m2, J2, Lc, a2)
    rhs = Q[1:] - h[1:] - M[1:, 0] * u1_dot
    wdot = solve3(M[1:, 1:], rhs)
    out = np.empty(x.size)
    cp, sp = math.cos(psi), math.sin(psi)
    out[0] = u1 * cp - v * sp
    out[1] = u1 * sp + v * cp
    out[2] = r
    out[3] = gd
    out[4] = wdot[0]
    out[5] = wdot[1]
    out[6] = wdot[2]
    for i in range(alpha.size):
        out[N_BODY + i] = slip_rate(v_long[i], v_lat[i], alpha[i], sigma)
    return out


stm_step = make_rk4(stm_rhs)
"""One RK4 step of :func:`stm_rhs`: ``stm_step(x, dt, u1, u1_dot, delta, P)``."""


@njit(cache=True)
def stm_observe(x, u1, delta, P, s1, s2):
    """Signals at the two sensor points, in ``OBSERVATION`` order.

    Parameters
    ----------
    x : ndarray
        State.
    u1 : float
        Tractor longitudinal speed [m/s].
    delta : float
        Road-wheel angle [rad] (unused: the STM's velocities are states).
    P : tuple
        Parameters, as for :func:`stm_rhs`.
    s1 : ndarray, shape (2,)
        Tractor sensor ``(x, y)`` from the tractor centre of gravity [m].
    s2 : ndarray, shape (2,)
        Semitrailer sensor ``(x, y)`` from the kingpin [m].
    """
    r = x[5]
    return sensor_signals(x[0], x[1], x[2], x[3], u1, x[4], r, r - x[6], -P[4], s1, s2)


def stm_parameters(vehicle: Vehicle, f: float | None = None,
                   trailer_axles: np.ndarray | None = None) -> tuple:
    """Pack a vehicle into the STM's parameter tuple.

    Parameters
    ----------
    vehicle : Vehicle
        Masses, inertias, geometry and static axle loads.
    f : float, optional
        Normalised cornering stiffness [1/rad]; the vehicle's by default.
    trailer_axles : ndarray, optional
        Replace the trailer axles by these distances behind the kingpin [m],
        sharing the trailer group's load equally (for model studies).
    """
    f = vehicle.f if f is None else f
    tractor = vehicle.tractor_axles
    loads = vehicle.static_loads
    n1 = len(tractor)
    ax_x = np.array([a.x - vehicle.b1 for a in tractor])
    ax_steer = np.array([1.0 if a.steered else 0.0 for a in tractor])
    if trailer_axles is None:
        tr_l = vehicle.trailer_axle_distances
        tr_fz = loads[n1:]
    else:
        tr_l = np.asarray(trailer_axles, dtype=float)
        tr_fz = np.full(tr_l.size, loads[n1:].sum() / tr_l.size)
    C = f * np.concatenate([loads[:n1], tr_fz])
    return (vehicle.m1, vehicle.J1, vehicle.m2, vehicle.J2, vehicle.Lc, vehicle.a2,
            vehicle.sigma_alpha, ax_x, ax_steer, tr_l, C)


class SingleTrackModel:
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

    def __init__(self, vehicle: Vehicle, f: float | None = None,
                 trailer_axles: np.ndarray | None = None) -> None:
        self.vehicle = vehicle
        self.P = stm_parameters(vehicle, f, trailer_axles)
        self.n_axles = self.P[7].size + self.P[9].size
        self._s1 = np.array([vehicle.sensor1[0] - vehicle.b1, vehicle.sensor1[1]])
        self._s2 = np.array(vehicle.sensor2[:2])
        self.x = np.zeros(N_BODY + self.n_axles)
        self._u1 = 0.0
        self._delta = 0.0

    def reset(self, initial: InitialState) -> None:
        """Place the combination at ``initial``, tyres at steady-state slip."""
        s1x, s1y = self._s1
        dx, dy = rotate(initial.psi_1, s1x, s1y)
        v = initial.v_y_1 - initial.r_1 * s1x
        x = np.zeros(N_BODY + self.n_axles)
        x[:N_BODY] = [initial.x_1 - dx, initial.y_1 - dy, initial.psi_1,
                      wrap_angle(initial.gamma), v, initial.r_1, initial.r_1 - initial.r_2]
        v_long, v_lat = self.axle_velocities(x, initial.u1, 0.0)
        x[N_BODY:] = [slip_angle(a, b) for a, b in zip(v_long, v_lat, strict=True)]
        self.x = x
        self._u1 = initial.u1
        self._delta = 0.0

    def step(self, dt: float, delta: float, u1: float, u1_dot: float) -> None:
        """Advance ``dt`` [s]; see :mod:`reduced.interface`."""
        self.x = stm_step(self.x, dt, u1, u1_dot, delta, self.P)
        self._u1 = u1 + u1_dot * dt
        self._delta = delta

    def observe(self, delta: float | None = None) -> np.ndarray:
        """Signals at the sensor points, in ``OBSERVATION`` order.

        ``delta`` is accepted for the common interface; the STM's velocities
        are states and do not jump with the steering.
        """
        y = stm_observe(self.x, self._u1, self._delta, self.P, self._s1, self._s2)
        y[12] = wrap_angle(y[12])
        return y

    def compiled(self) -> tuple:
        """Compiled step and observe functions, state, parameters and sensors.

        For the harness's compiled closed loop; see :mod:`validation.harness`.
        """
        return stm_step, stm_observe, self.x.copy(), self.P, self._s1, self._s2

    def axle_velocities(self, x: np.ndarray, u1: float, delta: float):
        """Axle-centre velocities ``(v_long, v_lat)`` in wheel frames [m/s]."""
        _, _, _, _, Lc, _, _, ax_x, ax_steer, tr_l, _ = self.P
        return axle_velocities(u1, x[4], x[5], x[3], x[6], delta, ax_x, ax_steer, tr_l, Lc)

    @property
    def tyre_forces(self) -> np.ndarray:
        """Lateral force of every axle, tractor first [N]."""
        return self.P[10] * self.x[N_BODY:]

    @property
    def gamma(self) -> float:
        """Articulation angle [rad]."""
        return float(wrap_angle(self.x[3]))
