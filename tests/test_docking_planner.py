"""KIN linearised for path following, and the planner's paths onto the dock."""

from __future__ import annotations

import math

import numpy as np
import pytest

from artic.mjcf import load_vehicle
from artic.validation.docking import planner as pl
from artic.validation.docking.geometry import Frames, first_hit
from artic.validation.docking.linear import (
    discretise,
    gains,
    linearise,
    trailer_error_model,
    with_steering_state,
)
from artic.validation.docking.scenarios import Start, scenario
from tests.helpers import PRESETS


# ---------------------------------------------------------------- linearisation
@pytest.mark.parametrize("direction", [-1.0, 1.0])
def test_the_jacobians_per_metre_are_eq_4(unloaded, direction):
    """About the straight line, per metre of travel (``u1 = +-1``), by hand from eq. (1)."""
    kin = Frames.of(unloaded).kin
    L1, L1c, L2 = kin.P
    u = direction
    A, B = linearise(kin, direction)
    expect_A = np.zeros((4, 4))
    expect_A[0, 2] = 0.0  # -u sin(psi)
    expect_A[1, 2] = u
    expect_A[3, 3] = -u / L2
    assert A == pytest.approx(expect_A, abs=1e-12)
    assert B[:, 0] == pytest.approx([0.0, 0.0, u / L1, (1 - L1c / L2) * u / L1], abs=1e-12)


@pytest.mark.parametrize("preset", PRESETS)
def test_reversing_the_semitrailer_is_unstable_at_one_over_L2_per_metre(preset):
    kin = Frames.of(load_vehicle(preset)).kin
    P = kin.P
    rev = np.sort(np.linalg.eigvals(trailer_error_model(kin, -1.0)[0]).real)
    fwd = np.sort(np.linalg.eigvals(trailer_error_model(kin, 1.0)[0]).real)
    assert rev == pytest.approx([0.0, 0.0, 1.0 / P[2]], abs=1e-7)
    assert fwd == pytest.approx([-1.0 / P[2], 0.0, 0.0], abs=1e-7)


def test_the_semitrailer_axles_offset_is_the_linear_map_of_kins_state(unloaded):
    """``z = T (Y, psi_1, gamma)`` to first order, as the error model assumes."""
    fr = Frames.of(unloaded)
    L1c, L2 = fr.P[1], fr.P[2]
    eps = np.array([0.01, 0.002, -0.003])
    x = np.array([0.0, eps[0], eps[1], eps[2]])
    axle = fr.trailer_axle(x)
    base = fr.trailer_axle(np.zeros(4))
    expect = eps[0] + (L1c - L2) * eps[1] + L2 * eps[2]
    assert axle[1] - base[1] == pytest.approx(expect, abs=1e-5)
    assert axle[2] == pytest.approx(eps[1] - eps[2])


@pytest.mark.parametrize("direction", [-1, 1])
@pytest.mark.parametrize("speed", [0.3, 1.1, 1.7])
def test_the_gains_stabilise_the_sampled_loop_at_every_speed(unloaded, direction, speed):
    from artic.validation.docking.linear import tractor_error_model

    kin = Frames.of(unloaded).kin
    ds = speed * 0.1
    model = trailer_error_model if direction < 0 else tractor_error_model
    A, B = with_steering_state(*model(kin, float(direction)))
    Ad, Bd = discretise(A, B, ds)
    K = gains(kin, direction, ds)
    assert np.max(np.abs(np.linalg.eigvals(Ad - Bd @ K[None, :]))) < 1.0
    # Scheduled: another speed, other gains.
    assert not np.allclose(K, gains(kin, direction, 2 * ds))


# ---------------------------------------------------------------- planner
def _check_path(plan, v, yard, margin=pl.MARGIN):
    fr = Frames.of(v)
    boxes = pl.HybridAStar(margin=margin).obstacles(yard)
    for seg in plan.segments:
        assert seg.direction in (-1, 1)
        x = seg.states
        assert np.all(np.abs(x[:, 3]) <= pl.GAMMA_PLAN + 1e-9)
        share = pl.STEER_SHARE if seg.direction > 0 else pl.REVERSE_STEER_SHARE
        assert np.all(np.abs(seg.delta) <= share * v.steering.delta_max + 1e-9)
        step = np.hypot(*np.diff(x[:, :2], axis=0).T)
        rate = np.abs(np.diff(seg.delta)) / np.maximum(step, 1e-9)
        # The rate limit holds per step (a short last step turns less).
        assert np.all(np.abs(np.diff(seg.delta)) <= pl.STEER_RATE * pl.STEP + 1e-9)
        assert np.all(rate[step > 0.2] <= pl.STEER_RATE * 1.05)
        t, k = fr.unit_poses_of_kin(x)
        assert first_hit(t, k, fr.tractor_box, fr.trailer_box, boxes)[0] == -1
    # Consecutive segments meet at their cusp and change direction there.
    for a, b in zip(plan.segments, plan.segments[1:], strict=False):
        assert a.direction != b.direction
        assert b.states[0] == pytest.approx(a.states[-1])
    last = plan.segments[-1]
    assert last.direction == -1
    x_r, y_r, psi_2 = fr.rear_of_kin(last.states[-1])
    assert x_r == pytest.approx(yard.x_dock, abs=1e-3)
    assert abs(y_r - yard.y_dock) <= pl.LANDING[0]
    assert abs(psi_2) <= pl.LANDING[1]


def test_a_straight_start_is_one_final_approach(unloaded):
    s = scenario("straight")
    yard = s.yard(unloaded)
    plan = pl.HybridAStar().plan(yard, unloaded, s.start(0))
    assert len(plan.segments) == 1 and plan.expansions == 1
    _check_path(plan, unloaded, yard)


@pytest.mark.parametrize("name", ["alley", "bay"])
def test_an_alley_dock_is_planned_within_the_limits(unloaded, name):
    s = scenario(name)
    yard = s.yard(unloaded)
    plan = pl.HybridAStar().plan(yard, unloaded, s.start(1))
    _check_path(plan, unloaded, yard)
    # A right angle: the semitrailer turns from across the row to square to the dock.
    psi = plan.states()[:, 2] - plan.states()[:, 3]
    assert abs(psi[0]) == pytest.approx(math.pi / 2, abs=math.radians(3.0))
    assert abs(psi[-1]) < math.radians(0.5)


def test_the_same_start_gives_the_same_path(unloaded):
    s = scenario("offset")
    yard = s.yard(unloaded)
    a = pl.HybridAStar().plan(yard, unloaded, s.start(2))
    b = pl.HybridAStar().plan(yard, unloaded, s.start(2))
    assert np.array_equal(a.states(), b.states())


def test_no_path_is_a_planning_error_not_a_crash(unloaded):
    s = scenario("bay")
    yard = s.yard(unloaded)
    with pytest.raises(pl.PlanningError, match="within 1 expansions"):
        pl.HybridAStar(max_expansions=1).plan(yard, unloaded, s.start(0))
    # A start on top of a parked semitrailer.
    with pytest.raises(pl.PlanningError, match="overlaps an obstacle"):
        pl.HybridAStar().plan(yard, unloaded, Start(yard.x_dock + 5.0, 4.0, 0.0, 0.0))
