"""KIN and the STM on a batch: one compiled call equals the single calls to the bit."""

from __future__ import annotations

import math

import numpy as np
import pytest

from artic.mjcf import load_vehicle
from artic.mjcf.errors import UserError
from artic.reduced import integrate
from artic.reduced.control import KIN, STM, BatchError

B, H, DT = 7, 12, 0.05


@pytest.fixture(scope="module")
def vehicle():
    return load_vehicle("gosar2022-unloaded")


@pytest.fixture(scope="module", params=["kin", "stm"])
def model(request, vehicle):
    return KIN(vehicle) if request.param == "kin" else STM(vehicle)


def batch(model, rng, b=B, h=H):
    """States (b, n) and input sequences (b, h, m), reversing and forward, steering varied."""
    x = np.zeros((b, model.nstates))
    x[:, :2] = rng.uniform(-5.0, 5.0, (b, 2))
    x[:, 2] = rng.uniform(-math.pi, math.pi, b)
    x[:, 3] = rng.uniform(-0.6, 0.6, b)
    if isinstance(model, STM):
        x[:, 4:7] = rng.uniform(-0.2, 0.2, (b, 3))
        x[:, 7:] = rng.uniform(-0.03, 0.03, (b, model.nstates - 7))
    u = np.zeros((b, h, model.ninputs))
    u[:, :, 0] = rng.uniform(-0.5, 0.5, (b, h))
    u[:, :, 1] = rng.choice([-1.0, 1.0], (b, 1)) * rng.uniform(0.5, 2.5, (b, h))
    if isinstance(model, STM):
        u[:, :, 2] = rng.uniform(-0.5, 0.5, (b, h))
    return x, u


def test_rollout_of_a_batch_is_the_single_rollouts_to_the_bit(model):
    x, u = batch(model, np.random.default_rng(1))
    out = model.rollout(x, u, DT)
    assert out.shape == (B, H + 1, model.nstates)
    for b in range(B):
        assert np.array_equal(out[b], model.rollout(x[b], u[b], DT))
    # And the single rollout is the harness's step in a loop (integrate.rk4_step).
    xk = x[0]
    for k in range(H):
        uk = u[0, k]
        u1_dot = uk[2] if uk.size > 2 else 0.0
        xk = integrate.rk4_step(model.kind, xk, DT, uk[1], u1_dot, uk[0], model.P)
        assert np.array_equal(out[0, k + 1], xk)


def test_one_state_is_shared_by_every_sequence(model):
    x, u = batch(model, np.random.default_rng(2))
    out = model.rollout(x[0], u, DT)
    assert out.shape == (B, H + 1, model.nstates)
    for b in range(B):
        assert np.array_equal(out[b], model.rollout(x[0], u[b], DT))


def test_step_and_jacobians_of_a_batch_are_the_single_ones_to_the_bit(model):
    x, u = batch(model, np.random.default_rng(3), h=1)
    u = u[:, 0]
    X1 = model.step(x, u, DT)
    A, Bm = model.jacobians(x, u)
    Ad, Bd = model.step_jacobians(x, u, DT)
    for b in range(B):
        assert np.array_equal(X1[b], model.step(x[b], u[b], DT))
        a, bb = model.jacobians(x[b], u[b])
        assert np.array_equal(A[b], a) and np.array_equal(Bm[b], bb)
        a, bb = model.step_jacobians(x[b], u[b], DT)
        assert np.array_equal(Ad[b], a) and np.array_equal(Bd[b], bb)


def test_the_fast_single_step_is_the_batch_step(model):
    """A 1-D float64 state takes the fast path; a list takes the general one: same bits."""
    x, u = batch(model, np.random.default_rng(4), h=1)
    fast = model.step(x[0], u[0, 0], DT)
    general = model.step(list(x[0]), list(u[0, 0]), DT)
    assert np.array_equal(fast, general)
    assert np.array_equal(fast, model.step(x[:1], u[:1, 0], DT)[0])


@pytest.mark.parametrize("call, match", [
    (lambda m, x, u: m.rollout(x, u[:, :, :1], DT), r"rollout: x0 has shape .* and u \(7, 12, 1\)"),
    (lambda m, x, u: m.rollout(x[:3], u, DT), r"rollout: x0 has shape \(3, \d+\) and u \(7, 12"),
    (lambda m, x, u: m.rollout(x, u[0], DT), r"rollout: x0 has shape \(7, \d+\) and u \(12,"),
    (lambda m, x, u: m.rollout(x[:0], u[:0], DT), r"x0 has shape \(0, \d+\): an empty batch"),
    (lambda m, x, u: m.rollout(x[0], u[:, :0], DT), r"u has shape \(7, 0, \d\): an empty"),
    (lambda m, x, u: m.step(x[:3], u[:2, 0], DT), r"a batch of 3 states and one of 2 inputs"),
    (lambda m, x, u: m.step(x[:0], u[:0, 0], DT), r"x has shape \(0, \d+\): an empty batch"),
    (lambda m, x, u: m.step(x[:, :3], u[:, 0], DT), r"x has shape \(7, 3\); expected"),
    (lambda m, x, u: m.jacobians(x[:0], u[:0, 0]), r"x has shape \(0, \d+\): an empty batch"),
])
def test_bad_shapes_are_refused_in_one_line_naming_the_argument(model, call, match):
    x, u = batch(model, np.random.default_rng(5))
    with pytest.raises(BatchError, match=match) as info:
        call(model, x, u)
    assert "\n" not in str(info.value)
    assert isinstance(info.value, UserError) and isinstance(info.value, ValueError)


@pytest.mark.parametrize("bad", [math.nan, math.inf, -math.inf])
def test_a_state_or_input_that_is_not_finite_is_refused(model, bad):
    x, u = batch(model, np.random.default_rng(6))
    xb = x.copy()
    xb[2, 3] = bad
    with pytest.raises(BatchError, match=rf"x0 has shape \(7, \d+\) and a {bad} at index \(2, 3\)"):
        model.rollout(xb, u, DT)
    ub = u.copy()
    ub[4, 5, 1] = bad
    with pytest.raises(BatchError, match=rf"u has shape \(7, 12, \d\) and a {bad} at index "
                                         r"\(4, 5, 1\)"):
        model.rollout(x, ub, DT)
    # The single step's fast path refuses it too, naming it the same way.
    with pytest.raises(BatchError, match=r"x has shape \(\d+,\) and a .* at index \(3,\)"):
        model.step(xb[2], u[0, 0], DT)
    with pytest.raises(BatchError, match=r"u has shape \(\d,\) and a .* at index \(1,\)"):
        model.step(x[0], ub[4, 5], DT)


class DoubledKIN(KIN):
    """KIN with twice the articulation rate: a subclass that changes the dynamics."""

    def rhs(self, x, u):
        f = np.array(super().rhs(x, u))
        f[..., 3] *= 2.0
        return f


def test_a_subclass_rhs_is_what_the_batched_rollout_integrates(vehicle):
    sub, kin = DoubledKIN(vehicle), KIN(vehicle)
    x, u = batch(kin, np.random.default_rng(7))
    out = sub.rollout(x, u, DT)
    # Its own dynamics, not KIN's: the articulation moves differently.
    assert not np.allclose(out[:, -1, 3], kin.rollout(x, u, DT)[:, -1, 3])
    for b in range(B):
        # The batch of the subclass's vectorised rhs equals its single rollouts to the bit:
        # the same numpy operations, element by element.
        assert np.array_equal(out[b], sub.rollout(x[b], u[b], DT))
    # And the Python step of the subclass's rhs is the RK4 of it: one step by hand.
    x0, u0 = x[0], u[0, 0]
    k1 = sub.rhs(x0, u0)
    k2 = sub.rhs(x0 + 0.5 * DT * k1, u0)
    k3 = sub.rhs(x0 + 0.5 * DT * k2, u0)
    k4 = sub.rhs(x0 + DT * k3, u0)
    expected = x0 + DT / 6.0 * (k1 + 2.0 * k2 + 2.0 * k3 + k4)
    # The same stages; the sum's association may differ by rounding only.
    np.testing.assert_allclose(out[0, 1], expected, rtol=0, atol=1e-12)
