"""STM, eq. (2): the derivation, conservation, limits and zero-speed passage."""

from __future__ import annotations

import math

import numpy as np
import pytest

from artic.mjcf import load_vehicle
from artic.reduced import KIN, STM, Driven, InitialState
from artic.reduced.single_track import N_BODY, generalised_forces, mass_and_bias, stm_rhs
from artic.reduced.tyre_linear import slip_angle, slip_rate

RNG = np.random.default_rng(20221)


def paper_matrices(g, u, v, r, gd, m1, J1, m2, J2, Lc, a2):
    """Eqs. (11)-(12) as printed, with the design notes' correction in H row 1."""
    s, c = math.sin(g), math.cos(g)
    M = np.array([
        [m1 + m2, -m2 * (Lc + a2 * c), m2 * a2 * c],
        [-m2 * (Lc + a2 * c), J1 + J2 + m2 * (a2 ** 2 + 2 * a2 * Lc * c + Lc ** 2),
         -J2 - m2 * (a2 ** 2 + a2 * Lc * c)],
        [m2 * a2 * c, -J2 - m2 * (a2 ** 2 + a2 * Lc * c), J2 + m2 * a2 ** 2],
    ])
    H = np.array([
        m1 * r * u + m2 * (r * u - a2 * s * gd ** 2 - a2 * s * r ** 2 + 2 * a2 * s * gd * r),
        -m2 * (2 * a2 * Lc * s * gd * r - a2 * Lc * s * gd ** 2 + Lc * u * r
               + a2 * c * r * u - a2 * s * r * v),
        m2 * a2 * (c * r * u - s * r * v + Lc * s * r ** 2),
    ])
    return M, H


def test_mass_matrix_and_bias_match_corrected_paper(unloaded):
    v = unloaded
    p = (v.m1, v.J1, v.m2, v.J2, v.Lc, v.a2)
    for _ in range(50):
        g, u, vv, r, gd = RNG.uniform(-1.5, 1.5), *RNG.uniform(-3, 3, 2), *RNG.uniform(-1, 1, 2)
        M, h = mass_and_bias(g, u, vv, r, gd, p)
        Mp, Hp = paper_matrices(g, u, vv, r, gd, *p)
        np.testing.assert_allclose(M[1:, 1:], Mp, rtol=1e-12, atol=1e-9)
        np.testing.assert_allclose(h[1:], Hp, rtol=1e-12, atol=1e-9)
        # The u_dot terms the paper drops (design notes section 3).
        s = math.sin(g)
        np.testing.assert_allclose(M[1:, 0], [0.0, -v.m2 * v.a2 * s, v.m2 * v.a2 * s],
                                   atol=1e-9)
        assert np.all(np.linalg.eigvalsh(M) > 0)


def test_generalised_forces_match_paper_eq13(unloaded):
    v = unloaded
    ax_x = np.array([v.a1, -v.b1])
    ax_st = np.array([1.0, 0.0])
    tr_l = v.trailer_axle_distances
    for _ in range(20):
        F = RNG.normal(0, 1e4, 5)
        g, d = RNG.uniform(-1.2, 1.2), RNG.uniform(-0.6, 0.6)
        Q = generalised_forces(F, g, d, ax_x, ax_st, tr_l, v.Lc)
        Ft = F[2:].sum()
        expect = [
            F[0] * math.cos(d) + F[1] + Ft * math.cos(g),
            v.a1 * F[0] * math.cos(d) - v.b1 * F[1] - v.Lc * Ft * math.cos(g)
            - (tr_l * F[2:]).sum(),
            (tr_l * F[2:]).sum(),
        ]
        np.testing.assert_allclose(Q[1:], expect, rtol=1e-12, atol=1e-6)


def _free_rhs(s, p):
    """The free system (u not prescribed, no forces): all four rows of M w_dot + h = 0."""
    X, Y, psi, g, u, v, r, gd = s
    M, h = mass_and_bias(g, u, v, r, gd, p)
    wdot = np.linalg.solve(M, -h)
    return np.array([u * math.cos(psi) - v * math.sin(psi), u * math.sin(psi) + v * math.cos(psi),
                     r, gd, *wdot])


def _invariants(s, p):
    m1, J1, m2, J2, Lc, a2 = p
    X, Y, psi, g, u, v, r, gd = s
    M, _ = mass_and_bias(g, u, v, r, gd, p)
    w = np.array([u, v, r, gd])
    energy = 0.5 * w @ M @ w
    w2 = r - gd
    V2 = np.array([u - a2 * w2 * math.sin(g), v - r * Lc - a2 * w2 * math.cos(g)])
    R = np.array([[math.cos(psi), -math.sin(psi)], [math.sin(psi), math.cos(psi)]])
    V1e, V2e = R @ np.array([u, v]), R @ V2
    x1 = np.array([X, Y])
    x2 = x1 + R @ (np.array([-Lc, 0.0]) - a2 * np.array([math.cos(g), -math.sin(g)]))
    momentum = m1 * V1e + m2 * V2e
    cross = lambda a, b: a[0] * b[1] - a[1] * b[0]  # noqa: E731
    angular = m1 * cross(x1, V1e) + m2 * cross(x2, V2e) + J1 * r + J2 * w2
    return energy, momentum, angular


def test_free_system_conserves_energy_and_momenta(unloaded):
    # With no external force, kinetic energy, linear momentum and angular
    # momentum are invariants. A wrong sign or factor anywhere in M or h
    # breaks at least one of them. RK4 at 1 ms over 5 s keeps the drift
    # of a correct model near 1e-12 relative.
    v = unloaded
    p = (v.m1, v.J1, v.m2, v.J2, v.Lc, v.a2)
    s = np.array([1.0, -2.0, 0.3, 0.6, 2.0, -0.4, 0.5, -0.7])
    e0, p0, l0 = _invariants(s, p)
    dt = 1e-3
    for _ in range(5000):
        k1 = _free_rhs(s, p)
        k2 = _free_rhs(s + 0.5 * dt * k1, p)
        k3 = _free_rhs(s + 0.5 * dt * k2, p)
        k4 = _free_rhs(s + dt * k3, p)
        s = s + dt / 6 * (k1 + 2 * k2 + 2 * k3 + k4)
    e1, p1, l1 = _invariants(s, p)
    assert abs(s[3] - 0.6) > 0.5  # the articulation really moved
    assert e1 == pytest.approx(e0, rel=1e-9)
    np.testing.assert_allclose(p1, p0, rtol=1e-9, atol=1e-9 * np.linalg.norm(p0))
    assert l1 == pytest.approx(l0, rel=1e-9)


def steady(model, delta, u, seconds=300.0):
    model = model if isinstance(model, Driven) else Driven(model)
    model.reset(InitialState(0.0, 0.0, 0.0, 0.0, u1=u))
    for _ in range(int(seconds / 0.01)):
        model.step(0.01, delta, u, 0.0)
    return model.observe()


def test_stiff_tyres_approach_kin(unloaded):
    # One trailer axle at L2, as KIN has. At walking speed the slip angles
    # are the lateral accelerations over the cornering stiffness, so the
    # difference to KIN falls as 1/f: a tenfold f cuts it tenfold.
    delta, u = 0.2, 0.5
    kin = steady(KIN(unloaded, "paper"), delta, u)
    err = {}
    for f in (6.0, 60.0, 600.0):
        stm = steady(STM(unloaded, f=f, trailer_axles=np.array([unloaded.L2])),
                     delta, u)
        err[f] = abs(stm[12] - kin[12]) + abs(stm[5] - kin[5])
    assert err[60.0] < 2e-6
    assert err[60.0] / err[6.0] == pytest.approx(0.1, rel=0.05)
    assert err[600.0] / err[60.0] == pytest.approx(0.1, rel=0.05)


def test_trailer_tridem_scrub(unloaded):
    # Three trailer axles resist the trailer's yaw: their forces have no
    # moment about the hitch only when the trailer turns about a point
    # L_eq = sum(C l^2) / sum(C l) behind the kingpin, beyond L2. The longer
    # equivalent wheelbase makes the trailer cut in more: |gamma| > KIN's.
    v = unloaded
    delta, u = 0.2, 0.5
    m = Driven(STM(v))
    y = steady(m, delta, u)
    kin = steady(KIN(v, "paper"), delta, u)
    assert y[12] > kin[12] + math.radians(1.0)
    x = m.x
    r, gd, g, vv = x[5], x[6], x[3], x[4]
    v_hitch_lat = u * math.sin(g) + (vv - r * v.Lc) * math.cos(g)
    l_noslip = v_hitch_lat / (r - gd)
    C, ell = v.cornering_stiffness[2:], v.trailer_axle_distances
    L_eq = (C * ell ** 2).sum() / (C * ell).sum()
    # Linear-tyre moment balance; the atan of slip angles near j/R ~ 0.07 rad
    # bends it by well under 0.1 %.
    assert l_noslip == pytest.approx(L_eq, rel=1e-3)
    assert L_eq > v.L2


def test_reversing_eigenvalue_approaches_eq6(unloaded):
    # Linearise the STM's reversing loop, delta = K gamma, about straight
    # travel. With one trailer axle its slowest mode tends to eq. (6) as 1/f.
    v, u1 = unloaded, -3.0 / 3.6

    def eig(f, K):
        model = STM(v, f=f, trailer_axles=np.array([v.L2]))
        P = model.P
        n = N_BODY - 3 + model.n_axles

        def fz(z):
            return stm_rhs(np.concatenate([np.zeros(3), z]), u1, 0.0, K * z[0], P)[3:]
        J = np.empty((n, n))
        for i in range(n):
            e = np.zeros(n)
            e[i] = 1e-7
            J[:, i] = (fz(e) - fz(-e)) / 2e-7
        return np.linalg.eigvals(J)

    for K in (0.0, 3.0):
        lam6 = u1 * (-v.L1 + K * (v.L2 - v.L1c)) / (v.L1 * v.L2)
        rel = []
        for f in (6.0, 60.0):
            ev = eig(f, K)
            near = ev[np.argmin(np.abs(ev - lam6))]
            rel.append(abs(near.real - lam6) / abs(lam6))
            assert abs(near.imag) < 1e-9
        assert rel[0] < 5e-3 and rel[1] < rel[0] / 5


def test_forward_stop_reverse_is_smooth(unloaded):
    # 1.4 m/s, brake to standstill, 4 s standing, reverse at 0.8 m/s, with
    # the wheels turned throughout. Nothing may go NaN; through the stop and
    # the change of direction no axle force may jump by more than 1 % of the
    # axle's static load in one 10 ms step.
    v = unloaded
    t = np.arange(0.0, 40.0, 0.01)
    u = np.interp(t, [0, 10, 14, 18, 22, 40], [1.4, 1.4, 0.0, 0.0, -0.8, -0.8])
    m = Driven(STM(v))
    m.reset(InitialState(0.0, 0.0, 0.0, 0.0, u1=u[0]))
    F, obs = [], []
    for k in range(t.size - 1):
        m.step(0.01, 0.15, u[k], (u[k + 1] - u[k]) / 0.01)
        F.append(m.tyre_forces.copy())
        obs.append(m.observe())
    F, obs = np.array(F), np.array(obs)
    assert np.all(np.isfinite(F)) and np.all(np.isfinite(obs))
    window = slice(int(9 / 0.01), int(25 / 0.01))
    jumps = np.abs(np.diff(F[window], axis=0)).max(axis=0)
    assert np.all(jumps < 0.01 * v.static_loads), jumps
    # Standing still, the combination stays where it stopped (within 5 mm).
    stand = slice(int(15 / 0.01), int(17.5 / 0.01))
    assert np.ptp(obs[stand, 0]) < 5e-3 and np.ptp(obs[stand, 1]) < 5e-3
    # Reversing with steady steer: the articulation leaves its forward value.
    assert abs(obs[-1, 12] - obs[int(13 / 0.01), 12]) > math.radians(5)


def test_slip_angle_sign_and_reverse_mirror():
    # Sliding right (v_lat < 0) gives a positive slip angle and a leftward force,
    # forward and in reverse alike; at standstill it is zero, not NaN.
    assert slip_angle(2.0, -0.1) > 0 and slip_angle(-2.0, -0.1) > 0
    assert slip_angle(2.0, -0.1) == pytest.approx(slip_angle(-2.0, -0.1))
    assert slip_angle(0.0, 0.0) == 0.0
    assert slip_rate(0.0, 0.0, 0.3, 0.45) == 0.0
    # The lag has the classic small-slip form sigma*a' + |v_x|*a = -v_y.
    vx, vy, a, sig = -1.5, 0.01, 0.002, 0.45
    assert slip_rate(vx, vy, a, sig) == pytest.approx((-vy - abs(vx) * a) / sig, rel=1e-3)


def test_six_axle_runs_and_tag_axle_scrubs():
    v = load_vehicle("six-axle")
    m = Driven(STM(v))
    assert m.n_axles == 6
    y = steady(m, 0.2, 0.5, seconds=200.0)
    assert np.all(np.isfinite(y))
    # Tag and drive axles scrub against each other: opposite lateral forces.
    F = m.tyre_forces
    assert F[1] * F[2] < 0


def test_deterministic(unloaded):
    runs = []
    for _ in range(2):
        m = Driven(STM(unloaded))
        m.reset(InitialState(1.0, 2.0, 0.3, 0.1, u1=-0.8))
        for k in range(500):
            m.step(0.01, 0.05 * math.sin(k / 50), -0.8, 0.0)
        runs.append(m.x.copy())
    assert np.array_equal(runs[0], runs[1])


def test_start_from_rest_with_noisy_velocity_has_relaxed_tyres(unloaded):
    # A log that starts at rest reads 1 cm/s of sensor noise. Steady-state slip
    # from that would be near 90 deg; the tyres start relaxed in proportion to speed.
    from artic.reduced.control import U_SLIP_KNOWN

    m = Driven(STM(unloaded))
    m.reset(InitialState(0.0, 0.0, 0.0, 0.0, v_y_1=0.01, u1=0.005))
    assert np.abs(m.x[N_BODY:]).max() < (math.pi / 2) * (0.02 / U_SLIP_KNOWN)
    m.reset(InitialState(0.0, 0.0, 0.0, 0.0, v_y_1=0.05, u1=3.0))
    v_long, v_lat = m.axle_velocities(m.x, 3.0, 0.0)
    np.testing.assert_allclose(m.x[N_BODY:], -np.arctan2(v_lat, np.abs(v_long)))
