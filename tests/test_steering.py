"""The steering map, eq. (3), with offset and monotonicity guard."""

from __future__ import annotations

import math

import numpy as np
import pytest

from artic.mjcf.steering import Steering, SteeringRangeError

# The largest road-wheel angle plays no part in eq. (3); a tractor's, for a whole map.
DELTA_MAX = math.radians(40.0)
MAP = Steering(i_s=20.0, q=0.01, delta_h_offset=math.radians(5.0), delta_max=DELTA_MAX)


def test_offset_gives_straight_wheels():
    assert MAP.road_wheel(MAP.delta_h_offset) == 0.0


def test_equation_3_by_hand():
    d = 2.0  # rad past the offset
    assert MAP.road_wheel(MAP.delta_h_offset + d) == pytest.approx((d - 0.01 * d * d) / 20.0)
    assert MAP.road_wheel(MAP.delta_h_offset - d) == pytest.approx((-d - 0.01 * d * d) / 20.0)


def test_positive_q_steers_less_left_than_right():
    # A linkage driven from the left wheel: left turns (positive) get less.
    left = MAP.road_wheel(MAP.delta_h_offset + 3.0)
    right = MAP.road_wheel(MAP.delta_h_offset - 3.0)
    assert 0 < left < -right
    assert -right - left == pytest.approx(2 * 0.01 * 9.0 / 20.0)


def test_inverse_round_trip():
    d = np.linspace(-0.4, 0.4, 101)
    np.testing.assert_allclose(MAP.road_wheel(MAP.steering_wheel(d)), d, atol=1e-14)
    linear = Steering(20.0, 0.0, 0.0, delta_max=DELTA_MAX)
    assert linear.steering_wheel(0.1) == pytest.approx(2.0)


def test_monotonic_guard_refuses_the_fold():
    printed = Steering(i_s=21.0, q=0.1, delta_h_offset=0.0, delta_max=DELTA_MAX)
    # The printed q = 0.1 /rad folds at 1/(2q) = 5 rad = 286 deg: a 500 deg turn fails.
    with pytest.raises(SteeringRangeError, match="monotonic"):
        printed.check_range(np.radians([0.0, 500.0]), "test")
    printed.check_range(np.radians([0.0, 200.0]))
    MAP.check_range(np.radians([-500.0, 500.0]))
    # A negative q folds on the right-turn side, and only there.
    mirrored = Steering(20.0, -0.1, 0.0, delta_max=DELTA_MAX)
    mirrored.check_range(np.radians([0.0, 500.0]))
    with pytest.raises(SteeringRangeError, match="-500 deg"):
        mirrored.check_range(np.radians([0.0, -500.0]))
    # Degrees passed as radians also reach the fold: the message says so.
    with pytest.raises(SteeringRangeError, match="radians"):
        MAP.check_range(np.array([200.0]))


def test_map_is_monotonic_below_the_fold():
    d = np.linspace(-10, 0.95 / (2 * 0.01), 1000)
    assert np.all(np.diff(MAP.road_wheel(d + MAP.delta_h_offset)) > 0)


def test_the_scalar_path_is_the_array_path_to_the_bit():
    # The simulation loops call the map with one float per step and take a
    # plain-float path; the logs must not depend on which path ran, so the two
    # must agree exactly, not to a tolerance.
    rng = np.random.default_rng(3)
    for q in (0.0, 0.01, 0.03):
        m = Steering(i_s=21.7, q=q, delta_h_offset=0.087, delta_max=DELTA_MAX)
        for x in rng.uniform(-8.0, 8.0, 200):
            x = float(x)
            assert m.road_wheel(x) == float(m.road_wheel(np.array([x]))[0])
            d = float(m.road_wheel(x))
            assert m.steering_wheel(d) == float(m.steering_wheel(np.array([d]))[0])
