"""KIN, eq. (1): steady states in closed form, limits and outputs."""

from __future__ import annotations

import math
from types import SimpleNamespace

import numpy as np
import pytest

from artic.reduced import KIN, Driven, InitialState
from artic.reduced.kinematic import kin_rhs


def steady(model, delta, u, seconds=300.0, dt=0.01):
    model = Driven(model)
    model.reset(InitialState(0.0, 0.0, 0.0, 0.0, u1=u))
    for _ in range(int(seconds / dt)):
        model.step(dt, delta, u, 0.0)
    return model.observe()


@pytest.mark.parametrize("wheelbase", ["paper", "equivalent"])
@pytest.mark.parametrize("delta", [0.05, 0.2, -0.35])
def test_steady_circle_closed_form(unloaded, delta, wheelbase):
    u = 1.4
    model = KIN(unloaded, wheelbase)
    L1, L1c, L2 = model.P
    v = SimpleNamespace(L1=L1, L1c=L1c, L2=L2)  # eq. (1)'s lengths, whichever the choice
    y = steady(model, delta, u)
    # Yaw rate: u tan(delta) / L1.
    assert y[5] == pytest.approx(u * math.tan(delta) / v.L1, rel=1e-12)
    # Articulation from the geometry. Drive axle on radius R1 = L1 / tan(delta);
    # the hitch, L1c ahead, moves at atan(L1c / R1) to the tractor; the trailer
    # axle's radius is R2 = sqrt(R1^2 + L1c^2 - L2^2); the trailer axis makes
    # atan(L2 / R2) with the hitch velocity.
    R1 = v.L1 / math.tan(abs(delta))
    R2 = math.sqrt(R1 ** 2 + v.L1c ** 2 - v.L2 ** 2)
    gamma = math.copysign(math.atan(v.L2 / R2) - math.atan(v.L1c / R1), delta)
    # The same from gamma_dot = 0 in eq. (1): L1 sin(g) + L1c tan(d) cos(g) = L2 tan(d).
    amp = math.hypot(v.L1, v.L1c * math.tan(delta))
    gamma_b = math.asin(v.L2 * math.tan(delta) / amp) - math.atan2(v.L1c * math.tan(delta), v.L1)
    assert gamma == pytest.approx(gamma_b, abs=1e-12)
    # 300 s at 1.4 m/s is > 10 time constants L2/u: converged to 1e-6 rad.
    assert y[12] == pytest.approx(gamma, abs=1e-6)
    # In a steady turn both units yaw at the same rate.
    assert y[11] == pytest.approx(y[5], rel=1e-6)


def test_on_axle_hitch_is_the_standard_model():
    # With L1c = 0: gamma_dot = -u sin(gamma)/L2 + u tan(delta)/L1.
    rng = np.random.default_rng(1)
    L1, L2 = 3.8, 7.5
    for _ in range(20):
        g, d, u = rng.uniform(-1.2, 1.2), rng.uniform(-0.5, 0.5), rng.uniform(-3, 3)
        out = kin_rhs(np.array([0.0, 0.0, 0.3, g]), u, 0.0, d, np.array([L1, 0.0, L2]))
        assert out[3] == pytest.approx(-u * math.sin(g) / L2 + u * math.tan(d) / L1, abs=1e-14)


def test_hitch_ahead_of_axle_sign():
    # Eq. (1)'s (1 - L1c cos(gamma) / L2): a hitch ahead of the drive axle
    # moves sideways with the tractor's yaw, swinging the trailer less.
    base = kin_rhs(np.zeros(4), 1.0, 0.0, 0.2, np.array([3.8, 0.0, 7.5]))[3]
    ahead = kin_rhs(np.zeros(4), 1.0, 0.0, 0.2, np.array([3.8, 0.67, 7.5]))[3]
    assert ahead == pytest.approx(base * (1 - 0.67 / 7.5))
