"""The yard's conditions a sweep varies: defaults are today's, delay, grade and friction act."""

from __future__ import annotations

import math

import numpy as np
import pytest

from artic.mjcf import load_vehicle
from artic.mjcf.errors import UserError
from artic.mjcf.interface import OBS_INDEX, InitialState
from artic.plant import Plant
from artic.plant.tyre import steady_state
from artic.validation.docking.conditions import ActuatorDelay, road
from artic.validation.docking.controllers import Command, Controller
from artic.validation.docking.run import PLANT_DT, STEER_RATE, drive
from artic.validation.docking.scenarios import scenario

VEHICLE = "gosar2022-unloaded"
G = 9.81

TODAY = {"lateral_error_m": 0.010358919847888694, "longitudinal_error_m": 0.012235642036024785,
         "heading_error_deg": -0.11549424030380614, "time_s": 26.900000000001405,
         "path_length_m": 24.496213376525912, "max_gamma_deg": 4.412226193057967}
"""The reference controller's run of straight seed 0 on gosar2022-unloaded, from the code
before the sweep's keywords existed (commit c395242)."""


def test_the_axes_defaults_reproduce_todays_run():
    nominal = drive(scenario("straight"), VEHICLE, "reference", 0,
                    delay=0.0, steer_rate=STEER_RATE, friction=1.0, grade=0.0).row
    assert nominal["success"], nominal["failure"]
    # The same code path bit for bit on one machine; 1 um and 1e-6 deg leave room
    # for another compiler's rounding in the plant's compiled loop, not for a change.
    for key, value in TODAY.items():
        assert nominal[key] == pytest.approx(value, abs=1e-6), key


class SteerStep(Controller):
    """Open loop: the wheel steps to 90 deg and the speed to -1 m/s at t = 0.5 s."""

    def command(self, obs):
        on = obs.t >= 0.5 - 1e-9
        straight = self.steering_wheel(0.0)  # where the wheel stands at the start
        return Command(straight + (math.radians(90.0) if on else 0.0), -1.0 if on else 0.0,
                       done=obs.t >= 1.5 - 1e-9)


@pytest.mark.parametrize("delay", [0.05, 0.2])
def test_a_delay_shifts_the_actuators_response_by_the_delay(delay):
    a = drive(scenario("straight"), VEHICLE, SteerStep, 0, timeout=3.0).trace
    b = drive(scenario("straight"), VEHICLE, SteerStep, 0, timeout=3.0, delay=delay).trace
    n = round(delay / PLANT_DT)
    wa, wb = np.asarray(a.steering_wheel), np.asarray(b.steering_wheel)
    ua, ub = np.asarray(a.speed), np.asarray(b.speed)
    m = min(wa.size, wb.size - n)
    # The wheel and the speed do with the delay, step for step, what they did without it
    # delay seconds earlier (the same floats: the same increments from the same start).
    np.testing.assert_array_equal(wb[n:n + m], wa[:m])
    np.testing.assert_array_equal(ub[n:n + m], ua[:m])
    # and nothing before the step arrives: 0.5 s + delay
    first = int(np.flatnonzero(wb != wb[0])[0])
    assert first * PLANT_DT == pytest.approx(0.5 + delay + PLANT_DT, abs=1e-9)


def test_a_delay_must_be_whole_plant_steps():
    with pytest.raises(UserError, match="whole number of the plant's 10 ms steps"):
        ActuatorDelay(0.015, PLANT_DT, (0.0, 0.0))
    with pytest.raises(UserError, match="zero or more"):
        ActuatorDelay(-0.01, PLANT_DT, (0.0, 0.0))


@pytest.mark.parametrize("delay", [0.0, 0.03, 0.1, 0.25])
def test_a_sample_s_filled_targets_are_the_steps_own(delay):
    # drive's compiled steps take a sample's targets at once (fill); its Python loop asks
    # step by step (at): the same values, and the same queue left behind.
    a, b = (ActuatorDelay(delay, PLANT_DT, (0.5, 0.0)) for _ in range(2))
    seen = []
    for k in range(8):
        for x in (a, b):
            if k % 3 != 2:  # a sample without a command (settling) now and then
                x.command(10 * k, (float(k), -0.1 * k))
        rows = np.full((10, 2), np.nan)
        a.fill(10 * k, rows)
        np.testing.assert_array_equal(rows, [b.at(10 * k + j) for j in range(10)])
        assert a.current == b.current and list(a._queue) == list(b._queue)
        seen.append(rows)
    assert len(np.unique(np.concatenate(seen)[:, 0])) >= 5  # the commands arrived


def _free_roll(grade: float) -> tuple[float, float]:
    """Speed change over 1-3 s [m/s^2] and travel after 4 s [m] of the parked plant, no brake."""
    v = road(load_vehicle(VEHICLE), grade=grade)
    with Plant(v, speed="pedals") as p:  # pedals (0, 0): no drive, no brake: it rolls free
        p.reset(InitialState(0.0, 0.0, 0.0, 0.0, u1=0.0))
        speed = []
        for _ in range(400):
            p.step(PLANT_DT, 0.0, 0.0, 0.0)
            speed.append(p.observe(0.0)[OBS_INDEX["v_x_1"]])
        x = p.observe(0.0)[0]
    return (speed[299] - speed[99]) / 2.0, x


def test_grade_rolls_a_free_plant_towards_the_dock_at_g_sin_theta():
    v = load_vehicle(VEHICLE)
    with Plant(v, speed="pedals") as p:
        m = p.model
        spin = np.atleast_1d(p._spin_dof)
        # The wheels' spin inertia adds J / R^2 each to the mass the slope accelerates.
        j = sum(m.body_inertia[m.dof_bodyid[d]][1] + m.dof_armature[d] for d in spin)
        k = 1.0 + j / p.R0 ** 2 / p.mass
    a0, x0 = _free_roll(0.0)
    a5, x5 = _free_roll(5.0)
    a10, x10 = _free_roll(10.0)
    an5, xn5 = _free_roll(-5.0)
    assert abs(a0) < 1e-6 and abs(x0) < 1e-6  # level: it stays
    # A positive grade falls towards the dock, which faces +x from behind: -x.
    assert x5 < -1.0 and xn5 > 1.0 and a5 < 0.0 < an5
    assert a5 == pytest.approx(-an5, rel=1e-3)  # the slope's sign, nothing else
    # Between two grades the rolling resistance (QSY1 Fz cos theta, nearly equal) cancels:
    # the difference is g (sin theta_10 - sin theta_5) / k. 1 %: the suspension's pitch
    # settling in the window, and the rolling resistance's cos theta (0.4 per mille).
    expect = -G * (math.sin(math.atan(0.10)) - math.sin(math.atan(0.05))) / k
    assert a10 - a5 == pytest.approx(expect, rel=0.01)


def test_friction_lowers_the_force_peaks_by_its_factor():
    v = load_vehicle(VEHICLE)
    alpha = np.linspace(-0.5, 0.5, 20001)  # 0.05 mrad apart: the peak to 1e-6 of itself
    kappa = np.linspace(-0.6, 0.6, 20001)
    with Plant(v) as dry, Plant(road(v, friction=0.3)) as snow:
        assert len(dry.tyres) == len(snow.tyres)
        for pd_, ps in zip(dry.tyres, snow.tyres, strict=True):
            assert ps.LMUY == pytest.approx(0.3 * pd_.LMUY)
            assert ps.LKY == pd_.LKY  # the cornering stiffness stays
            fz = np.full_like(alpha, pd_.FNOMIN)
            _, fy_dry, _ = steady_state(pd_, fz, np.zeros_like(alpha), alpha)
            _, fy_snow, _ = steady_state(ps, fz, np.zeros_like(alpha), alpha)
            assert np.abs(fy_snow).max() == pytest.approx(0.3 * np.abs(fy_dry).max(), rel=1e-4)
            fx_dry, _, _ = steady_state(pd_, fz, kappa, np.zeros_like(kappa))
            fx_snow, _, _ = steady_state(ps, fz, kappa, np.zeros_like(kappa))
            assert np.abs(fx_snow).max() == pytest.approx(0.3 * np.abs(fx_dry).max(), rel=1e-4)
            # Small slips: the linear range, the cornering stiffness, does not change.
            small = np.abs(alpha) < 1e-3
            np.testing.assert_allclose(fy_snow[small], fy_dry[small], rtol=0.02)


def test_friction_composes_with_the_vehicle_files_scaling_and_nominal_is_the_same_vehicle():
    import dataclasses

    v = load_vehicle(VEHICLE)
    assert road(v) is v
    w = dataclasses.replace(v, tyre_scaling=(("LKY", 1.2), ("LMUY", 0.9)))
    s = dict(road(w, friction=0.5).tyre_scaling)
    assert s == {"LKY": 1.2, "LMUX": 0.5, "LMUY": pytest.approx(0.45)}
    assert road(v, grade=5.0).plant.grade == pytest.approx(math.atan(0.05))
    with pytest.raises(UserError, match="positive"):
        road(v, friction=0.0)
