"""KIN's and the STM's hand-derived Jacobians against CasADi's automatic differentiation.

The references are the models written here in CasADi's symbols, sharing no
code with artic: KIN's eq. (1) of "Model Validation of a Low-Speed and Reverse
Driving Articulated Vehicle", and the STM by Kane's method from its definitions
alone (the bodies' velocities, the axles' wheel frames, the lagged slips), the
mass matrix and velocity-product terms formed by CasADi's own derivatives.
CasADi differentiates them; :meth:`artic.KIN.jacobians` and
:meth:`artic.STM.jacobians` are derived by hand (:mod:`artic.reduced.jacobians`).
"""

from __future__ import annotations

import numpy as np
import pytest

import artic

casadi = pytest.importorskip("casadi", reason="CasADi (the optional [control] extra) is not "
                                              "installed: no automatic differentiation to "
                                              "compare with")


def kin_reference(L1: float, L1c: float, L2: float):
    """Eq. (1) in CasADi: the functions ``A(x, u)`` and ``B(x, u)``, ``u = (delta, u1)``."""
    x = casadi.SX.sym("x", 4)
    u = casadi.SX.sym("u", 2)
    psi, gamma = x[2], x[3]
    delta, u1 = u[0], u[1]
    r1 = u1 * casadi.tan(delta) / L1
    f = casadi.vertcat(u1 * casadi.cos(psi), u1 * casadi.sin(psi), r1,
                       -u1 * casadi.sin(gamma) / L2 + (1.0 - L1c * casadi.cos(gamma) / L2) * r1)
    return (casadi.Function("A", [x, u], [casadi.jacobian(f, x)]),
            casadi.Function("B", [x, u], [casadi.jacobian(f, u)]))


@pytest.mark.parametrize("preset", ["gosar2022-unloaded", "scale-model-1to14"])
def test_kin_jacobians_equal_casadis(preset):
    # Both are exact derivatives of the same closed form, so they agree to
    # rounding: 1e-12 relative to the largest entry (a few ulps of sums of
    # products of order-one terms), over headings, articulations, steering
    # angles and speeds in either direction.
    model = artic.KIN(artic.load_vehicle(preset))
    p = model.params
    A_ad, B_ad = kin_reference(p.L1, p.L1c, p.L2)
    rng = np.random.default_rng(45)
    for _ in range(200):
        x = np.array([*rng.uniform(-50.0, 50.0, 2), rng.uniform(-np.pi, np.pi),
                      rng.uniform(-1.2, 1.2)])
        u = np.array([rng.uniform(-0.6, 0.6), rng.uniform(-3.0, 3.0)])
        A, B = model.jacobians(x, u)
        A_ref, B_ref = np.array(A_ad(x, u)), np.array(B_ad(x, u))
        scale = max(np.abs(A_ref).max(), np.abs(B_ref).max(), 1.0)
        np.testing.assert_allclose(A, A_ref, rtol=0.0, atol=1e-12 * scale)
        np.testing.assert_allclose(B, B_ref, rtol=0.0, atol=1e-12 * scale)


def stm_reference(p):
    """The STM in CasADi: the function ``(x, u) -> (f, df/dx, df/du)``, ``u = (delta, u1, u1_dot)``.

    Generalised speeds ``w = (u1, v, r, gamma_dot)``; the semitrailer's velocity
    and yaw rate from the hitch geometry; ``M = sum m P^T P + J W^T W`` over the
    bodies' partial velocities ``P`` and rates ``W``; ``h`` from their
    velocity-product accelerations, ``dV/dgamma gamma_dot + r x V`` in tractor axes;
    ``Q`` from each axle's lateral force ``C alpha'`` along its wheel's lateral axis.
    """
    n1, n2 = len(p.ax_x), len(p.tr_l)
    x, u = casadi.SX.sym("x", 7 + n1 + n2), casadi.SX.sym("u", 3)
    psi, g, v, r, gd = x[2], x[3], x[4], x[5], x[6]
    delta, u1, u1_dot = u[0], u[1], u[2]
    w = casadi.vertcat(u1, v, r, gd)
    s, c = casadi.sin(g), casadi.cos(g)
    w2 = r - gd  # the semitrailer's yaw rate
    V1 = casadi.vertcat(u1, v)
    V2 = casadi.vertcat(u1 - p.a2 * w2 * s, v - r * p.Lc - p.a2 * w2 * c)
    P1, P2 = casadi.jacobian(V1, w), casadi.jacobian(V2, w)
    W1, W2 = casadi.jacobian(r, w), casadi.jacobian(w2, w)
    M = p.m1 * P1.T @ P1 + p.m2 * P2.T @ P2 + p.J1 * W1.T @ W1 + p.J2 * W2.T @ W2

    def product(V):  # the velocity-product acceleration, in tractor axes
        return casadi.jacobian(V, g) * gd + casadi.vertcat(-r * V[1], r * V[0])

    h = p.m1 * P1.T @ product(V1) + p.m2 * P2.T @ product(V2)
    Q, rates = casadi.SX.zeros(4), []
    for i in range(n1 + n2):
        if i < n1:  # a tractor axle, steered or not
            V = casadi.vertcat(u1, v + r * p.ax_x[i])
            d = delta if p.ax_steer[i] > 0.5 else 0.0
            ex = casadi.vertcat(casadi.cos(d), casadi.sin(d))
            ey = casadi.vertcat(-casadi.sin(d), casadi.cos(d))
        else:  # a semitrailer axle, tr_l behind the kingpin
            lk = p.tr_l[i - n1]
            V = casadi.vertcat(u1 - w2 * lk * s, v - r * p.Lc - w2 * lk * c)
            ex, ey = casadi.vertcat(c, -s), casadi.vertcat(s, c)
        vl, vt = casadi.dot(V, ex), casadi.dot(V, ey)
        a = x[7 + i]
        Q += p.C[i] * a * (casadi.jacobian(V, w).T @ ey)
        rates.append(casadi.sqrt(vl ** 2 + vt ** 2) / p.sigma_alpha
                     * (-casadi.atan2(vt, casadi.fabs(vl)) - a))
    wdot = casadi.solve(M[1:, 1:], Q[1:] - h[1:] - M[1:, 0] * u1_dot)  # u1 is prescribed
    f = casadi.vertcat(u1 * casadi.cos(psi) - v * casadi.sin(psi),
                       u1 * casadi.sin(psi) + v * casadi.cos(psi), r, gd, wdot, *rates)
    return casadi.Function("stm", [x, u], [f, casadi.jacobian(f, x), casadi.jacobian(f, u)])


@pytest.mark.parametrize("preset", ["gosar2022-unloaded", "six-axle"])
def test_stm_jacobians_equal_casadis(preset):
    # The right-hand side first (the reference is the same model), then both
    # Jacobians: exact derivatives of the same equations, so they agree to
    # rounding. 1e-12 relative to the largest entry: the 3 x 3 solve and the sums
    # of a few dozen products lose a few hundred ulps at most (2.5e-14 seen).
    # Rolling states in either direction (the slip's |v_long| is smooth there).
    model = artic.STM(artic.load_vehicle(preset))
    reference = stm_reference(model.params)
    rng = np.random.default_rng(45)
    n_slips = model.nstates - 7
    for _ in range(200):
        x = np.concatenate([rng.uniform(-50.0, 50.0, 2), rng.uniform(-np.pi, np.pi, 1),
                            rng.uniform(-1.2, 1.2, 1), rng.normal(0.0, 0.5, 1),
                            rng.normal(0.0, 0.3, 2), rng.normal(0.0, 0.05, n_slips)])
        u = np.array([rng.uniform(-0.6, 0.6), rng.choice([-1.0, 1.0]) * rng.uniform(0.5, 4.0),
                      rng.normal(0.0, 0.5)])
        f_ref, A_ref, B_ref = (np.array(z) for z in reference(x, u))
        A, B = model.jacobians(x, u)
        for got, want in ((model.rhs(x, u), f_ref.ravel()), (A, A_ref), (B, B_ref)):
            np.testing.assert_allclose(got, want, rtol=0.0,
                                       atol=1e-12 * max(np.abs(want).max(), 1.0))
