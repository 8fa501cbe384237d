"""Open-loop prediction errors: zero for the log's own generator, growing for a wrong model."""

from __future__ import annotations

import math

import numpy as np
import pytest

from artic.reduced import KIN, Driven
from artic.validation.criteria.prediction import (
    COLUMNS,
    horizon_ends,
    prediction_errors,
    start_points,
)
from artic.validation.harness.simulate import drive_articulation
from artic.validation.logs.runfile import Run


def reverse_log(vehicle, seconds: float = 60.0, u: float = -1.0) -> Run:
    """KIN reversing at constant speed while a driver swings the trailer +-10 deg."""
    t = np.arange(0.0, seconds, 0.01)
    gamma_ref = math.radians(10.0) * np.sin(2.0 * math.pi * t / 25.0)
    run = drive_articulation(KIN(vehicle, wheelbase="paper"), vehicle, t,
                             np.full(t.size, u), gamma_ref, gain=2.0)
    return Run(run.frame, {"name": "swing", "direction": "reverse", "manoeuvre": "test"})


@pytest.fixture(scope="module")
def log(unloaded):
    return reverse_log(unloaded)


class SteeringFlipped:
    """KIN with the sign of its steering term flipped, driven step by step in Python."""

    name = "kin"

    def __init__(self, vehicle):
        self.inner = Driven(KIN(vehicle, wheelbase="paper"))

    def reset(self, initial):
        self.inner.reset(initial)

    def step(self, dt, delta, u1, u1_dot):
        self.inner.step(dt, -delta, u1, u1_dot)

    def observe(self, delta=None):
        return self.inner.observe(None if delta is None else -delta)

    def compiled(self):
        return None

    def closed_loop(self):
        return None

    def close(self):
        pass

    @property
    def gamma(self):
        return self.inner.gamma


def test_the_logs_own_generator_predicts_it_exactly(log, unloaded):
    got = prediction_errors(KIN(unloaded, wheelbase="paper"), log, unloaded)
    # Same model, same inputs (the steering map's round trip and the speed
    # filter, exact on a constant speed, agree to rounding): only rounding
    # is left, amplified at most e-fold over 10 m of reversing (1/L2 per metre).
    for c in COLUMNS:
        assert got[c] < 1e-9, (c, got[c])
    assert got["starts"] == 6  # every 10 m of 60 m, the one at 60 m has no log after it
    assert got["note"] == "" and got["stopped"] == 0


def test_a_wrong_wheelbase_grows_with_the_horizon(log, unloaded):
    model = KIN(unloaded, wheelbase="paper")
    model.params = model.params._replace(L2=1.2 * model.params.L2)  # 20 % long
    got = prediction_errors(model, log, unloaded)
    p = [got[f"pred_p_{h}m"] for h in (2, 5, 10)]
    g = [got[f"pred_gamma_{h}m"] for h in (2, 5, 10)]
    assert p[0] < p[1] < p[2] and g[0] < g[1] < g[2], (p, g)
    # Gamma's rate is off by ~u sin(gamma) (1/L2 - 1/(1.2 L2)) ~ 0.004 rad per metre at
    # 10 deg: a few hundredths of a radian over 10 m.
    assert 5e-3 < g[2] < 0.2
    assert p[2] > 1e-3


def test_a_flipped_steering_sign_is_caught(log, unloaded):
    got = prediction_errors(SteeringFlipped(unloaded), log, unloaded)
    exact = prediction_errors(KIN(unloaded, wheelbase="paper"), log, unloaded)
    assert got["pred_gamma_10m"] > 0.05 and got["pred_p_10m"] > 0.05
    assert got["pred_gamma_10m"] > 1e6 * max(exact["pred_gamma_10m"], 1e-15)


def test_start_points_follow_distance_and_reversing():
    s = np.linspace(0.0, 30.0, 3001)  # 1 cm per sample
    rev = np.ones(s.size, dtype=bool)
    rev[1500:] = False  # drives forward from 15 m on
    np.testing.assert_array_equal(start_points(s, rev, 5.0), [0, 500, 1000])
    np.testing.assert_array_equal(start_points(s, np.ones(s.size, bool), 10.0),
                                  [0, 1000, 2000, 3000])
    ends = horizon_ends(s, np.array([0, 2000, 2600]), (2.0, 5.0, 10.0))
    np.testing.assert_array_equal(ends, [[200, 500, 1000], [2200, 2500, 3000],
                                         [2800, -1, -1]])


def test_short_and_forward_logs_say_why_they_have_no_value(unloaded):
    short = reverse_log(unloaded, seconds=7.0)  # 7 m: no room for 10 m
    got = prediction_errors(KIN(unloaded), short, unloaded)
    assert np.isfinite(got["pred_p_2m"]) and np.isfinite(got["pred_gamma_5m"])
    assert math.isnan(got["pred_p_10m"]) and math.isnan(got["pred_gamma_10m"])
    assert "10 m" in got["note"] and "7.0 m" in got["note"]
    fwd = Run(short.frame.assign(v_x_1=-short.frame["v_x_1"]), {"name": "fwd"})
    got = prediction_errors(KIN(unloaded), fwd, unloaded)
    assert all(math.isnan(got[c]) for c in COLUMNS)
    assert got["note"] == "not a reverse log"


def test_metrics_rows_carry_the_predictions(log, unloaded):
    from artic.validation.runs.validate import validate_runs

    rows = validate_runs([log], unloaded, ["kin", "stm"])
    assert rows[list(COLUMNS)].notna().all().all()
    # STM on a log KIN made: not exact, but far from the flipped model's error.
    assert (rows["pred_gamma_10m"] < 0.05).all()


@pytest.mark.slow
def test_the_plant_predicts_through_its_compiled_loop(log, unloaded):
    from artic.plant import Plant

    with Plant(unloaded) as plant:
        assert plant.closed_loop() is not None
        got = prediction_errors(plant, log, unloaded)
    # The plant is not KIN (tyre slip, the tridem's scrub): errors well above
    # rounding, but a reversing model's over 10 m, not a diverged one's.
    assert got["starts"] == 6 and got["stopped"] == 0
    assert 1e-4 < got["pred_gamma_10m"] < 0.1
    assert got["pred_p_2m"] < got["pred_p_10m"] < 1.0
