"""The reversing decision: hysteresis on the speed, so that standstill noise is no reversing.

A forward log whose speed noise crosses zero at standstill gets no feedback
steering at all; a real reverse gets it from its first millimetres, its weight
ramping up over the handover, and hands it back the same way at a stop.
"""

from __future__ import annotations

import math

import numpy as np
import pytest

from artic.mjcf import load_vehicle
from artic.reduced import KIN, STM, Driven
from artic.validation.harness.loop import run_closed_loop, unsteered_inputs
from artic.validation.harness.reversing import (
    DEAD_BAND,
    HANDOVER,
    MIN_DURATION,
    feedback_weight,
    reversing,
)
from artic.validation.harness.simulate import simulate
from artic.validation.logs.profile import Profile
from artic.validation.logs.runfile import Run
from tests.helpers import as_log

DT = 0.01


def stop_and_go(v, noise: float, seed: int = 5) -> Run:
    """A forward log that stands still, drives a slalom, stops, stands and drives again.

    Driven on KIN; its speed then gets white noise of ``noise`` [m/s] at 100 Hz (an
    inertial unit's), so that at standstill it crosses zero all the time.
    """
    t = np.arange(0.0, 50.0, DT)
    u_cruise = 1.4 * v.speed_ratio  # 5 km/h full-size, Froude-scaled for a model
    ramp = np.clip((t - 8.0) / 2.0, 0, 1) - np.clip((t - 25.0) / 2.0, 0, 1) \
        + np.clip((t - 38.0) / 2.0, 0, 1)
    u = u_cruise * ramp
    s = v.steering_for("kin")
    road = 0.15 * np.sin(2 * math.pi * t / 6.0) * (ramp > 0)
    prof = Profile("slalom", t, s.i_s * road + s.delta_h_offset, u, {"direction": "forward"})
    log = as_log(simulate(KIN(v), v, prof), "stop-and-go")
    rng = np.random.default_rng(seed)
    log.frame["v_x_1"] = log.frame["v_x_1"] + rng.normal(0.0, noise, t.size)
    return log


@pytest.mark.parametrize("preset,noise", [("gosar2022-unloaded", 0.01),
                                          ("gosar2022-unloaded", 0.03),
                                          ("scale-model-1to14", 0.01)])
def test_standstill_noise_gives_no_feedback_in_a_forward_run(preset, noise):
    v = load_vehicle(preset)
    log = stop_and_go(v, noise)
    # The old decision, v_x_1 < 0 per sample, took half the 19 s of standstill (a fifth of
    # the log) for reversing.
    assert (log.frame["v_x_1"] < 0).mean() > 0.15
    inputs = unsteered_inputs(log, v)
    assert not inputs.reversing.any() and np.all(inputs.weight == 0.0)
    models = [KIN(v)] + ([STM(v)] if v.has_tyre_data else [])
    for model in models:
        run = run_closed_loop(model, log, v, gain=3.0)
        assert run.meta["status"] == "ok"
        fb = run.frame["delta_fb"].to_numpy()
        assert np.all(fb == 0.0), (model.name, np.abs(fb).max())


@pytest.mark.slow
def test_standstill_noise_gives_no_feedback_on_the_plant():
    from artic.plant import Plant

    v = load_vehicle("gosar2022-unloaded")
    log = stop_and_go(v, 0.03)
    plant = Plant(v)
    try:
        run = run_closed_loop(plant, log, v, gain=3.0, extras=False)
    finally:
        plant.close()
    assert np.all(run.frame["delta_fb"].to_numpy() == 0.0)


def reverse_from_standstill(v, a: float = 0.3, u_rev: float = -0.83) -> Run:
    """Standing 3 s, then reversing straight at deceleration ``a`` to ``u_rev`` [m/s]."""
    t = np.arange(0.0, 20.0, DT)
    u = np.maximum(u_rev, -a * np.clip(t - 3.0, 0.0, None))
    z = np.zeros_like(t)
    x = np.concatenate([[0.0], np.cumsum(0.5 * (u[1:] + u[:-1]) * DT)])
    import pandas as pd

    frame = pd.DataFrame({
        "t": t, "delta_h": np.full_like(t, v.steering_for("kin").delta_h_offset),
        "x_1": x, "y_1": z, "psi_1": z, "v_x_1": u, "v_y_1": z, "r_1": z,
        "x_2": x - 10.0, "y_2": z, "psi_2": z, "v_x_2": u, "v_y_2": z, "r_2": z, "gamma": z})
    frame.loc[0, ["gamma", "psi_2"]] = [math.radians(2.0), -math.radians(2.0)]
    return Run(frame, {"name": "reverse", "direction": "reverse"})


@pytest.mark.parametrize("a", [0.1, 0.3, 1.0])
def test_a_real_reverse_gets_feedback_from_its_first_millimetres(unloaded, a):
    v = unloaded
    log = reverse_from_standstill(v, a)
    inputs = unsteered_inputs(log, v)
    x = log.frame["x_1"].to_numpy()
    first = int(np.argmax(inputs.reversing))
    # Reversing from where the smoothed speed passes -v_off: v_off^2 / (2 a) of travel
    # (0.3 mm to 3 mm here); the quadratic speed filter rounds the ramp's corner over a
    # quarter window either way, which adds at most a (0.125 s)^2 / 2 < 1 cm at 1 m/s^2.
    v_off = DEAD_BAND / 2
    travelled = -x[first]
    assert travelled <= v_off ** 2 / (2 * a) + 0.5 * a * 0.125 ** 2 + 1e-4, travelled
    assert inputs.reversing[first:].all()  # and on for the rest of the reverse
    # The feedback acts from there: the model starts 2 deg off the log's articulation.
    run = run_closed_loop(KIN(v), log, v, gain=3.0)
    fb = run.frame["delta_fb"].to_numpy()
    assert np.all(fb[:first] == 0.0) and np.all(np.abs(fb[first:]) > 0)


def test_stretches_need_the_dead_band_and_the_minimum_duration():
    t = np.arange(0.0, 10.0, DT)
    u = np.zeros_like(t)
    u[100:180] = -0.2  # 0.8 s: too short
    u[300:500] = -0.04  # never past -v_on = 0.05: inside the dead band
    u[600:800] = -0.2  # a reverse of 2 s
    u[650:700] = -0.03  # dips back towards zero, but stays below -v_off: one stretch
    r = reversing(t, u)
    assert not r[:600].any() and r[600:800].all() and not r[800:].any()
    # The dead band scales with the vehicle's speeds: a 1:14 model's 4 cm/s counts.
    r14 = reversing(t, u, speed_ratio=math.sqrt(1 / 14))
    assert r14[300:500].all()
    assert MIN_DURATION == pytest.approx(1.0)


def test_a_log_reversing_from_its_first_sample_is_reversing_throughout(unloaded):
    from tests.helpers import straight_log

    log = straight_log(n=300, u=-0.83, gamma0=math.radians(1.0))
    assert unsteered_inputs(log, unloaded).reversing.all()


def reverse_stop_forward(t: np.ndarray, a: float = 0.5, u_rev: float = -0.83,
                         start: float = 3.0, stop: float = 15.0) -> np.ndarray:
    """Speed [m/s]: standing, reversing at ``a`` [m/s^2] to ``u_rev``, stopping, then forward."""
    u = np.maximum(u_rev, -a * np.clip(t - start, 0.0, None))
    brake = np.clip(u_rev + a * (t - stop), u_rev, 0.0)
    u = np.where(t < stop, u, brake)
    return np.where(t > stop - u_rev / a + 2.0, 0.5 * np.clip(t - (stop - u_rev / a + 2.0), 0, 1),
                    u)


@pytest.mark.parametrize("speed_ratio", [1.0, math.sqrt(1 / 14)])
def test_the_weight_is_0_outside_1_inside_and_ramps_at_a_bounded_slope(speed_ratio):
    t = np.arange(0.0, 25.0, DT)
    u = reverse_stop_forward(t) * speed_ratio
    w = feedback_weight(t, u, speed_ratio)
    r = reversing(t, u, speed_ratio)
    assert w.dtype == float and np.all((w >= 0.0) & (w <= 1.0))
    # Positive on exactly the reversing samples: which samples reverse is unchanged.
    np.testing.assert_array_equal(w > 0.0, r)
    first, last = int(np.argmax(r)), int(r.size - 1 - np.argmax(r[::-1]))
    ramp = HANDOVER * speed_ratio
    # Continuous: no sample-to-sample jump beyond the ramp's slope (1 / ramp per second,
    # rounding aside), the edges included (0 just outside, DT / ramp on the edge sample).
    assert np.abs(np.diff(w)).max() <= DT / ramp * (1 + 1e-9)
    assert w[first] == pytest.approx(DT / ramp) and w[last] == pytest.approx(DT / ramp)
    # Linear over the ramp, then exactly 1: the middle of the stretch has the whole law.
    k = int(math.ceil(ramp / DT - 1e-9))  # samples to reach 1
    up = np.minimum(1.0, (np.arange(k) + 1) * DT / ramp)
    np.testing.assert_allclose(w[first:first + k], up, rtol=1e-9)
    assert np.all(w[first + k:last - k + 1] == 1.0) and last - first > 4 * k
    np.testing.assert_allclose(w[last - k + 1:last + 1], up[::-1], rtol=1e-9)
    # Where the weight is short of 1 the tractor is near a standstill: the ramp's travel
    # is v_off T + a T^2 / 2 (filter aside, this log is unsmoothed), 0.275 m at 0.5 m/s^2
    # full-size, the same share of L2 at 1:14 (distances scale with speed_ratio^2).
    dist = np.sum(np.abs(u[(w > 0) & (w < 1)])) * DT / 2  # per ramp: two of them
    a = 0.5
    assert dist <= (0.5 * DEAD_BAND * speed_ratio * ramp + 0.5 * a * ramp ** 2) * 1.05


def test_a_short_stretch_ramps_up_and_straight_down():
    # A stretch shorter than two ramps never reaches 1: a triangle, still continuous.
    t = np.arange(0.0, 5.0, DT)
    u = np.zeros_like(t)
    u[100:250] = -0.3  # 1.5 s
    w = feedback_weight(t, u)
    assert 0.7 < w.max() < 0.8 and np.abs(np.diff(w)).max() <= DT / HANDOVER * (1 + 1e-9)
    np.testing.assert_array_equal(w > 0, reversing(t, u))


def test_a_stretch_at_the_logs_ends_starts_and_ends_at_full_weight():
    # The model starts on the log's state, so the feedback term starts at 0 anyway:
    # no ramp at the log's first sample, none at its last (nothing follows).
    t = np.arange(0.0, 5.0, DT)
    assert np.all(feedback_weight(t, np.full(t.size, -0.8)) == 1.0)
    u = np.full(t.size, -0.8)
    u[300:] = 0.5
    w = feedback_weight(t, u)
    assert w[0] == 1.0 and w[299] == pytest.approx(DT / HANDOVER) and np.all(w[300:] == 0.0)


@pytest.mark.parametrize("cls", [KIN, STM])
def test_the_feedback_is_handed_over_without_a_step(unloaded, cls):
    # A reverse that stops and drives on forward, with the model 2 deg off the log's
    # articulation at the start: the feedback term rises from 0 and falls back to 0
    # at the slope of the ramp (times K |e|), never stepping by the whole term, and
    # it is w K wrap(e) throughout. The Python law (any model) and the numba loop agree.
    v = unloaded
    log = reverse_from_standstill(v, 0.5)  # 20 s
    t = log.frame["t"].to_numpy()
    log.frame["v_x_1"] = log.frame["v_x_2"] = reverse_stop_forward(t, stop=12.0)
    x = np.concatenate([[0.0], np.cumsum(0.5 * (log.frame["v_x_1"].to_numpy()[1:]
                                                + log.frame["v_x_1"].to_numpy()[:-1]) * DT)])
    log.frame["x_1"], log.frame["x_2"] = x, x - 10.0
    log.frame["gamma"] = log.frame["psi_2"] = 0.0
    log.frame.loc[0, ["gamma", "psi_2"]] = [math.radians(2.0), -math.radians(2.0)]
    run = run_closed_loop(cls(v), log, v, gain=3.0)
    inputs = unsteered_inputs(log, v)
    w = inputs.weight
    fb = run.frame["delta_fb"].to_numpy()
    g = run.frame["gamma"].to_numpy()
    assert run.meta["status"] == "ok" and (w == 1.0).sum() > 500
    assert np.all(fb[w == 0.0] == 0.0)
    np.testing.assert_allclose(fb, w * 3.0 * (g - log.frame["gamma"].to_numpy()), atol=1e-12)
    # Standing 3 s 2 deg off, the model meets the reverse with K |e| = 6 deg of feedback
    # due: switched on in one sample, that was the step. Handed over, no sample moves the
    # term by more than the ramp's dt / T of it plus what the error itself moves.
    first = int(np.argmax(w > 0))
    assert 3.0 * abs(g[first]) > math.radians(5.9)
    jump = np.abs(np.diff(fb))
    assert jump.max() <= DT / HANDOVER * 3.0 * np.abs(g).max() + np.abs(np.diff(3.0 * g)).max()
    assert jump.max() < math.radians(0.1)
    # The same run in Python's loop (a model without a compiled form) gives the same bits.
    from artic.validation.harness.loop import _python_loop, loop_args, steered

    steering = v.steering_for(cls.name)
    inp = steered(inputs, steering, "test")
    model = Driven(cls(v))
    model.reset(inp.initial)
    py = _python_loop(model, loop_args(inp, v, 3.0))
    np.testing.assert_allclose(py[2], fb, rtol=0.0, atol=1e-12)
