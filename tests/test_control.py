"""KIN and STM for planners: the harness's physics, analytic Jacobians, eq. (4)'s eigenvalue."""

from __future__ import annotations

import math
from pathlib import Path

import numpy as np
import pytest

import artic
from artic.mjcf import load_vehicle
from artic.reduced import integrate
from artic.reduced.control import KIN, STM
from artic.reduced.kinematic import equivalent_length, kin_observe, kin_rhs
from artic.reduced.single_track import stm_observe, stm_rhs

EPS = np.finfo(float).eps
# Central differences err by the truncation h^2 |f'''| / 6 and by the round-off
# eps |f| / h; h = eps^(1/3) max(1, |x_j|) (about 6e-6) balances the two near
# eps^(2/3), 4e-11 relative, four decades below the 1e-6 asserted.
H_FD = EPS ** (1.0 / 3.0)
RTOL = 1e-6


@pytest.fixture(scope="module")
def vehicle():
    # The tridem: two tractor axles, three trailer axles, a hitch ahead of the drive axle.
    return load_vehicle("gosar2022-unloaded")


@pytest.fixture(scope="module")
def kin(vehicle):
    return KIN(vehicle)


@pytest.fixture(scope="module")
def stm(vehicle):
    return STM(vehicle)


def random_point(model, rng, direction):
    """A state and inputs away from the slip angle's kinks (|v_long| well above zero)."""
    x = np.zeros(model.nstates)
    x[:2] = rng.uniform(-5.0, 5.0, 2)
    x[2] = rng.uniform(-math.pi, math.pi)
    x[3] = rng.uniform(-0.8, 0.8)
    if isinstance(model, STM):
        x[4:7] = rng.uniform(-0.3, 0.3, 3)
        x[7:] = rng.uniform(-0.05, 0.05, model.nstates - 7)
    u = np.array([rng.uniform(-0.5, 0.5), direction * rng.uniform(0.5, 3.0),
                  rng.uniform(-1.0, 1.0)])
    return x, u[:model.ninputs]


def central(f, z):
    """Central-difference Jacobian of ``f`` at ``z``, and the absolute floor of its round-off."""
    f0 = f(z)
    J = np.empty((f0.size, z.size))
    floor = np.empty_like(J)
    for j in range(z.size):
        h = H_FD * max(1.0, abs(z[j]))
        e = np.zeros(z.size)
        e[j] = h
        J[:, j] = (f(z + e) - f(z - e)) / (2.0 * h)
        # Round-off of the difference: a few eps of the row's magnitude (its
        # terms are O(1) in SI here, hence the 1) over 2h; 50 eps for the
        # cancellations inside the mass-matrix solve.
        floor[:, j] = 50.0 * EPS * np.maximum(1.0, np.abs(f0)) / h
    return J, floor


def assert_jacobian(J, f, z):
    J_fd, floor = central(f, z)
    err = np.abs(J - J_fd)
    bad = err > RTOL * np.abs(J_fd) + floor
    assert not bad.any(), (np.argwhere(bad), J[bad], J_fd[bad])
    assert np.abs(J).max() > 0.0


# -- names and shapes ---------------------------------------------------------


def test_signals_are_named(kin, stm, vehicle):
    assert kin.state_labels == ("X_1", "Y_1", "psi_1", "gamma")
    assert kin.input_labels == ("delta", "u_1")
    assert stm.input_labels == ("delta", "u_1", "u_1_dot")
    n_axles = len(vehicle.tractor_axles) + len(vehicle.trailer_axles)
    assert stm.nstates == 7 + n_axles and stm.state_labels[-1] == f"alpha_{n_axles}"
    assert (kin.nstates, kin.ninputs, kin.noutputs) == (4, 2, 6)
    assert stm.find_state("r_1") == 5 and kin.find_input("u_1") == 1
    assert kin.find_output("Y_2") == 4
    with pytest.raises(ValueError, match="no state 'v_1'.*X_1, Y_1, psi_1, gamma"):
        kin.find_state("v_1")


def test_front_door():
    assert artic.KIN is KIN and artic.STM is STM
    assert {"KIN", "STM"} <= set(artic.__all__)


@pytest.mark.parametrize("which", ["kin", "stm"])
def test_batch_shapes(which, request):
    model = request.getfixturevalue(which)
    rng = np.random.default_rng(7)
    n, m = model.nstates, model.ninputs
    pts = [random_point(model, rng, d) for d in (1, -1, 1, -1, 1)]
    X = np.array([p[0] for p in pts])
    U = np.array([p[1] for p in pts])
    dt = 0.05
    assert model.rhs(X[0], U[0]).shape == (n,)
    assert model.step(X, U, dt).shape == (5, n)
    assert model.output(X).shape == (5, 6) and model.output(X[0]).shape == (6,)
    A, B = model.jacobians(X, U)
    assert A.shape == (5, n, n) and B.shape == (5, n, m)
    Ad, Bd = model.step_jacobians(X[0], U[0], dt)
    assert Ad.shape == (n, n) and Bd.shape == (n, m)
    C, D = model.output_jacobians(X, U)
    assert C.shape == (5, 6, n) and D.shape == (5, 6, m)
    # A batch is its rows.
    for k in range(5):
        np.testing.assert_array_equal(model.step(X, U, dt)[k], model.step(X[k], U[k], dt))
        np.testing.assert_array_equal(A[k], model.jacobians(X[k], U[k])[0])
    # One input broadcast over a batch of states, and the reverse.
    np.testing.assert_array_equal(model.rhs(X, U[2])[4], model.rhs(X[4], U[2]))
    np.testing.assert_array_equal(model.rhs(X[1], U)[3], model.rhs(X[1], U[3]))
    with pytest.raises(ValueError, match="batch of 5 states and one of 2 inputs"):
        model.rhs(X, U[:2])
    with pytest.raises(ValueError, match=r"x has shape \(3,\)"):
        model.rhs(np.zeros(3), U[0])


# -- the harness's physics ----------------------------------------------------


def test_rhs_is_the_harness_rhs(kin, stm):
    rng = np.random.default_rng(11)
    for d in (1, -1):
        for _ in range(10):
            x, u = random_point(kin, rng, d)
            np.testing.assert_array_equal(kin.rhs(x, u), kin_rhs(x, u[1], 0.0, u[0], kin.P))
            x, u = random_point(stm, rng, d)
            np.testing.assert_array_equal(stm.rhs(x, u), stm_rhs(x, u[1], u[2], u[0], stm.P))


def test_step_is_the_harness_step(kin, stm):
    # The harness's step (integrate.rk4_step): the road-wheel angle held, the
    # speed ramping at u1_dot. KIN's inputs are held; the STM's u_1 ramps.
    rng = np.random.default_rng(12)
    for d in (1, -1):
        x, u = random_point(kin, rng, d)
        np.testing.assert_array_equal(
            kin.step(x, u, 0.01), integrate.rk4_step(integrate.KIN, x, 0.01, u[1], 0.0, u[0],
                                                     kin.P))
        x, u = random_point(stm, rng, d)
        np.testing.assert_array_equal(
            stm.step(x, u, 0.01), integrate.rk4_step(integrate.STM, x, 0.01, u[1], u[2], u[0],
                                                     stm.P))


@pytest.mark.parametrize("which", ["kin", "stm"])
def test_rollout_is_step_in_a_loop_to_the_bit(which, request):
    """The compiled rollout takes the same steps as :meth:`step` called once per input."""
    model = request.getfixturevalue(which)
    rng = np.random.default_rng(5)
    x, u = random_point(model, rng, -1)
    us = np.repeat(u[None, :], 40, axis=0)
    us[:, model.find_input("delta")] = np.linspace(-0.2, 0.3, 40)
    xs = [x]
    for k in range(40):
        xs.append(model.step(xs[-1], us[k], 0.05))
    np.testing.assert_array_equal(model.rollout(x, us, 0.05), np.array(xs))
    assert np.abs(np.diff(np.array(xs), axis=0)).max() > 1e-3  # it moved
    with pytest.raises(ValueError, match="rollout: x0 has shape"):
        model.rollout(np.array([x, x]), us, 0.05)


@pytest.mark.parametrize("which", ["kin", "stm"])
@pytest.mark.parametrize("direction", [1, -1])
def test_step_converges_at_fourth_order(which, direction, request):
    # Against the same integration at a step 64 times finer, over 4 s of a
    # turn, speeding up (STM): halving dt divides the error by 2^4. The steps
    # sit in RK4's asymptotic range, well above round-off: |h lambda| < 0.4
    # for the STM's fastest modes (17 rad/s), KIN's slowest being L2 / u.
    model = request.getfixturevalue(which)
    dt = 0.02 if which == "stm" else 0.4
    x0, u = random_point(model, np.random.default_rng(13), direction)
    if model.ninputs == 3:
        u[2] = 0.5 * direction  # away from standstill, where the slip rate has a kink

    def run(h):
        x, uk = x0.copy(), u.copy()
        for _ in range(round(4.0 / h)):
            x = model.step(x, uk, h)
            if model.ninputs == 3:
                uk[1] += uk[2] * h
        return x

    ref = run(dt / 64)
    errors = [np.abs(run(h) - ref).max() for h in (dt, dt / 2)]
    assert 11.0 < errors[0] / errors[1] < 21.0, errors  # 16, with the next order's share


# -- Jacobians ------------------------------------------------------------------


@pytest.mark.parametrize("preset", ["gosar2022-unloaded", "six-axle"])  # six-axle: a tag axle
@pytest.mark.parametrize("which", [KIN, STM])
@pytest.mark.parametrize("direction", [1, -1])
def test_jacobians_equal_central_differences(preset, which, direction):
    model = which(load_vehicle(preset))
    rng = np.random.default_rng(21 + direction)
    for _ in range(8):
        x, u = random_point(model, rng, direction)
        A, B = model.jacobians(x, u)
        assert_jacobian(A, lambda z, u=u: model.rhs(z, u), x)
        assert_jacobian(B, lambda w, x=x: model.rhs(x, w), u)


@pytest.mark.parametrize("which", ["kin", "stm"])
@pytest.mark.parametrize("direction", [1, -1])
def test_step_jacobians_equal_central_differences(which, direction, request):
    model = request.getfixturevalue(which)
    rng = np.random.default_rng(31 + direction)
    dt = 0.05
    for _ in range(4):
        x, u = random_point(model, rng, direction)
        Ad, Bd = model.linearise(x, u, dt=dt)
        assert_jacobian(Ad, lambda z, u=u: model.step(z, u, dt), x)
        assert_jacobian(Bd, lambda w, x=x: model.step(x, w, dt), u)


@pytest.mark.parametrize("which", ["kin", "stm"])
def test_output_jacobians_equal_central_differences(which, request):
    model = request.getfixturevalue(which)
    rng = np.random.default_rng(41)
    x, u = random_point(model, rng, -1)
    C, D = model.output_jacobians(x, u)
    assert_jacobian(C, model.output, x)
    assert not D.any()


def test_step_jacobians_along_the_straight_line_are_rk4s_polynomial(kin):
    # Along the straight line f does not depend on X or Y, so every stage sees
    # the same A and B, and RK4 turns x' = A x + B u into
    # A_d = sum_{k<=4} (h A)^k / k!, B_d = h sum_{k<4} (h A)^k / (k + 1)! B.
    x0, u0 = kin.straight(-1.5)
    A, B = kin.linearise(x0, u0)
    h = 0.2
    Ad, Bd = kin.linearise(x0, u0, dt=h)
    hA = h * A
    P = [np.linalg.matrix_power(hA, k) for k in range(5)]
    np.testing.assert_allclose(Ad, sum(P[k] / math.factorial(k) for k in range(5)),
                               rtol=1e-14, atol=1e-15)
    np.testing.assert_allclose(Bd, h * sum(P[k] / math.factorial(k + 1) for k in range(4)) @ B,
                               rtol=1e-14, atol=1e-15)


# -- eq. (4) and (6): the reversing instability -------------------------------


@pytest.mark.parametrize("u", [-0.5, -2.0, 1.5])
def test_straight_line_eigenvalue_is_eq4(kin, u):
    L1, L1c, L2 = kin.L1, kin.L1c, kin.L2
    assert L1c > 0.1  # a hitch well off the axle, so that the L1c term's sign shows
    x0, u0 = kin.straight(u)
    A, B = kin.linearise(x0, u0)
    # The same from the right-hand side itself, so that a sign flipped in
    # eq. (1) fails here as well as one flipped in the Jacobian (within the
    # differences' 1e-10).
    A_fd = central(lambda z: kin.rhs(z, u0), x0)[0]
    B_fd = central(lambda w: kin.rhs(x0, w), u0)[0]
    for A_, B_, rel in ((A, B, 1e-12), (A_fd, B_fd, 1e-8)):
        eig = np.linalg.eigvals(A_)
        # Eq. (4): gamma_dot = u (-gamma / L2 + (1 - L1c / L2) delta / L1). X, Y
        # and psi_1 are free (zero eigenvalues); gamma's is -u / L2: positive
        # in reverse.
        lam = eig[np.argmax(np.abs(eig))]
        assert lam == pytest.approx(-u / L2, rel=rel)
        assert (lam > 0) == (u < 0)
        np.testing.assert_allclose(np.sort(np.abs(eig))[:3], 0.0, atol=1e-15)
        assert B_[3, 0] == pytest.approx(u * (1 - L1c / L2) / L1, rel=rel)
        assert B_[2, 0] == pytest.approx(u / L1, rel=rel)
    # Eq. (6): the harness's feedback delta = K gamma closes the loop at
    # u (-L1 + K (L2 - L1c)) / (L1 L2), stable in reverse for K > L1 / (L2 - L1c).
    for K in (0.5 * L1 / (L2 - L1c), 3.0):
        Acl = A + K * np.outer(B[:, 0], np.eye(4)[3])
        lam_cl = np.linalg.eigvals(Acl)[np.argmax(np.abs(np.linalg.eigvals(Acl)))]
        assert lam_cl == pytest.approx(u * (-L1 + K * (L2 - L1c)) / (L1 * L2), rel=1e-12)
        if u < 0:
            assert (lam_cl.real < 0) == (K > L1 / (L2 - L1c))


@pytest.mark.parametrize("delta", [0.15, -0.3])
@pytest.mark.parametrize("u", [1.2, -0.8])
def test_steady_turn_eigenvalue_is_the_semitrailer_speed_over_L2(kin, delta, u):
    # In a steady turn both units yaw at r = u tan(delta) / L1 about one centre:
    # the rear axle on R1 = L1 / tan|delta|, the semitrailer's axle on
    # R2 = sqrt(R1^2 + L1c^2 - L2^2). Eq. (4) generalises to gamma's eigenvalue
    # -u_2 / L2, with u_2 = u R2 / R1 the semitrailer's own speed; this fails if
    # the sign of the L1c sin(gamma) term is wrong.
    x0, u0 = kin.steady_turn(delta, u)
    A, _ = kin.linearise(x0, u0)
    A_fd = central(lambda z: kin.rhs(z, u0), x0)[0]
    R1 = kin.L1 / math.tan(abs(delta))
    R2 = math.sqrt(R1 ** 2 + kin.L1c ** 2 - kin.L2 ** 2)
    assert A[3, 3] == pytest.approx(-u * R2 / (R1 * kin.L2), rel=1e-12)
    assert A_fd[3, 3] == pytest.approx(-u * R2 / (R1 * kin.L2), rel=1e-8)


def test_stm_jackknife_eigenvalue_tends_to_kins_as_the_tyres_stiffen(vehicle):
    # One trailer axle at L2 and a 4x2 tractor: with rigid tyres the STM is KIN
    # with the paper's geometry. Its unstable eigenvalue reversing straight is
    # -u/L2 up to the tyres' compliance, an error proportional to 1 / f.
    u = -1.0
    kin = KIN(vehicle, wheelbase="paper")
    errors = []
    for f in (6.0, 60.0, 600.0):
        stm = STM(vehicle, f=f, trailer_axles=np.array([vehicle.L2]))
        eig = np.linalg.eigvals(stm.linearise(*stm.straight(u))[0])
        assert np.sum(eig.real > 1e-9) == 1  # one unstable mode: the jackknife
        errors.append(abs(eig.real.max() / (-u / kin.L2) - 1.0))
    assert errors[0] < 0.01
    assert errors[0] / errors[1] == pytest.approx(10.0, rel=0.02)
    assert errors[1] / errors[2] == pytest.approx(10.0, rel=0.02)


# -- operating points ---------------------------------------------------------


@pytest.mark.parametrize("delta", [0.05, 0.25, -0.4])
@pytest.mark.parametrize("u", [1.4, -1.0])
def test_kin_steady_turn_is_a_fixed_point(kin, delta, u):
    x0, u0 = kin.steady_turn(delta, u)
    f = kin.rhs(x0, u0)
    assert f[3] == pytest.approx(0.0, abs=4 * EPS * abs(u))  # gamma_dot = 0
    assert f[2] == pytest.approx(u * math.tan(delta) / kin.L1, rel=1e-15)
    assert np.sign(x0[3]) == np.sign(delta)  # articulated into the turn, both directions


def test_kin_steady_turn_refuses_a_turn_past_jackknife(kin):
    with pytest.raises(ValueError, match="tighter than the semitrailer can follow"):
        kin.steady_turn(1.5, 1.0)


@pytest.mark.parametrize("delta", [0.2, -0.35])
@pytest.mark.parametrize("u", [2.0, -1.0])
def test_stm_steady_turn_is_a_fixed_point(stm, kin, delta, u):
    x0, u0 = stm.steady_turn(delta, u)
    f = stm.rhs(x0, u0)
    # Newton stopped on a step below 1e-12; the residual is that times |J| < 1e3.
    np.testing.assert_allclose(f[3:], 0.0, atol=1e-9)
    assert f[2] == x0[5]
    # Near KIN's trim at yard speeds: the tyres' slip is small.
    assert x0[3] == pytest.approx(kin.steady_turn(delta, u)[0][3], abs=0.02)
    # Unstable in reverse, stable forward.
    eig = np.linalg.eigvals(stm.linearise(x0, u0)[0])
    assert (eig.real.max() > 1e-9) == (u < 0)


def test_stm_steady_turn_is_where_a_forward_turn_settles(stm):
    # Independent of Newton and the Jacobians: 100 s of the harness's step from
    # straight. The slowest mode decays at about u / L2 = 0.26 /s, so e^-26 of
    # the initial 0.4 rad is left; RK4 keeps a fixed point of f exactly.
    x0, u0 = stm.steady_turn(0.25, 2.0)
    x, _ = stm.straight(2.0)
    for _ in range(5000):
        x = stm.step(x, u0, 0.02)
    np.testing.assert_allclose(x[3:], x0[3:], atol=1e-9)


def test_stm_steady_turn_refuses_what_has_no_trim(stm):
    with pytest.raises(ValueError, match="u = 0"):
        stm.steady_turn(0.2, 0.0)
    with pytest.raises(ValueError, match="STM.steady_turn: .*tighter than the semitrailer"):
        stm.steady_turn(1.5, 1.0)


# -- outputs ------------------------------------------------------------------


def test_outputs_are_the_semitrailer_axle(kin, stm, vehicle):
    # The observation of a sensor placed on the semitrailer's (equivalent) axle.
    rng = np.random.default_rng(51)
    zero = np.zeros(2)
    x, u = random_point(kin, rng, -1)
    obs = kin_observe(x, u[1], u[0], kin.P, zero, np.array([-kin.L2, 0.0]))
    np.testing.assert_allclose(kin.output(x), obs[[0, 1, 2, 6, 7, 8]], rtol=1e-14, atol=1e-13)
    x, u = random_point(stm, rng, 1)
    n1 = len(vehicle.tractor_axles)
    l0 = equivalent_length(vehicle.trailer_axle_distances, vehicle.static_loads[n1:])
    obs = stm_observe(x, u[1], u[0], stm.P, zero, np.array([-l0, 0.0]))
    np.testing.assert_allclose(stm.output(x, u), obs[[0, 1, 2, 6, 7, 8]], rtol=1e-14,
                               atol=1e-13)
    # KIN's equivalent semitrailer axle is the STM's: one no-slip point.
    assert kin.L2 == pytest.approx(l0, rel=1e-14)


def test_python_control_signatures(kin):
    x, u = kin.straight(1.0)
    np.testing.assert_array_equal(kin.updfcn(0.0, x, u, {}), kin.rhs(x, u))
    np.testing.assert_array_equal(kin.outfcn(0.0, x, u, None), kin.output(x, u))


def test_the_docs_planner_example_runs(kin):
    page = Path(__file__).resolve().parents[1] / "docs" / "guide" / "planner.md"
    code = page.read_text().split("```python\n", 1)[1].split("```", 1)[0]
    namespace: dict = {}
    exec(compile(code, str(page), "exec"), namespace)  # noqa: S102
    assert np.linalg.eigvals(namespace["A"]).real.max() == pytest.approx(1.0 / kin.L2)
    assert namespace["x1"][3] > 0.05  # the articulation grows in reverse
