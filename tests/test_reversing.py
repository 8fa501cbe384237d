"""The reversing decision: hysteresis on the speed, so that standstill noise is no reversing.

A forward log whose speed noise crosses zero at standstill gets no feedback
steering at all; a real reverse gets it from its first millimetres.
"""

from __future__ import annotations

import math

import numpy as np
import pytest

from artic.mjcf import load_vehicle
from artic.reduced import KinematicModel, SingleTrackModel
from artic.validation.harness.loop import run_closed_loop, unsteered_inputs
from artic.validation.harness.reversing import DEAD_BAND, MIN_DURATION, reversing
from artic.validation.harness.simulate import simulate
from artic.validation.logs.runfile import Run
from artic.validation.synthetic.manoeuvres import Profile
from conftest import as_log

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
    log = as_log(simulate(KinematicModel(v), v, prof), "stop-and-go")
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
    assert not unsteered_inputs(log, v).reversing.any()
    models = [KinematicModel(v)] + ([SingleTrackModel(v)] if v.has_tyre_data else [])
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
    run = run_closed_loop(KinematicModel(v), log, v, gain=3.0)
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
    from conftest import straight_log

    log = straight_log(n=300, u=-0.83, gamma0=math.radians(1.0))
    assert unsteered_inputs(log, unloaded).reversing.all()
