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
paper's (11) and (13). Its (12) agrees once the printed ``psi_1_ddot`` in the
first row is read as ``psi_1_dot**2``.

The speed ``u`` is prescribed, so the first row only sets the traction force.
The other three give ``(v_dot, r_dot, gamma_ddot)``, and in them the
``M[1:, 0] * u_dot`` terms stay: ``-m2 a2 sin(gamma) u_dot`` (yaw row) and
``+m2 a2 sin(gamma) u_dot`` (articulation row).

Any number of axles per unit. Each axle's lateral force acts at its centre,
and its generalised force is its partial velocity dotted with the force.

State: ``[X, Y, psi_1, gamma, v, r, gamma_dot, alpha'_1 ... alpha'_n]``, with
``(X, Y)`` the tractor centre of gravity [m] (KIN's is its rear axle, a log's
its sensor) and ``alpha'`` the lagged slip
angle of every axle in file order (see :mod:`artic.reduced.tyre_linear`).
"""

from __future__ import annotations

import math
from typing import NamedTuple

import numpy as np
from numba import njit

from artic.mjcf.vehicle import Vehicle
from artic.reduced.sensors import sensor_signals
from artic.reduced.tyre_linear import slip_rate

N_BODY = 7
"""Number of rigid-body states before the slip states."""

STM_LC = 4
"""Index of ``Lc`` in the parameter array."""


@njit(cache=True)
def mass_and_bias(gamma, u, v, r, gamma_dot, inertia):
    """Mass matrix ``M(gamma)`` and velocity-product vector ``h(gamma, w)``.

    Both cover all four generalised speeds ``(u, v, r, gamma_dot)``, so the
    free system (``u`` not prescribed) can be integrated too. ``inertia`` is
    ``(m1, J1, m2, J2, Lc, a2)``, as :func:`stm_unpack` gives them [kg, kg m^2, m].

    Returns
    -------
    M : ndarray, shape (4, 4)
        [kg, kg m, kg m^2].
    h : ndarray, shape (4,)
        [N, N m].
    """
    m1, J1, m2, J2, Lc, a2 = inertia
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


@njit(cache=True, inline="always")
def axle_velocity(i, u, v, r, gamma_dot, trig, axles):
    """Velocity of axle ``i`` (tractor axles first) in its wheel frame [m/s].

    ``trig`` is ``(cg, sg, cd, sd)``, the cosine and sine of the articulation and
    of the road-wheel angle; ``axles`` is ``(ax_x, ax_steer, tr_l, Lc)`` (see
    :func:`axle_velocities`). Returns ``(v_long, v_lat)``.
    """
    cg, sg, cd, sd = trig
    ax_x, ax_steer, tr_l, Lc = axles
    n1 = ax_x.size
    if i < n1:
        vy = v + r * ax_x[i]
        if ax_steer[i] > 0.5:
            return u * cd + vy * sd, -u * sd + vy * cd
        return u, vy
    vh = v - r * Lc
    return u * cg - vh * sg, u * sg + vh * cg - (r - gamma_dot) * tr_l[i - n1]


@njit(cache=True, inline="always")
def axle_generalised_force(i, F, trig, axles):
    """Axle ``i``'s share ``(Q_u, Q_v, Q_r, Q_gamma_dot)`` of ``Q`` for its lateral force ``F``.

    The partial velocities of the axle centre, dotted with the force along
    the wheel's lateral axis; ``trig`` and ``axles`` as for :func:`axle_velocity`.
    """
    cg, sg, cd, sd = trig
    ax_x, ax_steer, tr_l, Lc = axles
    n1 = ax_x.size
    if i < n1:
        if ax_steer[i] > 0.5:
            return -F * sd, F * cd, ax_x[i] * F * cd, 0.0
        return 0.0, F, ax_x[i] * F, 0.0
    k = i - n1
    return F * sg, F * cg, -(Lc * cg + tr_l[k]) * F, tr_l[k] * F


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
    n = ax_x.size + tr_l.size
    v_long = np.empty(n)
    v_lat = np.empty(n)
    cg, sg = math.cos(gamma), math.sin(gamma)
    cd, sd = math.cos(delta), math.sin(delta)
    for i in range(n):
        v_long[i], v_lat[i] = axle_velocity(i, u, v, r, gamma_dot, (cg, sg, cd, sd),
                                            (ax_x, ax_steer, tr_l, Lc))
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
    Q = np.zeros(4)
    cg, sg = math.cos(gamma), math.sin(gamma)
    cd, sd = math.cos(delta), math.sin(delta)
    for i in range(F.size):
        q0, q1, q2, q3 = axle_generalised_force(i, F[i], (cg, sg, cd, sd),
                                                (ax_x, ax_steer, tr_l, Lc))
        Q[0] += q0
        Q[1] += q1
        Q[2] += q2
        Q[3] += q3
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


@njit(cache=True, inline="always")
def stm_unpack(P):
    """Split the STM's packed parameter array (:meth:`StmParameters.packed`), compiled.

    Returns
    -------
    tuple
        ``(m1, J1, m2, J2, Lc, a2, sigma, ax_x, ax_steer, tr_l, C)``; the arrays
        are views of ``P``.
    """
    n1, n2 = int(P[7]), int(P[8])
    i = 9
    ax_x = P[i:i + n1]
    ax_steer = P[i + n1:i + 2 * n1]
    tr_l = P[i + 2 * n1:i + 2 * n1 + n2]
    C = P[i + 2 * n1 + n2:i + 3 * n1 + 2 * n2]
    return P[0], P[1], P[2], P[3], P[4], P[5], P[6], ax_x, ax_steer, tr_l, C


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
    P : ndarray
        Parameter array, see :func:`stm_parameters`.
    """
    out = np.empty(x.size)
    stm_rhs_into(x, u1, u1_dot, delta, P, out)
    return out


@njit(cache=True)
def stm_rhs_into(x, u1, u1_dot, delta, P, out):
    """:func:`stm_rhs` written into ``out`` (shape (n,)): the one copy of the equations.

    :func:`stm_rhs` and the batched steps of :mod:`artic.reduced.integrate`
    both call it, so they agree to the bit.
    """
    m1, J1, m2, J2, Lc, a2, sigma, ax_x, ax_steer, tr_l, C = stm_unpack(P)
    psi, gamma, v, r, gd = x[2], x[3], x[4], x[5], x[6]
    cg, sg = math.cos(gamma), math.sin(gamma)
    cd, sd = math.cos(delta), math.sin(delta)
    trig, axles = (cg, sg, cd, sd), (ax_x, ax_steer, tr_l, Lc)
    # One pass over the axles (the per-axle kernels of axle_velocities and
    # generalised_forces), with no temporary arrays: this is the hot loop.
    Q1 = Q2 = Q3 = 0.0
    for i in range(C.size):
        a = x[N_BODY + i]
        _, q1, q2, q3 = axle_generalised_force(i, C[i] * a, trig, axles)
        Q1 += q1
        Q2 += q2
        Q3 += q3
        vl, vt = axle_velocity(i, u1, v, r, gd, trig, axles)
        out[N_BODY + i] = slip_rate(vl, vt, a, sigma)
    M, h = mass_and_bias(gamma, u1, v, r, gd, (m1, J1, m2, J2, Lc, a2))
    b = np.empty(3)
    b[0] = Q1 - h[1] - M[1, 0] * u1_dot
    b[1] = Q2 - h[2] - M[2, 0] * u1_dot
    b[2] = Q3 - h[3] - M[3, 0] * u1_dot
    wdot = solve3(M[1:, 1:], b)
    cp, sp = math.cos(psi), math.sin(psi)
    out[0] = u1 * cp - v * sp
    out[1] = u1 * sp + v * cp
    out[2] = r
    out[3] = gd
    out[4] = wdot[0]
    out[5] = wdot[1]
    out[6] = wdot[2]


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
    P : ndarray
        Parameter array, as for :func:`stm_rhs`.
    s1 : ndarray, shape (2,)
        Tractor sensor ``(x, y)`` from the tractor centre of gravity [m].
    s2 : ndarray, shape (2,)
        Semitrailer sensor ``(x, y)`` from the kingpin [m].
    """
    r = x[5]
    return sensor_signals(x[0], x[1], x[2], x[3], u1, x[4], r, r - x[6], -P[STM_LC], (s1, s2))


class StmParameters(NamedTuple):
    """The STM's parameters, by name.

    Axles are listed tractor first, each unit's in the vehicle file's order.

    Attributes
    ----------
    m1, m2 : float
        Tractor and semitrailer masses [kg].
    J1, J2 : float
        Their yaw inertias about their centres of gravity [kg m^2].
    Lc : float
        Fifth wheel behind the tractor's centre of gravity [m].
    a2 : float
        Semitrailer's centre of gravity behind the kingpin [m].
    sigma_alpha : float
        Relaxation length of the lagged slip angles [m].
    ax_x : ndarray
        Tractor axle positions ahead of its centre of gravity [m].
    ax_steer : ndarray
        1.0 for a steered tractor axle, else 0.0.
    tr_l : ndarray
        Semitrailer axle distances behind the kingpin [m].
    C : ndarray
        Cornering stiffness of every axle, tractor first [N/rad].
    """

    m1: float
    J1: float
    m2: float
    J2: float
    Lc: float
    a2: float
    sigma_alpha: float
    ax_x: np.ndarray
    ax_steer: np.ndarray
    tr_l: np.ndarray
    C: np.ndarray

    @property
    def n_axles(self) -> int:
        """Number of axles, both units."""
        return int(self.C.size)

    def packed(self) -> np.ndarray:
        """The flat array the compiled functions take (:func:`stm_unpack` reads it).

        Layout: ``[m1, J1, m2, J2, Lc, a2, sigma_alpha, n1, n2, ax_x (n1),
        ax_steer (n1), tr_l (n2), C (n1 + n2)]``.
        """
        return np.concatenate([
            [self.m1, self.J1, self.m2, self.J2, self.Lc, self.a2, self.sigma_alpha,
             self.ax_x.size, self.tr_l.size], self.ax_x, self.ax_steer, self.tr_l, self.C])

    @classmethod
    def from_packed(cls, P: np.ndarray) -> StmParameters:
        """The parameters of a packed array (:meth:`packed`)."""
        m1, J1, m2, J2, Lc, a2, sigma, ax_x, ax_steer, tr_l, C = stm_unpack(P)
        return cls(float(m1), float(J1), float(m2), float(J2), float(Lc), float(a2),
                   float(sigma), ax_x.copy(), ax_steer.copy(), tr_l.copy(), C.copy())


def stm_params(vehicle: Vehicle, f: float | None = None,
               trailer_axles: np.ndarray | None = None) -> StmParameters:
    """The STM's parameters of a vehicle, by name.

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
    return StmParameters(vehicle.m1, vehicle.J1, vehicle.m2, vehicle.J2, vehicle.Lc, vehicle.a2,
                         vehicle.sigma_alpha, ax_x, ax_steer, tr_l, C)


def stm_parameters(vehicle: Vehicle, f: float | None = None,
                   trailer_axles: np.ndarray | None = None) -> np.ndarray:
    """The STM's parameters as the compiled functions take them.

    :func:`stm_params` packed (:meth:`StmParameters.packed`); see there for the
    parameters and the layout.
    """
    return stm_params(vehicle, f, trailer_axles).packed()
