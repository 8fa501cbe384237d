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


def test_truth_states_come_back_exactly_from_the_metadata(log):
    import json

    from artic.validation.criteria.distance import travelled
    from artic.validation.criteria.prediction import (
        STATE_KEY,
        candidates,
        record_states,
        truth_states,
    )

    rng = np.random.default_rng(0)
    states = [rng.normal(size=7) * 10.0 ** rng.integers(-12, 6, 7) for _ in range(len(log.frame))]
    rec = json.loads(json.dumps(record_states(log.frame, states)))  # as meta.json holds it
    got = truth_states({STATE_KEY: rec})
    k = candidates(travelled(log.frame))
    kept = np.unique(np.clip(np.concatenate([k - 1, k, k + 1]), 0, len(states) - 1))
    np.testing.assert_array_equal(got.t, log.frame["t"].to_numpy()[kept])
    for i in kept:  # float64, bit for bit
        assert np.array_equal(got.at(float(log.frame["t"].iloc[i])), states[i])
    assert got.at(float(log.frame["t"].iloc[kept[0] + 3])) is None
    rec["size"] = 6
    with pytest.raises(ValueError, match="damaged"):
        truth_states({STATE_KEY: rec})
    assert truth_states({}) is None


def test_a_start_point_without_a_truth_state_is_left_out(log, unloaded):
    from artic.validation.criteria.prediction import TruthStates

    got = prediction_errors(KIN(unloaded, wheelbase="paper"), log, unloaded,
                            states=TruthStates(np.zeros(0), np.zeros((0, 4))))
    assert all(math.isnan(got[c]) for c in COLUMNS)
    assert got["left_out"] == 6 and got["starts"] == 0
    assert "6 of 6 start points left out" in got["note"]


def test_the_reduced_models_start_as_the_harness_starts_them(log, unloaded):
    from artic.reduced import STM
    from artic.validation.criteria.prediction import starter
    from artic.validation.harness.loop import loop_inputs, run_inputs, window

    for model in (Driven(KIN(unloaded)), Driven(STM(unloaded))):
        assert starter(model, None, 0.0) == model.reset  # their own reset, unchanged
        inputs = loop_inputs(log, unloaded, unloaded.steering)
        part = window(inputs, log.frame, 1500, 2500)
        a = run_inputs(model, part, unloaded, gain=0.0)[0]
        b = run_inputs(model, part, unloaded, gain=0.0, start=model.reset)[0]
        np.testing.assert_array_equal(a, b)


def plant_log(plant, log, vehicle) -> Run:
    """The plant's own closed-loop run of ``log``, with the steering wheel it applied."""
    from artic.validation.harness.loop import run_closed_loop

    run = run_closed_loop(plant, log, vehicle, extras=False)
    frame = run.frame[list(log.frame.columns)].copy()
    steering = vehicle.steering_for("mbd")
    frame["delta_h"] = np.asarray(steering.steering_wheel(run.frame["delta"].to_numpy()))
    return Run(frame, {"name": "own", "direction": "reverse", "manoeuvre": "test"})


def test_the_plants_steady_start_is_closer_to_its_own_run(log, unloaded):
    from artic.plant import Plant

    with Plant(unloaded) as plant:
        own = plant_log(plant, log, unloaded)
        steady = prediction_errors(plant, own, unloaded)
        plant.reset_steady = None  # the start as it was: hidden states zeroed
        zeroed = prediction_errors(plant, own, unloaded)
    # Its own run, restarted every 10 m from its own signals: what is left is
    # what the signals do not carry. Zeroed, the tyres first build the slip the
    # swinging semitrailer already has, and the steering wheel turns to it.
    for c in ("pred_gamma_2m", "pred_gamma_10m", "pred_p_10m"):
        assert steady[c] < zeroed[c], (c, steady[c], zeroed[c])
    assert steady["pred_gamma_10m"] < 0.5 * zeroed["pred_gamma_10m"]


def test_the_plants_steady_start_holds_its_tyres_where_they_are(unloaded):
    import dataclasses

    from artic.mjcf.interface import InitialState
    from artic.plant import Plant

    initial = InitialState(3.0, -2.0, 0.4, math.radians(12.0), v_y_1=0.05, r_1=-0.06,
                           r_2=-0.02, u1=-1.5, delta=math.radians(8.0))
    with Plant(unloaded) as plant:
        plant.reset_steady(initial)
        obs = plant.observe()
        # The signals are the initial state's, as reset() gives them.
        np.testing.assert_allclose(obs[[0, 1, 2, 12]], [3.0, -2.0, 0.4, math.radians(12.0)],
                                   atol=1e-12)
        np.testing.assert_allclose(obs[[4, 5, 11]], [0.05, -0.06, -0.02], atol=1e-12)
        assert plant.data.qpos[plant._steer_L[0]] == pytest.approx(math.radians(8.0))
        # The lateral treads' rates, which the callback wrote at the forward:
        # zero at the steady deflections (every wheel rolls above SLIP_KNOWN).
        steady = np.abs(plant.data.ctrl[plant._tread_v]).max()
        plant.reset(dataclasses.replace(initial))
        zeroed = np.abs(plant.data.ctrl[plant._tread_v]).max()
    assert zeroed > 0.01  # m/s: the lateral slip velocities of a turning, swinging combination
    assert steady < 1e-9 * zeroed / 0.01
