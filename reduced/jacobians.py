"""Analytic Jacobians of KIN's and STM's right-hand sides, derived by hand.

``A = df/dx`` and ``B = df/d(delta, u1, u1_dot)`` of :func:`artic.reduced.kinematic.kin_rhs`
and :func:`artic.reduced.single_track.stm_rhs`, term by term, so that a planner
linearises without differentiating numba functions numerically. Both are
checked against central finite differences of the right-hand sides
(``tests/test_control.py``). The classes a planner uses are in
:mod:`artic.reduced.control`.

**KIN**, eq. (1), with ``r1 = u1 tan(delta) / L1`` and ``k = 1 - L1c cos(gamma) / L2``::

    X_dot     = u1 cos(psi_1)   d/dpsi_1 = -u1 sin(psi_1)  d/du1 = cos(psi_1)
    Y_dot     = u1 sin(psi_1)   d/dpsi_1 =  u1 cos(psi_1)  d/du1 = sin(psi_1)
    psi_1_dot = r1              d/ddelta = u1 / (L1 cos^2(delta))
                                d/du1    = tan(delta) / L1
    gamma_dot = -u1 sin(gamma) / L2 + k r1
        d/dgamma = -u1 cos(gamma) / L2 + (L1c sin(gamma) / L2) r1
        d/ddelta = k u1 / (L1 cos^2(delta))
        d/du1    = -sin(gamma) / L2 + k tan(delta) / L1

About the straight line (``gamma = delta = 0``) the articulation row is eq. (4),
``gamma_dot = u1 (-gamma / L2 + (1 - L1c / L2) delta / L1)``, with the eigenvalue
``-u1 / L2``: positive, unstable, in reverse.

**STM**, eq. (2). The state is ``[X, Y, psi_1, gamma, v, r, gamma_dot, alpha'_i]``
and every row but the kinematic ones depends on the body through
``z = (gamma, v, r, gamma_dot, u1, delta)``. Three pieces, each differentiated
in ``z`` and combined by the chain rule:

1. *Axle velocities* (:func:`artic.reduced.single_track.axle_velocity`), in the
   wheel frame. Unsteered tractor axle at ``x_i``: ``v_long = u1``,
   ``v_lat = v + r x_i``. Steered: those turned by ``-delta``, so
   ``d v_long/d delta = v_lat`` and ``d v_lat/d delta = -v_long``. Trailer axle
   ``l_k`` behind the kingpin, with the hitch's lateral velocity
   ``v_h = v - r Lc``: ``v_long = u1 cos(gamma) - v_h sin(gamma)``,
   ``v_lat = u1 sin(gamma) + v_h cos(gamma) - (r - gamma_dot) l_k``, so
   ``d v_long/d gamma = -u1 sin(gamma) - v_h cos(gamma)``,
   ``d v_lat/d gamma = v_long + (r - gamma_dot) l_k`` and so on, linear in
   ``(v, r, gamma_dot, u1)``.
2. *Slip rates* (:func:`artic.reduced.tyre_linear.slip_rate`),
   ``g = (s / sigma) (alpha - alpha')`` with ``s = |(v_long, v_lat)|`` and
   ``alpha = -atan2(v_lat, |v_long|)``. With ``ds/dv_long = v_long / s``,
   ``dalpha/dv_long = v_lat sign(v_long) / s^2`` and
   ``dalpha/dv_lat = -|v_long| / s^2``::

       dg/dv_long = (v_long (alpha - alpha') + v_lat sign(v_long)) / (sigma s)
       dg/dv_lat  = (v_lat (alpha - alpha') - |v_long|) / (sigma s)
       dg/dalpha' = -s / sigma

   At an axle's standstill (``s = 0``) the rate is not differentiable (it is
   a cone in the velocity); the Jacobian puts zero there, a frozen tyre.
3. *Velocity rows*, ``w_dot = M_b^-1 b`` with ``M_b = M[1:, 1:](gamma)`` and
   ``b = Q(gamma, delta, alpha') - h[1:](gamma, v, r, gamma_dot, u1) - M[1:, 0](gamma) u1_dot``
   (:func:`artic.reduced.single_track.mass_and_bias`). Differentiating
   ``M_b w_dot = b`` gives ``dw_dot/dz = M_b^-1 (db/dz - (dM_b/dz) w_dot)``, where
   only ``gamma`` moves ``M``. ``Q`` is linear in the axle forces
   ``F_i = C_i alpha'_i``, so ``dQ/dalpha'_i`` is axle ``i``'s generalised force
   per radian; ``delta`` turns a steered axle's ``(F cos(delta), x_i F cos(delta))``
   and ``gamma`` a trailer axle's ``(F cos(gamma), -(Lc cos(gamma) + l_k) F)``.
   ``M`` and ``h`` come from the trailer centre of gravity's partial velocities
   ``p = (px, py)``, with ``px = (1, 0, -a2 sin, a2 sin)`` and
   ``py = (0, 1, -Lc - a2 cos, a2 cos)``: ``dM_jk/dgamma = m2 (p_j' . p_k + p_j . p_k')``,
   and ``h_j = m2 p_j . a_2(w) (+ m1 r u1 for j = v)`` is differentiated
   through the trailer's velocity ``V2`` and its velocity-product acceleration
   ``a_2 = (-a2 w2 cos(gamma) gamma_dot - r V2y, a2 w2 sin(gamma) gamma_dot + r V2x)``,
   ``w2 = r - gamma_dot``.

The kinematic rows are ``X_dot = u1 cos(psi_1) - v sin(psi_1)``,
``Y_dot = u1 sin(psi_1) + v cos(psi_1)``, ``psi_1_dot = r`` and
``gamma_dot = gamma_dot``.
"""

from __future__ import annotations

import math

import numpy as np
from numba import njit

from artic.reduced.single_track import (
    N_BODY,
    axle_generalised_force,
    axle_velocity,
    mass_and_bias,
    solve3,
    stm_unpack,
)

# Columns of B in the compiled kernels: the STM's inputs, KIN's and a zero u1_dot.
B_DELTA, B_U1, B_U1_DOT = 0, 1, 2


def kin_jacobian(x: np.ndarray, u: np.ndarray, P: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """KIN's ``A = df/dx`` and ``B = df/d(delta, u1)`` for a batch (module docstring).

    Parameters
    ----------
    x : ndarray, shape (batch, 4)
        ``[X, Y, psi_1, gamma]`` [m, m, rad, rad].
    u : ndarray, shape (batch, 2)
        ``[delta, u1]`` [rad, m/s].
    P : ndarray
        ``[L1, L1c, L2]`` [m], see :func:`artic.reduced.kinematic.kin_parameters`.

    Returns
    -------
    A : ndarray, shape (batch, 4, 4)
        ``A[:, i, j] = d x_i_dot / d x_j``, in row ``i``'s rate per unit of state ``j``.
    B : ndarray, shape (batch, 4, 2)
        ``B[:, i, k] = d x_i_dot / d u_k``, per radian of ``delta`` and per m/s of ``u1``.
    """
    L1, L1c, L2 = P[0], P[1], P[2]
    psi, gamma = x[:, 2], x[:, 3]
    delta, u1 = u[:, 0], u[:, 1]
    n = x.shape[0]
    cp, sp = np.cos(psi), np.sin(psi)
    cg, sg = np.cos(gamma), np.sin(gamma)
    td = np.tan(delta)
    sec2 = 1.0 + td * td
    r1 = u1 * td / L1
    k = 1.0 - L1c * cg / L2
    A = np.zeros((n, 4, 4))
    A[:, 0, 2] = -u1 * sp
    A[:, 1, 2] = u1 * cp
    A[:, 3, 3] = -u1 * cg / L2 + L1c * sg / L2 * r1
    B = np.zeros((n, 4, 2))
    B[:, 0, 1] = cp
    B[:, 1, 1] = sp
    B[:, 2, 0] = u1 * sec2 / L1
    B[:, 2, 1] = td / L1
    B[:, 3, 0] = k * u1 * sec2 / L1
    B[:, 3, 1] = -sg / L2 + k * td / L1
    return A, B


@njit(cache=True)
def stm_jacobian(x, u1, u1_dot, delta, P):
    """The STM's ``A = df/dx`` and ``B = df/d(delta, u1, u1_dot)`` (module docstring).

    Parameters
    ----------
    x : ndarray
        State, see :mod:`artic.reduced.single_track`.
    u1, u1_dot : float
        Tractor longitudinal speed [m/s] and its rate [m/s^2].
    delta : float
        Road-wheel angle [rad].
    P : ndarray
        Parameter array, see :func:`artic.reduced.single_track.stm_parameters`.

    Returns
    -------
    A : ndarray, shape (n, n)
        ``A[i, j] = d x_i_dot / d x_j``.
    B : ndarray, shape (n, 3)
        ``B[i, k] = d x_i_dot / d (delta, u1, u1_dot)_k``.
    """
    m1, J1, m2, J2, Lc, a2, sigma, ax_x, ax_steer, tr_l, C = stm_unpack(P)
    n = x.size
    na = C.size
    n1 = ax_x.size
    psi, g, v, r, gd = x[2], x[3], x[4], x[5], x[6]
    cg, sg = math.cos(g), math.sin(g)
    cd, sd = math.cos(delta), math.sin(delta)
    A = np.zeros((n, n))
    B = np.zeros((n, 3))
    # Columns of z = (gamma, v, r, gamma_dot, u1, delta) in A (>= 0) or B (< 0: -1 - column).
    zcol = (3, 4, 5, 6, -1 - B_U1, -1 - B_DELTA)
    Q = np.zeros(3)  # (Q_v, Q_r, Q_gamma_dot)
    dQ = np.zeros((3, 6))  # dQ/dz
    dQa = np.zeros((3, na))  # dQ/dalpha'
    dvl = np.zeros(6)
    dvt = np.zeros(6)
    for i in range(na):
        a = x[N_BODY + i]
        F = C[i] * a
        _, q1, q2, q3 = axle_generalised_force(i, C[i], (cg, sg, cd, sd),
                                               (ax_x, ax_steer, tr_l, Lc))
        dQa[0, i], dQa[1, i], dQa[2, i] = q1, q2, q3
        Q[0] += q1 * a
        Q[1] += q2 * a
        Q[2] += q3 * a
        vl, vt = axle_velocity(i, u1, v, r, gd, (cg, sg, cd, sd), (ax_x, ax_steer, tr_l, Lc))
        dvl[:] = 0.0
        dvt[:] = 0.0
        if i < n1:
            xi = ax_x[i]
            if ax_steer[i] > 0.5:
                dQ[0, 5] -= F * sd
                dQ[1, 5] -= xi * F * sd
                dvl[1], dvl[2], dvl[4], dvl[5] = sd, xi * sd, cd, vt
                dvt[1], dvt[2], dvt[4], dvt[5] = cd, xi * cd, -sd, -vl
            else:
                dvl[4] = 1.0
                dvt[1], dvt[2] = 1.0, xi
        else:
            lk = tr_l[i - n1]
            vh = v - r * Lc
            dQ[0, 0] -= F * sg
            dQ[1, 0] += Lc * sg * F
            dvl[0], dvl[1], dvl[2], dvl[4] = -u1 * sg - vh * cg, -sg, Lc * sg, cg
            dvt[0], dvt[1], dvt[2], dvt[3], dvt[4] = (u1 * cg - vh * sg, cg, -Lc * cg - lk,
                                                       lk, sg)
        s = math.sqrt(vl * vl + vt * vt)
        row = N_BODY + i
        A[row, row] = -s / sigma
        if s > 0.0:
            alpha = -math.atan2(vt, abs(vl))
            sign = 1.0 if vl > 0.0 else (-1.0 if vl < 0.0 else 0.0)
            gl = (vl * (alpha - a) + vt * sign) / (sigma * s)
            gt = (vt * (alpha - a) - abs(vl)) / (sigma * s)
            for j in range(6):
                d = gl * dvl[j] + gt * dvt[j]
                if zcol[j] >= 0:
                    A[row, zcol[j]] += d
                else:
                    B[row, -1 - zcol[j]] += d
    # Velocity rows: M_b w_dot = b.
    M, h = mass_and_bias(g, u1, v, r, gd, (m1, J1, m2, J2, Lc, a2))
    Mb = M[1:, 1:].copy()
    b = np.empty(3)
    for k in range(3):
        b[k] = Q[k] - h[k + 1] - M[k + 1, 0] * u1_dot
    wdot = solve3(Mb, b)
    # Partials of h[1:] in (gamma, v, r, gamma_dot, u1) and of M in gamma.
    w2 = r - gd
    V2x = u1 - a2 * w2 * sg
    V2y = v - r * Lc - a2 * w2 * cg
    a2x = -a2 * w2 * cg * gd - r * V2y
    a2y = a2 * w2 * sg * gd + r * V2x
    e = np.eye(5)
    ds = cg * e[0]
    dc = -sg * e[0]
    dw2 = e[2] - e[3]
    dV2x = e[4] - a2 * (dw2 * sg + w2 * ds)
    dV2y = e[1] - Lc * e[2] - a2 * (dw2 * cg + w2 * dc)
    da2x = -a2 * (dw2 * cg * gd + w2 * dc * gd + w2 * cg * e[3]) - (e[2] * V2y + r * dV2y)
    da2y = a2 * (dw2 * sg * gd + w2 * ds * gd + w2 * sg * e[3]) + e[2] * V2x + r * dV2x
    px = np.array([1.0, 0.0, -a2 * sg, a2 * sg])
    py = np.array([0.0, 1.0, -Lc - a2 * cg, a2 * cg])
    dpx = np.array([0.0, 0.0, -a2 * cg, a2 * cg])  # d/dgamma
    dpy = np.array([0.0, 0.0, a2 * sg, -a2 * sg])
    dh = np.empty((3, 5))
    for k in range(3):
        j = k + 1
        dh[k] = m2 * (px[j] * da2x + py[j] * da2y + (dpx[j] * a2x + dpy[j] * a2y) * e[0])
    dh[0] += m1 * (u1 * e[2] + r * e[4])
    dM = np.empty((4, 4))
    for j in range(4):
        for k in range(4):
            dM[j, k] = m2 * (dpx[j] * px[k] + px[j] * dpx[k] + dpy[j] * py[k] + py[j] * dpy[k])
    c = np.empty(3)
    for j in range(6):
        for k in range(3):
            c[k] = dQ[k, j]
            if j < 5:
                c[k] -= dh[k, j]
            if j == 0:
                c[k] -= dM[k + 1, 0] * u1_dot
                for m in range(3):
                    c[k] -= dM[k + 1, m + 1] * wdot[m]
        dw = solve3(Mb, c)
        for k in range(3):
            if zcol[j] >= 0:
                A[4 + k, zcol[j]] = dw[k]
            else:
                B[4 + k, -1 - zcol[j]] = dw[k]
    for i in range(na):
        for k in range(3):
            c[k] = dQa[k, i]
        dw = solve3(Mb, c)
        for k in range(3):
            A[4 + k, N_BODY + i] = dw[k]
    for k in range(3):
        c[k] = -M[k + 1, 0]
    dw = solve3(Mb, c)
    for k in range(3):
        B[4 + k, B_U1_DOT] = dw[k]
    # Kinematic rows.
    cp, sp = math.cos(psi), math.sin(psi)
    A[0, 2] = -u1 * sp - v * cp
    A[0, 4] = -sp
    B[0, B_U1] = cp
    A[1, 2] = u1 * cp - v * sp
    A[1, 4] = cp
    B[1, B_U1] = sp
    A[2, 5] = 1.0
    A[3, 6] = 1.0
    return A, B


@njit(cache=True)
def stm_jacobian_batch(x, u, P):
    """:func:`stm_jacobian` for rows of ``x`` (batch, n) and ``u`` (batch, 3: delta, u1, u1_dot)."""
    b, n = x.shape
    A = np.empty((b, n, n))
    B = np.empty((b, n, 3))
    for i in range(b):
        A[i], B[i] = stm_jacobian(x[i], u[i, 1], u[i, 2], u[i, 0], P)
    return A, B
